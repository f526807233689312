"""Warnings that stay readable when a link floods: loud for the first few of a kind, then summed up.

A camera link that turns to noise can reject thousands of lines a second.
:class:`BurstLog` logs the first :data:`LOUD_PER_KIND` messages of each kind
in a burst at WARNING, the rest at DEBUG, and says how many it kept quiet in
one WARNING line when the burst ends (:meth:`BurstLog.end`, called on a good
frame or a close) or every :data:`SUMMARY_EVERY_S` while it lasts: 1 MB of
noise is a dozen lines, not ten thousand.  The reader's counts keep the full
tally (docs/smartcam.md).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from typing import Any

LOUD_PER_KIND = 10
"""Log this many messages of one kind per burst at WARNING; the rest at DEBUG, summed up in one line."""
SUMMARY_EVERY_S = 10.0
"""A burst that goes on this long gets its summary line now, and again after as long."""


class BurstLog:
    """One link's warnings, rate-limited per kind and summed up per burst.

    Parameters
    ----------
    log
        Where the lines go.
    name
        The link's name, the first word of every line (``camera <name>: ...``).
    summary
        The link's counts so far, in words, appended to every summary line.
    """

    def __init__(self, log: logging.Logger, name: str, summary: Callable[[], str]) -> None:
        self._log = log
        self._name = name
        self._summary = summary
        self._loud: dict[str, int] = {}
        self._quiet: dict[str, tuple[int, float]] = {}  # kind -> messages kept at DEBUG, since when
        self.now: Callable[[], float] = time.monotonic
        """The clock bursts are timed by (a test may set its own)."""

    def say(self, kind: str, msg: str, *args: Any) -> None:
        """Log `msg % args` as one message of `kind`: at WARNING while the burst is young, else at DEBUG."""
        n = self._loud[kind] = self._loud.get(kind, 0) + 1
        if n <= LOUD_PER_KIND:
            if n == LOUD_PER_KIND:
                msg += f" (further '{kind}' messages at DEBUG, counted in one line when the burst ends)"
            self._log.warning("camera %s: " + msg, self._name, *args)
            return
        self._log.debug("camera %s: " + msg, self._name, *args)
        now = self.now()
        count, since = self._quiet.get(kind, (0, now))
        self._quiet[kind] = (count + 1, since)
        if now - since >= SUMMARY_EVERY_S:
            self._summarise(kind, now)

    def end(self) -> None:
        """The burst is over (a good frame came, or the link closed): say what was kept quiet."""
        now = self.now()
        for kind in list(self._quiet):
            self._summarise(kind, now)
        self._loud.clear()

    def _summarise(self, kind: str, now: float) -> None:
        count, since = self._quiet.pop(kind)
        self._log.warning("camera %s: %d more '%s' message(s) in %.1f s, logged at DEBUG (%s)",
                          self._name, count, kind, now - since, self._summary())
