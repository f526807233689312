"""A page's own commands: it joins (``hello``), it has drawn a frame (``ack``)."""

from __future__ import annotations

import time

from ..fields import identifier, integer, optional
from .spec import Cockpit, command


@command("hello", page=optional(identifier, "charts"))
def hello(session: Cockpit, cid: int, page: str) -> None:
    """A page joins: the session answers with ``session`` (what it runs) and a full ``frame``."""
    session.join(cid, page)


@command("ack", queued=False, frame=integer(0, 2**53))
def ack(session: Cockpit, cid: int, frame: int) -> None:
    """The page has drawn frame ``frame`` (the latency figures): noted at once, in the server's thread."""
    session.frames.ack(frame, time.perf_counter())
