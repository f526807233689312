"""The one running session the cockpit's pages view: a simulation thread over the :class:`Debugger`.

::

    simulation thread:  Debugger.run / step / tick / next / replay  (the one implementation)
        | paced by a PacedClock (x0.1 .. x10, or as fast as it goes), paused by the user or a breakpoint
        | frames (.frames): at most FRAME_HZ a second, each the latest state and every transition since the last
        v
    pages  <-- frames, replies --  Session  <-- commands (checked by .protocol, handled by .commands) --  pages

Every call into the debugger and the robot happens in the simulation thread;
pages (and the server's event loop) only queue :class:`~.protocol.Command`\\ s
and receive text.  While it runs, the session's clock asks the debugger to
pause between two control steps whenever a frame is due or a command waits,
publishes the frame, handles the commands and runs on, so a frame is never
built from a half-done step, and the pacing keeps absolute deadlines across
these pauses.  Each command is handled by the function that declares it
(:mod:`.commands`), which sees the session as a
:class:`~.commands.spec.Cockpit`.  The loop of the simulation thread is
:class:`~.session_thread.SessionThread`, the base of :class:`Session`.

Bounded in memory: the debugger keeps a bounded number of fingerprints and
the newest transitions of its trace (a ring buffer), the frames a bounded
number of pending transitions, frame stamps and latency samples.  The whole
trace is the debugger's trace file when it streams one (``ttt-sm gui
--trace``: written as it happens, ended by :meth:`Session.stop` with how the
cockpit stopped), else :meth:`Session.stop` saves the kept transitions.

A chart that raises while the robot runs (a student's chart, with ``ttt-sm
gui --lab``) does not end the session: :meth:`Session.robot_raised` holds the
arm where it stands, pauses, and refuses to run that robot on (its charts may
be half way through a step) until it is built again: a replay, a new game, the
lab's next save.  Every page is told (the frames' ``stop``, and whoever
listens in :attr:`Session.fault_listeners`).
"""

from __future__ import annotations

import contextlib
import gc
import logging
import threading
import time
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

from ..debug.debugger import Debugger
from ..debug.records import StopReason
from ..runtime.jsonable import dumps, jsonable
from ..sched.clock import PacedClock
from .arm_view import arm_scene
from .camera_feed import CameraFeed
from .catalogue import describe_session
from .commands import SPECS
from .coverage import CoverageRuns
from .frames import Frames, Status
from .operate import Operate
from .pages import Pages
from .protocol import Command
from .session_thread import FAULT_ENV as FAULT_ENV  # the test hook's name, where the tests look for it
from .session_thread import SessionThread, freeze_heap

log = logging.getLogger(__name__)

#: Frames a second at most, to every page.
FRAME_HZ = 30.0


class Session(SessionThread):
    """A robot under a :class:`Debugger`, run in a thread of its own, viewed by any number of pages.

    Parameters
    ----------
    debugger : Debugger
        The one debugger of the session (built with its recipe, for replay).
    speed : float or None
        Times real time (0.1 .. 10); None: as fast as it goes.
    running : bool
        Start running (else paused at power-on).
    frame_hz : float
        Frames a second at most.
    scenarios : mapping of name to Path
        Scenario files the pages may run for coverage.
    trace_path : Path, optional
        Where :meth:`stop` writes the trace (JSON Lines) when the debugger
        does not stream it to a file of its own.
    camera_feed : CameraFeed, optional
        A camera outside the simulation (``ttt-sm gui --camera``), started and
        stopped with the session; the frames carry what it shows.
    """

    def __init__(self, debugger: Debugger, *, speed: float | None = 1.0, running: bool = True,
                 frame_hz: float = FRAME_HZ, scenarios: Mapping[str, Path] | None = None,
                 trace_path: Path | None = None, camera_feed: CameraFeed | None = None) -> None:
        self.debugger = debugger
        self.camera_feed = camera_feed
        robot = debugger.robot
        self.params = robot.params
        self.info = describe_session(debugger)
        self.chart_classes = {name: type(c) for name, c in robot.charts.items()}
        self.info["scenarios"] = list(scenarios or {})
        self.info["arm"] = arm_scene(self.params)
        self._info_text: str | None = None  # the ``session`` message, once a page has joined
        self.trace_path = trace_path
        self.clock = PacedClock(self.params.control.dt, speed)
        self.speed = speed
        self.frame_period = 1.0 / frame_hz
        self.mode = "running" if running else "paused"
        #: Why the run stopped last (a frame's ``stop``), or None while it runs.
        self.last_stop: dict[str, Any] | None = None
        #: The pages connected (web/pages.py): their limits, and sending to them.
        self.pages = Pages(lambda: self.mode == "running")
        self._init_thread()
        self._resync = False
        #: Why the robot may not run on (a chart raised while it ran: :meth:`robot_raised`), or None.
        #: Cleared when the robot is built again (:meth:`robot_replaced`).
        self.fault: str | None = None
        #: Whether the session was running when the fault came (the lab's next good save runs on).
        self.fault_while_running = False
        #: ``tell(exc)``, in the simulation thread, when a chart raises while the robot runs (the lab
        #: names the student's file and line).
        self.fault_listeners: list[Callable[[BaseException], None]] = []
        #: How the session ends, for the trace file's last line: ``("interrupted", {"signal": "SIGTERM"})``
        #: when a signal stops the server (``ttt-sm gui`` sets it), else finished (or the error).
        self.ending: tuple[str, dict[str, Any]] | None = None
        #: Why tracing stopped (``gui --trace`` on a full disk: the file keeps whole lines), told to every page.
        self.trace_stopped: str | None = None
        #: The scenario runs for the diagrams' coverage colours (web/coverage.py).
        self.coverage = CoverageRuns(self.params, self.chart_classes, scenarios or {}, self.send_to, self.broadcast)
        #: The Operational page's side (web/operate.py): its graphs' samples, Trigger, the precision.
        self.operate = Operate(debugger)
        #: What the pages are sent (web/frames.py).
        self.frames = Frames(debugger, self.clock, self.operate, camera_feed)
        self._install_clock()

    # -- the pages' side (any thread) -----------------------------------------------------

    def submit(self, cid: int, command: Command) -> None:
        """Queue a checked command; the simulation thread handles it between two control steps.

        A page with :data:`.pages.PAGE_QUEUE` commands waiting gets this one refused (an ``error`` reply at once);
        a session that no longer runs refuses every command."""
        spec = SPECS.get(command.type)
        if self.error is not None:
            self.reply_error(cid, f"{command.type}: {self.error}", command)
            return
        if spec is not None and not spec.queued:
            try:
                spec.handler(self, cid, **command.args)
            except Exception:  # noted in the server's thread: a bug there must not end the connection
                log.exception("command %s failed", command.type)
            return
        go, why = self.pages.admit(cid, time.perf_counter())
        if why is not None:
            self.reply_error(cid, f"{command.type}: refused: {why}", command)
        if not go:  # refused, or a page gone (cid 0: the server's own, the bench's: not bounded)
            return
        self._queue.put((cid, command))
        self._wake = True

    def reply_error(self, cid: int, error: str, command: Command | None = None, msg_id: Any = None) -> None:
        """Send one page an error message (a message that did not pass :mod:`.protocol`, say)."""
        self.send_to(cid, {"type": "error", "id": command.id if command else msg_id,
                           "command": command.type if command else None, "error": error})

    # -- life -------------------------------------------------------------------------------

    def stop(self, timeout_s: float = 30.0) -> Path | None:
        """Stop the simulation thread at the next control step and end (or save) the trace; its path."""
        self._stopping = True
        self.debugger.pause()
        self._queue.put(None)
        if self._thread is not None:
            self._thread.join(timeout_s)
        self.coverage.close()
        gc.unfreeze()
        game = self.debugger.game
        if game is not None:
            try:
                game.close()  # its record ends (as interrupted, unless the game ended)
            except OSError:  # the disk refused the record's last line: it ends at its last whole line
                log.exception("the game's record could not be ended")
        if self.camera_feed is not None:
            self.camera_feed.stop()
        if self.debugger.trace_file is not None:
            how, data = self.ending or (("error", {"message": self.error}) if self.error else ("finished", {}))
            return self.debugger.end_trace(how, **data, clients=len(self.pages))
        if self.trace_path is not None:
            return self.debugger.save_trace(self.trace_path)
        return None

    def call(self, fn: Callable[[Debugger], Any], timeout_s: float = 60.0) -> Any:
        """Run ``fn(debugger)`` in the simulation thread and return its result (tests, the bench)."""
        done = threading.Event()
        box: dict[str, Any] = {}

        def job(dbg: Debugger) -> None:
            try:
                box["value"] = fn(dbg)
            except BaseException as exc:  # handed back to the caller
                box["error"] = exc
            finally:
                done.set()

        self._queue.put((0, Command("_call", {"fn": job})))
        self._wake = True
        if not done.wait(timeout_s):
            raise TimeoutError("the session did not answer")
        if "error" in box:
            raise box["error"]
        return box.get("value")

    def call_soon(self, fn: Callable[[Debugger], Any], done: Callable[[Any, BaseException | None], None],
                  wanted: Callable[[], bool] = lambda: True) -> None:
        """Queue ``fn(debugger)`` for the simulation thread without waiting: ``done(value, error)`` is called
        there with its result (the server's routes, which must not hold a thread while the session is busy).
        ``wanted()`` False when its turn comes (the route gave up waiting): it is not run."""
        def job(dbg: Debugger) -> None:
            if not wanted():
                return
            try:
                value = fn(dbg)
            except Exception as exc:  # handed back to the caller
                done(None, exc)
            else:
                done(value, None)

        self._queue.put((0, Command("_call", {"fn": job})))
        self._wake = True

    def plot_latency_ms(self) -> list[float]:
        """Plot-latency samples so far: a graph's sample taken -> the Operational page has drawn it, ms."""
        return [x * 1e3 for x in self.operate.latency()]

    def latency_ms(self) -> list[float]:
        """Latency samples so far: transition in the simulation -> the page has drawn it, ms."""
        return self.frames.latency_ms()

    # -- what commands call (the simulation thread) -----------------------------------------------------

    def join(self, cid: int, page: str) -> None:
        """Page ``cid`` joins: it gets what runs, a full frame, the coverage shown, then every frame."""
        client = self.pages.get(cid)
        if client is None:
            return
        again = client.joined
        if self._info_text is None:  # what the session runs does not change: serialized once, not per hello
            self._info_text = dumps(jsonable({"type": "session", "info": self.info}))
        if again:  # what runs and a full frame come with the next frame, built once for every page that asked
            client.full_due = self._dirty = True
            return
        client.send(self._info_text)
        self.send_to(cid, self.frames.frame(True, self._status()))
        if self.coverage.shown is not None:
            self.send_to(cid, {"type": "coverage", **self.coverage.shown})
        if self.trace_stopped is not None:
            self.send_to(cid, {"type": "error", "id": None, "command": None, "error": self.trace_stopped})
        self.pages.joined(cid, page)

    def publish(self) -> None:
        """Send every page that joined the next frame (full after a replay or a new game): the one place that
        sends frames."""
        now = time.perf_counter()
        frame = self.frames.next(self._status(), self._resync, now)
        self._resync = False
        text = dumps(jsonable(frame))
        targets, waiting = self.pages.frame_targets(now)
        full_text = None
        for send, due in targets:
            if due:
                send(self._info_text or "")
            if due and not frame["full"]:
                full_text = full_text or dumps(jsonable(self.frames.frame(True, self._status())))
                send(full_text)
            else:
                send(text)
        self._last_frame_at = now
        self._dirty = waiting  # a page's full frame not yet allowed comes with a later frame

    def note_stop(self, reason: StopReason) -> None:
        """Keep why the run stopped (a breakpoint, a step's end, ...), for the frames."""
        self.last_stop = {"kind": reason.kind, "text": reason.describe(), "tick": reason.chart_ticks,
                          "hits": [{"id": h.breakpoint, "spec": h.spec, "chart": h.chart, "tick": h.tick,
                                    "detail": h.detail} for h in reason.hits]}

    @contextlib.contextmanager
    def robot_replaced(self, *, replaying: bool) -> Iterator[None]:
        """Around a call that gives the debugger a new robot: a replay (``replaying``: its transitions are
        counted from power-on, not sent) or a new game (counted from zero after it).  Then every page gets a
        full frame."""
        if replaying:
            self.frames.forget_taken()
            self.frames.forget_pending()
            self.frames.replaying = True
        gc.unfreeze()  # the robot being replaced may be collected
        try:
            yield
        finally:
            self.frames.replaying = False
            self._install_clock()
            freeze_heap()
        if not replaying:
            self.frames.forget_taken()
        self.frames.forget_pending()
        self._resync = True
        self.fault = None  # the robot that raised is gone

    def robot_raised(self, exc: BaseException) -> None:
        """A chart raised while the robot ran (or a command broke off in the middle of a step).

        The arm holds where it stands (its setpoints are where the drives and
        the servo are now), the run pauses, and the robot runs no more: its
        charts may be half way through a tick.  :attr:`fault` says why until
        the robot is built again; the frames carry it as the ``stop``, and each
        of :attr:`fault_listeners` is told.  The session itself goes on.
        """
        log.error("the robot stopped: a chart raised", exc_info=exc)
        robot = self.debugger.robot
        arm = robot.arm
        try:
            arm.set_setpoints([*arm.encoder_angles(), arm.servo_setpoint], False)
        except Exception:  # an arm that cannot take them now (a link down): its own safety holds it
            log.exception("the arm could not be told to hold where it stands")
        self.fault_while_running = self.mode == "running"
        self.mode = "paused"
        message = " ".join(str(exc).split()) or type(exc).__name__
        self.fault = (f"the robot stopped at t = {robot.t:.4f} s, chart tick {robot.chart_ticks}:"
                      f" {type(exc).__name__}: {message}; the arm holds where it stands until the robot is"
                      f" built again")
        self.last_stop = {"kind": "error", "text": self.fault, "tick": robot.chart_ticks, "hits": []}
        self._dirty = True
        for tell in list(self.fault_listeners):
            try:
                tell(exc)
            except Exception:  # a listener's bug must not end the session either
                log.exception("a listener of the robot's fault failed")

    def send_to(self, cid: int, message: dict[str, Any]) -> None:
        """Send one page a message."""
        self.pages.send_to(cid, message)

    def broadcast(self, message: dict[str, Any]) -> None:
        """Send every page that joined a message."""
        self.pages.broadcast(message)

    # -- the simulation thread ----------------------------------------------------------------

    def warn_pages(self, text: str) -> None:
        """Tell every page something went wrong that does not end the session (any thread): an ``error``
        with no command, ``fatal`` false.  The hook for a trace that stops being written (a full disk
        under ``ttt-sm gui --trace``): the session runs on, its pages are told."""
        log.warning("%s", text)
        self.broadcast({"type": "error", "id": None, "command": None, "error": text, "fatal": False})

    def _status(self) -> Status:
        return Status(self.mode, self.speed, self.last_stop, len(self.pages), self.error)
