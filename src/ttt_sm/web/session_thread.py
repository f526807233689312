"""The session's simulation thread: its loop, the commands it takes, its clock's pauses, its death.

:class:`SessionThread` is the half of :class:`~.session.Session` that runs in
the simulation thread (the other half is what pages and the server call, and
what a command's handler sees): the loop that runs the robot in slices,
handles the waiting commands between two control steps (at most
:data:`COMMAND_SHARE` of the time while it runs, each for
:data:`COMMAND_BUDGET_S` at most) and publishes a frame when one is due; the
scheduler's clock that pauses the run for them (:class:`_SessionClock`); and
what happens when the loop itself fails (:meth:`SessionThread.died`).
"""

from __future__ import annotations

import gc
import logging
import os
import queue
import threading
import time
from collections.abc import Callable
from typing import Any

from ..debug.debugger import Debugger
from ..debug.errors import DebugError
from ..debug.records import StopReason
from ..sched.clock import PacedClock
from .camera_feed import CameraFeed
from .commands import SPECS
from .commands import run as run_commands
from .coverage import CoverageError
from .pages import Pages
from .protocol import Command

log = logging.getLogger(__name__)

#: A test-only fault hook (docs/gui.md, "When the session dies"): with this environment variable set to a
#: command type, the simulation thread raises when it takes a command of that type, outside the handling
#: that keeps a command's failure from ending the thread, as a bug of the session's own loop would.  The
#: process-level test of ``ttt-sm gui``'s exit status uses it; nobody else should.
FAULT_ENV = "TTT_SM_TEST_SESSION_FAULT"
_FAULT_ON = os.environ.get(FAULT_ENV) or None

#: One ``Debugger.run`` call while running: the run goes on after it (it is not a stop).
RUN_CHUNK_S = 60.0
#: Wall time one command may hold the simulation thread: a ``step``, ``tick`` or ``next`` that runs longer
#: pauses after it (the reply says how far it came; send it again to go on).
COMMAND_BUDGET_S = run_commands.COMMAND_BUDGET_S
#: While the robot runs, the commands take at most this share of the simulation thread's time (a flood of
#: them is handled between longer stretches of the run, whose pace they do not take).
COMMAND_SHARE = 0.3


class _SessionClock:
    """The scheduler's clock while the session runs: the pacing, then a pause when a frame is due."""

    paced = True

    def __init__(self, session: SessionThread) -> None:
        self._session = session

    def start(self) -> None:
        self._session.clock.start()

    def wait_period(self, k: int) -> None:
        s = self._session
        if not s._running_slice:
            if s._command_deadline is not None and time.perf_counter() > s._command_deadline:
                s._command_deadline = None
                s.debugger.pause()  # a command has had its COMMAND_BUDGET_S: it stops after this step
            return
        s.clock.wait_period(k)
        now = time.perf_counter()
        if (s._wake and now >= s._next_drain_at) or now >= s._next_frame_at:
            s.debugger.pause()


class SessionThread:
    """The simulation thread of a :class:`~.session.Session` (its base class): the loop and its state.

    What it reads of the session is declared below; :meth:`_init_thread` sets
    the loop's own state.
    """

    debugger: Debugger
    camera_feed: CameraFeed | None
    clock: PacedClock
    frame_period: float
    #: ``"running"`` or ``"paused"``.
    mode: str
    last_stop: dict[str, Any] | None
    pages: Pages
    fault: str | None
    trace_stopped: str | None

    def _init_thread(self) -> None:
        self._feed_grabs = 0
        self._queue: queue.Queue[tuple[int, Command] | None] = queue.Queue()
        self._wake = False
        self._next_drain_at = 0.0
        #: While a command runs: when it has had its :data:`COMMAND_BUDGET_S` (perf_counter), else None.
        self._command_deadline: float | None = None
        #: Set when the simulation thread has ended for good (stopped, or died: then :attr:`error` says why).
        self.ended = threading.Event()
        #: Called (in the simulation thread) if it dies of an error: ``ttt-sm gui`` stops the server then,
        #: and exits non-zero, rather than serve pages a session that no longer runs.
        self.death_listeners: list[Callable[[str], None]] = []
        self._running_slice = False
        self._stopping = False
        self._next_frame_at = 0.0
        self._last_frame_at = 0.0
        self._dirty = True
        self._thread: threading.Thread | None = None
        self.error: str | None = None

    # -- what the session provides ---------------------------------------------------------------

    def reply_error(self, cid: int, error: str, command: Command | None = None, msg_id: Any = None) -> None:
        raise NotImplementedError

    def send_to(self, cid: int, message: dict[str, Any]) -> None:
        raise NotImplementedError

    def broadcast(self, message: dict[str, Any]) -> None:
        raise NotImplementedError

    def publish(self) -> None:
        raise NotImplementedError

    def note_stop(self, reason: StopReason) -> None:
        raise NotImplementedError

    def robot_raised(self, exc: BaseException) -> None:
        raise NotImplementedError

    # -- the thread ---------------------------------------------------------------------------------

    def start(self) -> None:
        """Start the simulation thread."""
        if self._thread is not None:
            return
        if self.camera_feed is not None:
            self.camera_feed.start()
        self._thread = threading.Thread(target=self._main, name="ttt-sm-session", daemon=True)
        self._thread.start()

    def _main(self) -> None:
        try:
            freeze_heap()
            while not self._stopping:
                self._drain()
                if self._stopping:
                    break
                if self.mode == "running":
                    self._run_slice()
                else:
                    self._idle()
                self._flush()
        except BaseException as exc:  # the session cannot go on: say so to every page, and to whoever serves them
            log.exception("the session stopped")
            self.died(f"the session stopped ({' '.join(str(exc).split()) or type(exc).__name__}); restart"
                      " ttt-sm gui")
        finally:
            self.ended.set()

    def died(self, why: str) -> None:
        """The simulation thread cannot go on: every page is told (an ``error`` marked ``fatal``), the
        commands still queued are refused, and :attr:`death_listeners` hear it (``ttt-sm gui`` then stops
        the server and exits non-zero)."""
        self.error = why
        self.mode = "paused"
        try:
            self.broadcast({"type": "error", "id": None, "command": None, "error": why, "fatal": True})
        except Exception:  # the pages may be gone; the listeners must still hear it
            log.exception("the pages could not be told the session stopped")
        while True:
            try:
                item = self._queue.get_nowait()
            except queue.Empty:
                break
            if item is not None and item[0]:
                self.reply_error(item[0], f"{item[1].type}: {why}", item[1])
        for tell in list(self.death_listeners):
            try:
                tell(why)
            except Exception:
                log.exception("a listener of the session's end failed")

    def _drain(self) -> None:
        """Handle the commands waiting; while the robot runs, at most :data:`COMMAND_SHARE` of the time."""
        self._wake = False
        started = time.perf_counter()
        budget = self.frame_period if self.mode == "running" else COMMAND_BUDGET_S
        try:
            while True:
                try:
                    item = self._queue.get_nowait()
                except queue.Empty:
                    return
                if item is None:
                    return
                self._handle(*item)
                if self.mode == "running" and time.perf_counter() - started > budget and not self._queue.empty():
                    self._wake = True  # the rest after a stretch of the run
                    return
        finally:
            spent = time.perf_counter() - started
            self._next_drain_at = time.perf_counter() + spent * (1 - COMMAND_SHARE) / COMMAND_SHARE

    def _idle(self) -> None:
        timeout = None
        if self._dirty:
            timeout = max(0.0, self._last_frame_at + self.frame_period - time.perf_counter())
        elif self.camera_feed is not None:
            timeout = self.frame_period  # paused, the camera outside the simulation goes on: look again
        try:
            item = self._queue.get(timeout=timeout)
        except queue.Empty:
            return
        if item is not None:
            self._handle(*item)
            self._wake = True  # the others waiting, at once

    def _run_slice(self) -> None:
        dbg = self.debugger
        self._next_frame_at = max(self._last_frame_at + self.frame_period, time.perf_counter())
        if self.fault is not None:  # the robot that raised runs no more
            self.mode = "paused"
            return
        self._running_slice = True
        try:
            reason = dbg.run(min(RUN_CHUNK_S, dbg.max_run_s))
        except Exception as exc:  # a chart raised: the arm holds, the session goes on without running it
            self.robot_raised(exc)
            return
        finally:
            self._running_slice = False
        self._dirty = True
        if reason.kind not in ("timeout", "paused"):  # a breakpoint, or the game could not go on
            self.mode = "paused"
            self.note_stop(reason)

    def _flush(self) -> None:
        if self.trace_stopped is None and self.debugger.trace_failure is not None:
            self._trace_stopped(self.debugger.trace_failure)
        if self.camera_feed is not None and self.camera_feed.grabs != self._feed_grabs:
            self._feed_grabs = self.camera_feed.grabs
            self._dirty = True
        if self._dirty and time.perf_counter() - self._last_frame_at >= self.frame_period * 0.999:
            self.publish()

    def _trace_stopped(self, failure: OSError) -> None:
        """The trace file could not be written on (the disk full): it stops, whole lines only; the session goes
        on, and every page is told once (a page that joins later, when it joins)."""
        self.trace_stopped = (f"tracing stopped: {failure.filename}: {failure.strerror}; the session goes on"
                              " without a trace file (free some space and start again to trace)")
        log.error("%s", self.trace_stopped)
        self.broadcast({"type": "error", "id": None, "command": None, "error": self.trace_stopped})

    def _install_clock(self) -> None:
        self.debugger.robot.sched.set_clock(_SessionClock(self))
        self.clock.restart()

    def _handle(self, cid: int, cmd: Command) -> None:
        """One command, in the simulation thread: its reply, or its failure as an error reply to its page.

        Whatever a handler raises ends here, never the thread: a refusal
        (``ValueError``, ``DebugError``, ``CoverageError``) is sent as it says; anything else
        is a bug, logged with its traceback, and the page is told in words, without the
        exception's name.  If the robot moved (or was rebuilt) before it broke, it
        may be half way through a step: :meth:`robot_raised` holds it.
        """
        if cmd.type == _FAULT_ON:  # the test hook: outside the handling below, as a bug of the loop would be
            raise RuntimeError(f"{FAULT_ENV}={_FAULT_ON}: the test's fault in the simulation thread")
        if cmd.type == "_call":
            cmd.args["fn"](self.debugger)
            self._dirty = True
            return
        client = self.pages.taken(cid)
        spec = SPECS.get(cmd.type)
        if spec is None:
            self.reply_error(cid, f"{cmd.type}: not handled by this session", cmd)
            return
        robot, steps = self.debugger.robot, self.debugger.robot.steps
        started = time.perf_counter()
        self._command_deadline = started + COMMAND_BUDGET_S
        try:
            result = spec.handler(self, cid, **cmd.args)
        except (DebugError, CoverageError, ValueError) as exc:
            self.reply_error(cid, f"{cmd.type}: {exc}" if not str(exc).startswith(cmd.type) else str(exc), cmd)
        except Exception as exc:
            log.error("command %s failed", cmd.type, exc_info=exc)
            if self.debugger.robot is not robot or self.debugger.robot.steps != steps:
                self.robot_raised(exc)  # broke off in the middle (a replay through a chart that raises, say)
                self.reply_error(cid, f"{cmd.type}: {self.fault}", cmd)
            else:
                self.reply_error(cid, f"{cmd.type}: it failed inside the session before it changed anything (a"
                                      " bug of ttt_sm, written to the server's log); the session goes on", cmd)
        else:
            if result is not None:
                self.send_to(cid, {"type": "reply", "id": cmd.id, "command": cmd.type, "ok": True, **result})
        finally:
            self._command_deadline = None
            if client is not None:
                self.pages.used(client, time.perf_counter(), time.perf_counter() - started)
        self._dirty = True


def freeze_heap() -> None:
    """Collect, then leave the objects alive now out of the garbage collector's later passes.

    A robot holds some 200,000 objects (charts, numba and SciPy modules); a
    full collection of them took 0.24-0.4 s, and Python runs one every few
    simulated seconds of a run: a stall that real-time pacing counts as a slip.
    Frozen, they are not scanned again; what the run allocates afterwards is
    collected as usual.  :meth:`Session.stop` and a replay (which replaces the
    robot) unfreeze them.
    """
    gc.collect()
    gc.freeze()
