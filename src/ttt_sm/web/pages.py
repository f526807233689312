"""The pages connected to the cockpit's session: who they are, what each may ask of it, and sending to them.

A page is a WebSocket the server reads (any thread calls in here; one lock
guards the book).  Each page has a send function (the server's queue for its
socket), whether it has joined (said ``hello``: it gets the frames), and its
limits (docs/gui.md, "Limits"; docs/reliability.md, "The cockpit's session"):

- at most :data:`PAGE_QUEUE` of its commands wait for the simulation thread;
- its commands use at most :data:`PAGE_SHARE` of that thread's time, after a
  burst of :data:`PAGE_BURST_S`, while someone else needs the thread;
- a page over either limit has its messages dropped unread (a check, not a
  parse and a reply), and hears of them once a :data:`DROP_NOTICE_S`;
- a page that joined and says ``hello`` again gets what runs and a full frame
  with the next frame, at most once a :data:`FULL_AGAIN_S`.

:class:`~.session.Session` runs the commands and builds the frames; this
module only keeps the book of the pages and hands them text.
"""

from __future__ import annotations

import itertools
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..runtime.jsonable import dumps, jsonable

#: Commands of one page waiting for the simulation thread at most; one more is refused with an error reply.
PAGE_QUEUE = 16
#: A page whose messages are dropped unread hears of them at most once in this many seconds (wall).
DROP_NOTICE_S = 1.0
#: One page's commands take at most this share of the simulation thread's time, sustained, after a burst
#: of :data:`PAGE_BURST_S`: past it the page's commands are refused until its use has fallen back (a flood
#: of replays, each seconds long, no longer takes the robot's time).
PAGE_SHARE = 0.25
#: Seconds of the simulation thread a page may use at once before :data:`PAGE_SHARE` holds it back.
PAGE_BURST_S = 2.0
#: A page that joined and says hello again gets what runs and a full frame at most once in this many seconds
#: (the full frame is the biggest thing the session builds: a flood of hellos must not make it one a period).
FULL_AGAIN_S = 1.0

Send = Callable[[str], None]


@dataclass
class Page:
    """One connected page: how to reach it, and what it has used of the session."""

    send: Send
    joined: bool = False
    page: str = ""
    #: Commands of this page queued and not yet handled (at most :data:`PAGE_QUEUE`).
    queued: int = 0
    #: Commands refused because the page had :data:`PAGE_QUEUE` waiting, or had used its share.
    refused: int = 0
    #: Seconds of the simulation thread this page's commands have used, less PAGE_SHARE of the time since.
    used_s: float = 0.0
    used_at: float = 0.0
    #: Messages of this page read and parsed, and those dropped unparsed while it was refused
    #: (:meth:`Pages.refusing`): a flood costs the server a check per message, not a parse and a reply.
    parsed: int = 0
    dropped: int = 0
    #: The dropped messages not yet told to the page, and when it may be told next (one reply a window).
    untold: int = 0
    tell_at: float = 0.0
    #: A page that joined has said hello again: it gets what runs and a full frame with the next frame (one
    #: frame built for every such page, not one per hello: a flood of them costs no more than a frame a period).
    full_due: bool = False
    #: When this page may have the next such full frame (perf_counter): one a :data:`FULL_AGAIN_S` at most.
    full_at: float = 0.0

    def use(self, now: float, spent: float = 0.0) -> float:
        """The page's use of the simulation thread now (``spent`` added): it falls by PAGE_SHARE a second."""
        self.used_s = max(0.0, self.used_s - (now - self.used_at) * PAGE_SHARE) + spent
        self.used_at = now
        return self.used_s


class Pages:
    """The book of the session's pages.

    Parameters
    ----------
    running : callable
        Whether the robot runs now: then a page over its share is held back
        even when it is alone (the run needs the thread).
    """

    def __init__(self, running: Callable[[], bool]) -> None:
        self._running = running
        self._pages: dict[int, Page] = {}
        self._ids = itertools.count(1)
        self._lock = threading.Lock()

    def connect(self, send: Send) -> int:
        """A page connects: ``send(text)`` gets its replies and, once it says hello, the frames."""
        cid = next(self._ids)
        with self._lock:
            self._pages[cid] = Page(send)
        return cid

    def disconnect(self, cid: int) -> None:
        """A page is gone; nothing else changes."""
        with self._lock:
            self._pages.pop(cid, None)

    def get(self, cid: int) -> Page | None:
        with self._lock:
            return self._pages.get(cid)

    def __len__(self) -> int:
        with self._lock:
            return len(self._pages)

    def ids(self) -> list[int]:
        with self._lock:
            return list(self._pages)

    def counts(self, cid: int) -> dict[str, int]:
        """A page's messages parsed, dropped unread, and commands refused after parsing (tests, the probe)."""
        with self._lock:
            p = self._pages.get(cid)
            return {} if p is None else {"parsed": p.parsed, "dropped": p.dropped, "refused": p.refused}

    # -- limits ----------------------------------------------------------------------------------

    def refusing(self, cid: int, now: float) -> bool:
        """Whether this page's next message is dropped unread: it has :data:`PAGE_QUEUE` commands waiting, or
        has used more than its share (the refusals of :meth:`admit`, decided before the message is parsed).

        The server calls it for every message it reads.  A dropped message is counted; the page hears of
        them in one ``error`` a :data:`DROP_NOTICE_S` window (its ``dropped`` count), not one reply each."""
        with self._lock:
            page = self._pages.get(cid)
            if page is None:
                return False
            why = self._held_back(cid, page, now)
            if why is None:
                page.parsed += 1
                return False
            page.dropped += 1
            page.untold += 1
            if now < page.tell_at:
                return True
            told, page.untold, page.tell_at = page.untold, 0, now + DROP_NOTICE_S
        self.send_to(cid, {"type": "error", "id": None, "command": None, "dropped": told,
                           "error": f"refused: {told} message(s) dropped unread: {why}"})
        return True

    def admit(self, cid: int, now: float) -> tuple[bool, str | None]:
        """A parsed command of page ``cid`` for the simulation thread: whether it is queued (a page gone is
        not; cid 0, the server's own and the bench's, always is), and why it is refused if it is not."""
        with self._lock:
            page = self._pages.get(cid)
            if page is None:
                return cid == 0, None
            why = self._held_back(cid, page, now)
            if why is not None:
                page.refused += 1
                return False, why
            page.queued += 1
            return True, None

    def taken(self, cid: int) -> Page | None:
        """The simulation thread takes one of the page's queued commands (the page, if it is still there)."""
        with self._lock:
            page = self._pages.get(cid)
            if page is not None:
                page.queued = max(0, page.queued - 1)
            return page

    def used(self, page: Page, now: float, spent: float) -> None:
        """A command of ``page`` held the simulation thread ``spent`` seconds."""
        with self._lock:
            page.use(now, spent)

    def _held_back(self, cid: int, page: Page, now: float) -> str | None:
        """Why this page's next command is refused now, or None: it has :data:`PAGE_QUEUE` commands waiting,
        or it has used more than :data:`PAGE_BURST_S` of the simulation thread (less its share since) while
        someone else needs the thread (the robot running, or another page connected).  One page alone with a
        paused robot is never held back for its use: a replay that takes seconds on a slow or busy machine
        must not make the next Run or Pause a refusal.  Called with the lock held; counts the use up to `now`."""
        used = page.use(now)
        if page.queued >= PAGE_QUEUE:
            return (f"this page has {PAGE_QUEUE} commands waiting for the session already (the most one page may"
                    " have); wait for their replies")
        if used > PAGE_BURST_S and (self._running() or any(k != cid for k in self._pages)):
            wait = (used - PAGE_BURST_S) / PAGE_SHARE
            return (f"this page's commands have used the session more than one page may ({PAGE_SHARE:.0%} of"
                    f" its time, after a burst of {PAGE_BURST_S:g} s); send it again in {max(wait, 0.1):.1f} s")
        return None

    # -- sending ---------------------------------------------------------------------------------

    def send_to(self, cid: int, message: dict[str, Any]) -> None:
        """Send one page a message."""
        page = self.get(cid)
        if page is not None:
            page.send(dumps(jsonable(message)))

    def broadcast(self, message: dict[str, Any]) -> None:
        """Send every page that joined a message."""
        text = dumps(jsonable(message))
        with self._lock:
            targets = [p.send for p in self._pages.values() if p.joined]
        for send in targets:
            send(text)

    def joined(self, cid: int, page: str) -> None:
        """Page ``cid`` has had what runs and its full frame: the frames go to it from now on."""
        with self._lock:
            p = self._pages.get(cid)
            if p is not None:
                p.joined, p.page = True, page

    def frame_targets(self, now: float) -> tuple[list[tuple[Send, bool]], bool]:
        """Who gets the frame published at ``now``: each joined page's send and whether it gets what runs and
        a full frame (it said hello again, and its :data:`FULL_AGAIN_S` is over); whether a page still waits
        for one (a later frame brings it)."""
        with self._lock:
            targets = []
            for p in self._pages.values():
                due = p.full_due and now >= p.full_at
                if due:
                    p.full_due, p.full_at = False, now + FULL_AGAIN_S
                if p.joined:
                    targets.append((p.send, due))
            return targets, any(p.full_due for p in self._pages.values())
