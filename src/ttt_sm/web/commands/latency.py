"""A page has drawn a frame (``ack``): the latency figures, transition or graph sample to the screen."""

from __future__ import annotations

import time

from ..fields import integer
from .spec import Cockpit, command


@command("ack", queued=False, frame=integer(0, 2**53))
def ack(session: Cockpit, cid: int, frame: int) -> None:
    """The page has drawn frame ``frame``: noted at once, in the server's thread (it only notes a time)."""
    session.frames.ack(frame, time.perf_counter())
