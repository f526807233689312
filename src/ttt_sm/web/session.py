"""The one running session the cockpit's pages view: a simulation thread over the :class:`Debugger`.

::

    simulation thread:  Debugger.run / step / tick / next / replay  (the one implementation)
        | paced by a PacedClock (x0.1 .. x10, or as fast as it goes), paused by the user or a breakpoint
        | frames: at most FRAME_HZ a second, each the latest state and every transition since the last
        v
    pages  <-- frames, replies --  Session  <-- commands (checked by .protocol) --  pages

Every call into the debugger and the robot happens in the simulation thread;
pages (and the server's event loop) only queue :class:`~.protocol.Command`\\ s
and receive text.  While it runs, the session's clock asks the debugger to
pause between two control steps whenever a frame is due or a command waits,
publishes the frame, handles the commands and runs on, so a frame is never
built from a half-done step, and the pacing keeps absolute deadlines across
these pauses.

A frame is the state now (simulated time, active states, chart data and
signals as text with their units, changed values only) and every transition
taken since the previous frame (at most :data:`MAX_FRAME_TRANSITIONS`, with the
number left out), breakpoints, the last stop, pacing and latency figures.
A page that joins gets one ``full`` frame, then the same frames as everyone.

Bounded in memory: the debugger keeps a bounded number of fingerprints and
the newest transitions of its trace (a ring buffer), the session a bounded
number of pending transitions, frame stamps and latency samples.  The whole
trace is the debugger's trace file when it streams one (``ttt-sm gui
--trace``: written as it happens, ended by :meth:`Session.stop` with how the
cockpit stopped), else :meth:`Session.stop` saves the kept transitions.
"""

from __future__ import annotations

import functools
import gc
import itertools
import logging
import queue
import threading
import time
from collections import deque
from collections.abc import Callable, Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from statemachine import StateChart
from statemachine.transition import Transition

from ..debug.debugger import Debugger
from ..debug.errors import DebugError
from ..debug.records import StopReason
from ..debug.views import fmt_value, signal_text
from ..runtime.jsonable import dumps, jsonable
from ..runtime.structure import TICK_EVENT_NAME, TICK_EVENT_PREFIX
from ..sched.clock import PacedClock
from .arm_view import arm_scene, arm_view
from .camera_feed import CameraFeed, feed_view
from .catalogue import describe_session
from .coverage import CoverageError, colouring, load_scenarios, run_for_coverage, scenario_from_text
from .game import GAME_COMMANDS, game_view, start_new_game
from .operate import Operate
from .protocol import Command

log = logging.getLogger(__name__)

#: Frames a second at most, to every page.
FRAME_HZ = 30.0
#: Transitions sent in one frame at most (the newest); the frame says how many were left out.
MAX_FRAME_TRANSITIONS = 200
#: Transitions of the trace a page gets when it joins (the newest).
TRACE_ON_JOIN = 200
#: One ``Debugger.run`` call while running: the run goes on after it (it is not a stop).
RUN_CHUNK_S = 60.0
#: Latency samples kept for the p95 figure.
LATENCY_SAMPLES = 2000
#: The user's actions (inputs set, events posted) a frame lists, the newest: the page shows the last few,
#: and a session that runs for hours must not send (and describe) every one in every frame.
ACTIONS_SHOWN = 50

Send = Callable[[str], None]


@dataclass
class _Client:
    send: Send
    joined: bool = False
    page: str = ""


class _TransitionTap:
    """Listener on every chart (through :meth:`Debugger.add_listener`): counts and stamps transitions."""

    def __init__(self, session: Session) -> None:
        self._session = session

    def after_transition(self, machine: StateChart, transition: Transition, event: Any) -> None:
        self._session._on_transition(machine, transition, event)


class _SessionClock:
    """The scheduler's clock while the session runs: the pacing, then a pause when a frame is due."""

    paced = True

    def __init__(self, session: Session) -> None:
        self._session = session

    def start(self) -> None:
        self._session.clock.start()

    def wait_period(self, k: int) -> None:
        s = self._session
        if not s._running_slice:
            return
        s.clock.wait_period(k)
        if s._wake or time.perf_counter() >= s._next_frame_at:
            s.debugger.pause()


def safety_view(robot: Any) -> dict[str, Any]:
    """The ``safety`` part of a frame: the Safety chart's declared outputs (docs/safety.md), plain data."""
    chart = robot.safety
    return {"tripped": bool(chart.tripped), "reason": str(chart.reason), "trips": int(chart.trips),
            "reinitialising": bool(chart.reinit)}


class Session:
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
        self._feed_grabs = 0
        robot = debugger.robot
        self.params = robot.params
        self.info = describe_session(debugger)
        self.chart_classes = {name: type(c) for name, c in robot.charts.items()}
        self.scenarios = dict(scenarios or {})
        self.info["scenarios"] = list(self.scenarios)
        self.info["arm"] = arm_scene(self.params)
        self.trace_path = trace_path
        self.clock = PacedClock(self.params.control.dt, speed)
        self.speed = speed
        self.frame_period = 1.0 / frame_hz
        self.mode = "running" if running else "paused"
        self._clients: dict[int, _Client] = {}
        self._client_ids = itertools.count(1)
        self._lock = threading.Lock()
        self._queue: queue.Queue[tuple[int, Command] | None] = queue.Queue()
        self._wake = False
        self._running_slice = False
        self._stopping = False
        self._next_frame_at = 0.0
        self._last_frame_at = 0.0
        self._dirty = True
        self._resync = False
        self._seq = 0
        self._decls = {name: [(d.name, d.unit) for d in c.declarations()] for name, c in robot.charts.items()}
        self._sent: dict[str, Any] = {}
        self._taken: dict[str, dict[int, int]] = {name: {} for name in robot.charts}
        self._pending: deque[dict[str, Any]] = deque(maxlen=MAX_FRAME_TRANSITIONS)
        self._pending_total = 0
        self._pending_stamps: list[float] = []
        self._transition_serial = 0
        self._replaying = False
        self._stop: dict[str, Any] | None = None
        self._stamps: dict[int, list[float]] = {}
        self._latency: deque[float] = deque(maxlen=LATENCY_SAMPLES)
        self._rate_mark = (time.perf_counter(), robot.t)
        self._rate = 0.0
        self._coverage: dict[str, Any] | None = None
        self._coverage_busy = False
        self._worker = ThreadPoolExecutor(max_workers=1, thread_name_prefix="ttt-sm-coverage")
        self._thread: threading.Thread | None = None
        self.error: str | None = None
        #: How the session ends, for the trace file's last line: ``("interrupted", {"signal": "SIGTERM"})``
        #: when a signal stops the server (``ttt-sm gui`` sets it), else finished (or the error).
        self.ending: tuple[str, dict[str, Any]] | None = None
        #: The Operational page's side (web/operate.py): its graphs' samples, Trigger, the precision.
        self.operate = Operate(debugger)
        debugger.add_listener(_TransitionTap(self))
        self._install_clock()

    # -- the pages' side (any thread) -----------------------------------------------------

    def connect(self, send: Send) -> int:
        """A page connects: ``send(text)`` gets its replies and, once it says hello, the frames."""
        cid = next(self._client_ids)
        with self._lock:
            self._clients[cid] = _Client(send)
        return cid

    def disconnect(self, cid: int) -> None:
        """A page is gone; nothing else changes."""
        with self._lock:
            self._clients.pop(cid, None)

    def submit(self, cid: int, command: Command) -> None:
        """Queue a checked command; the simulation thread handles it between two control steps."""
        if command.type == "ack":
            self._ack(command.args["frame"], time.perf_counter())
            return
        self._queue.put((cid, command))
        self._wake = True

    def reply_error(self, cid: int, error: str, command: Command | None = None, msg_id: Any = None) -> None:
        """Send one page an error message (a message that did not pass :mod:`.protocol`, say)."""
        self._send_to(cid, {"type": "error", "id": command.id if command else msg_id,
                            "command": command.type if command else None, "error": error})

    @property
    def clients(self) -> int:
        with self._lock:
            return len(self._clients)

    # -- life -------------------------------------------------------------------------------

    def start(self) -> None:
        """Start the simulation thread."""
        if self._thread is not None:
            return
        if self.camera_feed is not None:
            self.camera_feed.start()
        self._thread = threading.Thread(target=self._main, name="ttt-sm-session", daemon=True)
        self._thread.start()

    def stop(self, timeout_s: float = 30.0) -> Path | None:
        """Stop the simulation thread at the next control step and end (or save) the trace; its path."""
        self._stopping = True
        self.debugger.pause()
        self._queue.put(None)
        if self._thread is not None:
            self._thread.join(timeout_s)
        self._worker.shutdown(wait=False, cancel_futures=True)
        gc.unfreeze()
        game = self.debugger.game
        if game is not None:
            game.close()  # its record ends (as interrupted, unless the game ended)
        if self.camera_feed is not None:
            self.camera_feed.stop()
        if self.debugger.trace_file is not None:
            how, data = self.ending or (("error", {"message": self.error}) if self.error else ("finished", {}))
            return self.debugger.end_trace(how, **data, clients=self.clients)
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

    def plot_latency_ms(self) -> list[float]:
        """Plot-latency samples so far: a graph's sample taken -> the Operational page has drawn it, ms."""
        return [x * 1e3 for x in self.operate.latency()]

    def latency_ms(self) -> list[float]:
        """Latency samples so far: transition in the simulation -> the page has drawn it, ms."""
        with self._lock:
            return [x * 1e3 for x in self._latency]

    # -- the simulation thread ----------------------------------------------------------------

    def _main(self) -> None:
        _freeze_heap()
        try:
            while not self._stopping:
                self._drain()
                if self._stopping:
                    break
                if self.mode == "running":
                    self._run_slice()
                else:
                    self._idle()
                self._flush()
        except Exception as exc:  # the session cannot go on: say so to every page
            log.exception("the session stopped")
            self.error = f"the session stopped: {type(exc).__name__}: {exc}"
            self._broadcast({"type": "error", "id": None, "command": None, "error": self.error})

    def _drain(self) -> None:
        self._wake = False
        while True:
            try:
                item = self._queue.get_nowait()
            except queue.Empty:
                return
            if item is None:
                return
            self._handle(*item)

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

    def _run_slice(self) -> None:
        dbg = self.debugger
        self._next_frame_at = max(self._last_frame_at + self.frame_period, time.perf_counter())
        self._running_slice = True
        try:
            reason = dbg.run(min(RUN_CHUNK_S, dbg.max_run_s))
        finally:
            self._running_slice = False
        self._dirty = True
        if reason.kind not in ("timeout", "paused"):  # a breakpoint, or the game could not go on
            self.mode = "paused"
            self._note_stop(reason)

    def _flush(self) -> None:
        if self.camera_feed is not None and self.camera_feed.grabs != self._feed_grabs:
            self._feed_grabs = self.camera_feed.grabs
            self._dirty = True
        if self._dirty and time.perf_counter() - self._last_frame_at >= self.frame_period * 0.999:
            self._publish()

    def _install_clock(self) -> None:
        self.debugger.robot.sched.set_clock(_SessionClock(self))
        self.clock.restart()

    # -- commands ---------------------------------------------------------------------------

    def _handle(self, cid: int, cmd: Command) -> None:
        if cmd.type == "_call":
            cmd.args["fn"](self.debugger)
            self._dirty = True
            return
        handler = getattr(self, f"_cmd_{cmd.type}", None)
        if handler is None and cmd.type in GAME_COMMANDS:  # the Tic-tac-toe page's (web/game.py)
            handler = functools.partial(_game_command, GAME_COMMANDS[cmd.type], self.debugger)
        if handler is None:
            self.reply_error(cid, f"{cmd.type}: not handled by this session", cmd)
            return
        try:
            result = handler(cid, **cmd.args)
        except (DebugError, CoverageError, ValueError) as exc:
            self.reply_error(cid, f"{cmd.type}: {exc}" if not str(exc).startswith(cmd.type) else str(exc), cmd)
        else:
            if result is not None:
                self._send_to(cid, {"type": "reply", "id": cmd.id, "command": cmd.type, "ok": True, **result})
        self._dirty = True

    def _cmd_hello(self, cid: int, page: str) -> dict[str, Any] | None:
        with self._lock:
            client = self._clients.get(cid)
            if client is None:
                return None
        self._send_to(cid, {"type": "session", "info": self.info})
        frame = self._frame(full=True)
        frame["seq"] = self._seq
        self._send_to(cid, frame)
        if self._coverage is not None:
            self._send_to(cid, {"type": "coverage", **self._coverage})
        with self._lock:
            client.joined, client.page = True, page
        return None

    def _cmd_run(self, cid: int) -> dict[str, Any]:
        self.mode = "running"
        self._stop = None
        self.clock.restart()
        return {"text": "running"}

    def _cmd_pause(self, cid: int) -> dict[str, Any]:
        robot = self.debugger.robot
        if self.mode == "running":
            self.mode = "paused"
            self._stop = {"kind": "paused", "text": f"paused at t = {robot.t:.4f} s, step {robot.steps},"
                          f" chart tick {robot.chart_ticks}", "tick": robot.chart_ticks, "hits": []}
        return {"text": "paused"}

    def _stepping(self, go: Callable[[], StopReason]) -> dict[str, Any]:
        self.mode = "paused"
        reason = go()
        self._note_stop(reason)
        return {"text": reason.describe()}

    def _cmd_step(self, cid: int, n: int) -> dict[str, Any]:
        return self._stepping(lambda: self.debugger.step(n))

    def _cmd_tick(self, cid: int, n: int) -> dict[str, Any]:
        return self._stepping(lambda: self.debugger.tick(n))

    def _cmd_next(self, cid: int, timeout_s: float) -> dict[str, Any]:
        return self._stepping(lambda: self.debugger.next(timeout_s))

    def _cmd_operate_trigger(self, cid: int, symbol: str, magnitude_cm: float, speed: float) -> dict[str, Any]:
        return self.operate.trigger(symbol, magnitude_cm, speed)

    def _cmd_operate_stop(self, cid: int) -> dict[str, Any]:
        return self.operate.stop()

    def _cmd_safety_reset(self, cid: int) -> dict[str, Any]:
        """Reset (docs/safety.md): the Safety chart's ``reset`` event, an input the debugger records."""
        robot = self.debugger.robot
        if not robot.tripped:
            raise ValueError("the Safety chart has not tripped: there is nothing to reset")
        self.debugger.post(robot.safety.chart_name, "reset")
        return {"text": f"Reset: the Safety chart re-initialises the drives (it tripped on: {robot.safety.reason})"}

    def _cmd_speed(self, cid: int, value: float | None) -> dict[str, Any]:
        self.clock.set_speed(value)
        self.speed = value
        return {"text": "as fast as it goes" if value is None else f"x{value:g}"}

    def _cmd_break(self, cid: int, spec: str) -> dict[str, Any]:
        bp = self.debugger.add_breakpoint(spec)
        return {"text": f"breakpoint {bp.id}: {bp.spec}", "breakpoint": bp.id}

    def _cmd_break_delete(self, cid: int, breakpoint: int | None) -> dict[str, Any]:
        self.debugger.delete(breakpoint)
        return {"text": "all breakpoints deleted" if breakpoint is None else f"breakpoint {breakpoint} deleted"}

    def _cmd_break_enable(self, cid: int, breakpoint: int, enabled: bool) -> dict[str, Any]:
        self.debugger.enable(breakpoint, enabled)
        return {"text": f"breakpoint {breakpoint} {'enabled' if enabled else 'disabled'}"}

    def _cmd_set(self, cid: int, chart: str, name: str, value: Any, force: bool) -> dict[str, Any]:
        typed = ("1" if value else "0") if isinstance(value, bool) else str(value)
        got = self.debugger.set_input(chart, name, typed, force=force)
        decl = self.debugger.datum_decl(chart, name)
        return {"text": f"{'forced' if force else 'set'} {chart}.{name} = {fmt_value(got, decl.unit)}"}

    def _cmd_release(self, cid: int, chart: str | None, name: str | None) -> dict[str, Any]:
        if (chart is None) != (name is None):
            raise ValueError("give both 'chart' and 'name' to release one input, or neither to release all")
        released = self.debugger.release(chart, name)
        return {"text": "released " + (", ".join(f"{c}.{n}" for c, n in released) or "nothing")}

    def _cmd_post(self, cid: int, chart: str, event: str, data: dict[str, Any]) -> dict[str, Any]:
        self.debugger.chart(chart)
        # As `post CHART EVENT NAME=VALUE` in ttt-sm debug: a number where it reads as one.
        data = {k: _number_or_text(v) for k, v in data.items()}
        self.debugger.post(chart, event, **data)
        return {"text": f"posted {chart} {event}" + "".join(f" {k}={v}" for k, v in data.items())}

    def _cmd_replay(self, cid: int, tick: int) -> dict[str, Any]:
        dbg = self.debugger
        if tick > dbg.furthest_tick:
            raise DebugError(f"replay: chart tick {tick} lies beyond where this session has been (chart tick"
                             f" {dbg.furthest_tick}); replay goes back, run goes forward")
        self.mode = "paused"
        self._stop = {"kind": "replaying", "text": f"replaying to chart tick {tick} ...", "tick": tick, "hits": []}
        self._publish()
        for counts in self._taken.values():
            counts.clear()
        self._pending.clear()
        self._replaying = True
        gc.unfreeze()  # the robot replay replaces may be collected
        try:
            result = dbg.replay(tick)
        finally:
            self._replaying = False
            self._install_clock()
            _freeze_heap()
        self._pending.clear()
        self._pending_total = 0
        self._pending_stamps = []
        self._stop = {"kind": "replay", "text": result.describe(), "tick": result.tick, "hits": []}
        self._resync = True
        return {"text": result.describe(), "identical": result.identical}

    def _cmd_game_new(self, cid: int) -> dict[str, Any]:
        gc.unfreeze()  # the robot the new game replaces may be collected
        try:
            result = start_new_game(self.debugger)
        finally:
            _freeze_heap()
        for counts in self._taken.values():
            counts.clear()
        self._pending.clear()
        self._pending_total = 0
        self._pending_stamps = []
        self._install_clock()
        self.mode = "paused"
        self._stop = None
        self._resync = True
        return result

    def _cmd_timeline(self, cid: int, chart: str, seconds: float) -> None:
        window = self.debugger.timeline(chart, seconds)
        qnames = {s["id"]: s["qname"] for c in self.info["charts"] if c["name"] == chart for s in c["states"]}
        rows: dict[str, list[tuple[int, int | None]]] = {}
        for state in self.debugger.state_history.states(chart):
            rows[state] = []
        for iv in window.intervals:
            rows.setdefault(iv.state, []).append((max(iv.entered, window.first), iv.left))
        self._send_to(cid, {"type": "timeline", "chart": chart, "first": window.first, "last": window.last,
                            "period_s": window.period_s, "dropped": window.dropped,
                            "rows": [{"state": st, "qname": qnames.get(st, st), "intervals": ivs}
                                     for st, ivs in rows.items() if ivs]})
        return None

    def _coverage_job(self, cid: int, cmd: str, job: Callable[[], dict[str, Any]]) -> dict[str, Any]:
        if self._coverage_busy:
            raise CoverageError("scenarios are running already; wait for their coverage")
        self._coverage_busy = True

        def work() -> None:
            try:
                result = job()
            except (CoverageError, ValueError) as exc:
                self._send_to(cid, {"type": "error", "id": None, "command": cmd, "error": f"{cmd}: {exc}"})
            except Exception as exc:  # a scenario run that broke: say so, keep the session
                log.exception("coverage run failed")
                self._send_to(cid, {"type": "error", "id": None, "command": cmd,
                                    "error": f"{cmd}: {type(exc).__name__}: {exc}"})
            else:
                self._coverage = result
                self._broadcast({"type": "coverage", **result})
            finally:
                self._coverage_busy = False

        self._worker.submit(work)
        return {"text": "running the scenarios; the diagrams are coloured when they are done"}

    def _cmd_coverage_run(self, cid: int, files: list[str]) -> dict[str, Any]:
        scenarios = load_scenarios(files, self.scenarios)
        return self._coverage_job(cid, "coverage_run",
                                  lambda: run_for_coverage(scenarios, self.params, self.chart_classes))

    def _cmd_coverage_scenario(self, cid: int, name: str, text: str) -> dict[str, Any]:
        scenario = scenario_from_text(name, text)
        return self._coverage_job(cid, "coverage_scenario",
                                  lambda: run_for_coverage([scenario], self.params, self.chart_classes))

    def _cmd_coverage_load(self, cid: int, report: dict[str, Any]) -> dict[str, Any]:
        self._coverage = {**colouring(report, self.chart_classes), "source": "report"}
        self._broadcast({"type": "coverage", **self._coverage})
        return {"text": "coverage report loaded"}

    def _cmd_coverage_clear(self, cid: int) -> dict[str, Any]:
        self._coverage = None
        self._broadcast({"type": "coverage", "charts": {}, "ignored": [], "cleared": True})
        return {"text": "coverage cleared"}

    # -- what happened ---------------------------------------------------------------------------

    def _on_transition(self, machine: StateChart, transition: Transition, event: Any) -> None:
        name = str(getattr(machine, "chart_name", type(machine).__name__))
        info = type(machine).structure().by_transition.get(id(transition))  # type: ignore[attr-defined]
        counts = self._taken.setdefault(name, {})
        if info is not None:
            counts[info.index] = counts.get(info.index, 0) + 1
        if self._replaying:
            return
        event_id = str(event) if event is not None else ""
        self._transition_serial += 1
        self._pending_total += 1
        self._pending.append({
            "n": self._transition_serial, "tick": getattr(machine, "tick_count", None),
            "time_s": getattr(machine, "time_s", None), "chart": name, "source": transition.source.id,
            "target": transition.target.id if transition.target is not None else None,
            "trigger": TICK_EVENT_NAME if event_id.startswith(TICK_EVENT_PREFIX) else event_id,
            "index": None if info is None else info.index,
        })
        if len(self._pending_stamps) < MAX_FRAME_TRANSITIONS:
            self._pending_stamps.append(time.perf_counter())

    def _note_stop(self, reason: StopReason) -> None:
        self._stop = {"kind": reason.kind, "text": reason.describe(), "tick": reason.chart_ticks,
                      "hits": [{"id": h.breakpoint, "spec": h.spec, "chart": h.chart, "tick": h.tick,
                                "detail": h.detail} for h in reason.hits]}

    # -- frames ---------------------------------------------------------------------------------------

    def _state(self) -> dict[str, Any]:
        """Everything a frame may carry, now, as text where a person reads it."""
        dbg = self.debugger
        robot = dbg.robot
        data = {}
        for name, chart in robot.charts.items():
            values = chart.snapshot()
            data[name] = {n: fmt_value(values[n], unit) for n, unit in self._decls[name]}
        signals = {n: signal_text(n, v) for n, v in robot.signal_values().items()}
        return {
            "data": data,
            "signals": signals,
            "taken": {name: dict(c) for name, c in self._taken.items()},
            "breakpoints": [{"id": bp.id, "spec": bp.spec, "enabled": bp.enabled, "hits": bp.hits,
                             "text": bp.describe()} for bp in dbg.breakpoints],
            "actions": [a.describe() for a in dbg.actions[-ACTIONS_SHOWN:]],
            "forced": [f"{c}.{n}" for c, n in dbg.forced],
            "stop": self._stop,
            "game": game_view(dbg),
            "arm": arm_view(robot),
            "camera": feed_view(self.camera_feed),
            "operate": self.operate.view(),
            "safety": safety_view(robot),
        }

    def _frame(self, full: bool, state: dict[str, Any] | None = None) -> dict[str, Any]:
        dbg = self.debugger
        robot = dbg.robot
        state = state if state is not None else self._state()
        stats = self.clock.stats()
        with self._lock:
            lat = sorted(self._latency)
        frame: dict[str, Any] = {
            "type": "frame", "full": full, "seq": self._seq,
            "t": robot.t, "steps": robot.steps, "tick": robot.chart_ticks, "furthest_tick": dbg.furthest_tick,
            "mode": self.mode, "speed": "max" if self.speed is None else self.speed,
            "initialised": robot.initialised,
            "active": {name: sorted(c.configuration_values) for name, c in robot.charts.items()},
            "pace": {"lag_ms": round(stats.lag_s * 1e3, 3), "lag_max_ms": round(stats.lag_max_s * 1e3, 3),
                     "overruns": stats.overruns, "slips": stats.slips, "lost_s": round(stats.lost_s, 3),
                     "realtime_factor": round(self._rate, 2)},
            "latency": {"p95_ms": round(lat[int(0.95 * (len(lat) - 1))] * 1e3, 1) if lat else None,
                        "samples": len(lat)},
            "transitions": list(self._pending) if not full else [],
            "transitions_total": self._pending_total if not full else 0,
            "clients": self.clients,
            "error": self.error,
        }
        if full:
            frame.update(state)
            frame["trace"] = [{"tick": r.tick, "time_s": r.time_s, "chart": r.chart, "source": r.source,
                               "target": r.target, "trigger": r.trigger}
                              for r in dbg.trace.records[-TRACE_ON_JOIN:]]
            frame["trace_total"] = dbg.trace.count
            frame["plot"] = self.operate.plot_history()
            return frame
        sent = self._sent
        for key in ("data",):
            frame[key] = {name: {n: v for n, v in values.items() if sent.get(key, {}).get(name, {}).get(n) != v}
                          for name, values in state[key].items()}
            frame[key] = {name: values for name, values in frame[key].items() if values}
        frame["signals"] = {n: v for n, v in state["signals"].items() if sent.get("signals", {}).get(n) != v}
        frame["taken"] = {name: {i: c for i, c in counts.items() if sent.get("taken", {}).get(name, {}).get(i) != c}
                          for name, counts in state["taken"].items()}
        frame["taken"] = {name: counts for name, counts in frame["taken"].items() if counts}
        for key in ("breakpoints", "actions", "forced", "stop", "game", "arm", "camera", "operate", "safety"):
            if sent.get(key, _MISSING) != state[key]:
                frame[key] = state[key]
        return frame

    def _publish(self) -> None:
        now = time.perf_counter()
        robot = self.debugger.robot
        mark_wall, mark_t = self._rate_mark
        if now - mark_wall >= 0.5:
            self._rate = (robot.t - mark_t) / (now - mark_wall) if self.mode == "running" else 0.0
            self._rate_mark = (now, robot.t)
        state = self._state()
        self._seq += 1
        full = self._resync
        frame = self._frame(full, state)
        frame["seq"] = self._seq
        plot = self.operate.plot_since(self._seq)  # taken always: a full frame has them in its history
        if plot is not None and not full:
            frame["plot"] = plot
        if self._pending_stamps:
            self._stamps[self._seq] = self._pending_stamps
            if len(self._stamps) > 256:
                for old in sorted(self._stamps)[:-256]:
                    del self._stamps[old]
        self._sent = state
        self._pending.clear()
        self._pending_total = 0
        self._pending_stamps = []
        self._resync = False
        self._broadcast(frame)
        self._last_frame_at = now
        self._dirty = False

    def _ack(self, seq: int, received: float) -> None:
        self.operate.ack(seq, received)
        stamps = self._stamps.pop(seq, None)
        if stamps:
            with self._lock:
                self._latency.extend(received - s for s in stamps)

    # -- sending ---------------------------------------------------------------------------------------------

    def _broadcast(self, message: dict[str, Any]) -> None:
        text = dumps(jsonable(message))
        with self._lock:
            targets = [c.send for c in self._clients.values() if c.joined]
        for send in targets:
            send(text)

    def _send_to(self, cid: int, message: dict[str, Any]) -> None:
        with self._lock:
            client = self._clients.get(cid)
        if client is not None:
            client.send(dumps(jsonable(message)))


_MISSING = object()


def _freeze_heap() -> None:
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


def _game_command(command: Callable[..., dict[str, Any]], debugger: Debugger, cid: int,
                  **args: Any) -> dict[str, Any]:
    return command(debugger, **args)


def _number_or_text(value: Any) -> Any:
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            return value
    return value
