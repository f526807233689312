"""What the session sends its pages: frames, each the state now and every transition since the last.

A frame is the state now (simulated time, active states, chart data and
signals as text with their units, changed values only) and every transition
taken since the previous frame (at most :data:`MAX_FRAME_TRANSITIONS`, with the
number left out), breakpoints, the last stop, pacing and latency figures, and
each page's own part (``game``, ``arm``, ``camera``, ``operate``, ``safety``).
A page that joins gets one ``full`` frame, then the same frames as everyone.

:class:`Frames` is called from the simulation thread only (but for
:meth:`Frames.ack` and :meth:`Frames.latency_ms`): it counts and stamps the
transitions as the charts take them (:class:`TransitionTap`, a listener on
every chart), and builds each frame against what the frame before carried.
Bounded in memory: a bounded number of pending transitions, frame stamps and
latency samples.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from dataclasses import dataclass
from typing import Any

from statemachine import StateChart
from statemachine.transition import Transition

from ..debug.debugger import Debugger
from ..debug.views import fmt_value, signal_text
from ..runtime.structure import TICK_EVENT_NAME, TICK_EVENT_PREFIX
from ..sched.clock import PacedClock
from .arm_view import arm_view
from .camera_feed import CameraFeed, feed_view
from .game import game_view
from .operate import Operate

#: Transitions sent in one frame at most (the newest); the frame says how many were left out.
MAX_FRAME_TRANSITIONS = 200
#: Transitions of the trace a page gets when it joins (the newest).
TRACE_ON_JOIN = 200
#: Latency samples kept for the p95 figure.
LATENCY_SAMPLES = 2000
#: The user's actions (inputs set, events posted) a frame lists, the newest: the page shows the last few,
#: and a session that runs for hours must not send (and describe) every one in every frame.
ACTIONS_SHOWN = 50
#: Frames whose transitions' stamps are kept until the page acknowledges them (the newest).
STAMPED_FRAMES = 256

#: The parts of a frame sent whole when they changed (data, signals and taken counts go value by value).
_WHOLE_PARTS = ("breakpoints", "actions", "forced", "stop", "game", "arm", "camera", "operate", "safety", "drive1")
_MISSING = object()


@dataclass(frozen=True)
class Status:
    """What a frame says of the session itself, beside the robot."""

    #: ``"running"`` or ``"paused"``.
    mode: str
    #: Times real time, or None: as fast as it goes.
    speed: float | None
    #: Why the run stopped last, or None.
    stop: dict[str, Any] | None
    #: Pages connected.
    clients: int
    #: Why the session could not go on, or None.
    error: str | None


def safety_view(robot: Any) -> dict[str, Any]:
    """The ``safety`` part of a frame: the Safety chart's declared outputs (docs/safety.md), plain data."""
    chart = robot.safety
    return {"tripped": bool(chart.tripped), "reason": str(chart.reason), "trips": int(chart.trips),
            "reinitialising": bool(chart.reinit)}


def drive1_view(robot: Any) -> dict[str, Any]:
    """The ``drive1`` part of a frame: drive 1's ``stop`` input and whether its chart is in ``stopped``."""
    chart = robot.chart("DriveInit1")
    return {"stop": bool(chart.stop), "stopped": "stopped" in chart.configuration_values}


class TransitionTap:
    """Listener on every chart (through :meth:`Debugger.add_listener`): hands each transition to :class:`Frames`."""

    def __init__(self, frames: Frames) -> None:
        self._frames = frames

    def after_transition(self, machine: StateChart, transition: Transition, event: Any) -> None:
        self._frames.on_transition(machine, transition, event)


class Frames:
    """The frames of one session: the transitions since the last frame, and the last frame's values to diff.

    Parameters
    ----------
    debugger : Debugger
        The session's debugger (its robot changes on a replay or a new game; its charts' names do not).
    clock : PacedClock
        The session's pacing, for the frames' ``pace`` figures.
    operate : Operate
        The Operational page's side: its ``operate`` part and its graphs' samples.
    camera_feed : CameraFeed, optional
        A camera outside the simulation: its ``camera`` part.
    """

    def __init__(self, debugger: Debugger, clock: PacedClock, operate: Operate,
                 camera_feed: CameraFeed | None = None) -> None:
        self.debugger = debugger
        self.clock = clock
        self.operate = operate
        self.camera_feed = camera_feed
        robot = debugger.robot
        #: The number of the last frame sent.
        self.seq = 0
        #: While a replay runs: transitions are counted (``taken``), not sent.
        self.replaying = False
        self._decls = {name: [(d.name, d.unit) for d in c.declarations()] for name, c in robot.charts.items()}
        self._sent: dict[str, Any] = {}
        self._taken: dict[str, dict[int, int]] = {name: {} for name in robot.charts}
        self._pending: deque[dict[str, Any]] = deque(maxlen=MAX_FRAME_TRANSITIONS)
        self._pending_total = 0
        self._pending_stamps: list[float] = []
        self._transition_serial = 0
        self._stamps: dict[int, list[float]] = {}
        self._lock = threading.Lock()
        self._latency: deque[float] = deque(maxlen=LATENCY_SAMPLES)
        self._rate_mark = (time.perf_counter(), robot.t)
        self._rate = 0.0
        debugger.add_listener(TransitionTap(self))

    # -- what happened ---------------------------------------------------------------------------

    def on_transition(self, machine: StateChart, transition: Transition, event: Any) -> None:
        """A chart took ``transition``: counted, and (but in a replay) kept for the next frame with its time."""
        name = str(getattr(machine, "chart_name", type(machine).__name__))
        info = type(machine).structure().by_transition.get(id(transition))  # type: ignore[attr-defined]
        counts = self._taken.setdefault(name, {})
        if info is not None:
            counts[info.index] = counts.get(info.index, 0) + 1
        if self.replaying:
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

    def forget_taken(self) -> None:
        """Count every transition from zero again (the robot starts over)."""
        for counts in self._taken.values():
            counts.clear()

    def forget_pending(self) -> None:
        """Send none of the transitions since the last frame (a replay's, a robot's before it started over)."""
        self._pending.clear()
        self._pending_total = 0
        self._pending_stamps = []

    # -- frames ---------------------------------------------------------------------------------------

    def state(self, stop: dict[str, Any] | None) -> dict[str, Any]:
        """Everything a frame may carry of the robot now, as text where a person reads it."""
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
            "stop": stop,
            "game": game_view(dbg),
            "arm": arm_view(robot),
            "camera": feed_view(self.camera_feed),
            "operate": self.operate.view(),
            "safety": safety_view(robot),
            "drive1": drive1_view(robot),
        }

    def frame(self, full: bool, status: Status, state: dict[str, Any] | None = None) -> dict[str, Any]:
        """A frame numbered :attr:`seq`: ``full`` (all of it, for a page that joins) or what changed since the
        last one sent, with the transitions since."""
        dbg = self.debugger
        robot = dbg.robot
        state = state if state is not None else self.state(status.stop)
        stats = self.clock.stats()
        with self._lock:
            lat = sorted(self._latency)
        frame: dict[str, Any] = {
            "type": "frame", "full": full, "seq": self.seq,
            "t": robot.t, "steps": robot.steps, "tick": robot.chart_ticks, "furthest_tick": dbg.furthest_tick,
            "mode": status.mode, "speed": "max" if status.speed is None else status.speed,
            "initialised": robot.initialised,
            "active": {name: sorted(c.configuration_values) for name, c in robot.charts.items()},
            "pace": {"lag_ms": round(stats.lag_s * 1e3, 3), "lag_max_ms": round(stats.lag_max_s * 1e3, 3),
                     "overruns": stats.overruns, "slips": stats.slips, "lost_s": round(stats.lost_s, 3),
                     "realtime_factor": round(self._rate, 2)},
            "latency": {"p95_ms": round(lat[int(0.95 * (len(lat) - 1))] * 1e3, 1) if lat else None,
                        "samples": len(lat)},
            "transitions": list(self._pending) if not full else [],
            "transitions_total": self._pending_total if not full else 0,
            "clients": status.clients,
            "error": status.error,
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
        data = {name: {n: v for n, v in values.items() if sent.get("data", {}).get(name, {}).get(n) != v}
                for name, values in state["data"].items()}
        frame["data"] = {name: values for name, values in data.items() if values}
        frame["signals"] = {n: v for n, v in state["signals"].items() if sent.get("signals", {}).get(n) != v}
        taken = {name: {i: c for i, c in counts.items() if sent.get("taken", {}).get(name, {}).get(i) != c}
                 for name, counts in state["taken"].items()}
        frame["taken"] = {name: counts for name, counts in taken.items() if counts}
        for key in _WHOLE_PARTS:
            if sent.get(key, _MISSING) != state[key]:
                frame[key] = state[key]
        return frame

    def next(self, status: Status, full: bool, now: float) -> dict[str, Any]:
        """The next frame to every page (``full``: all of it, after a replay or a new game), at time ``now``;
        what it carried becomes what the one after is diffed against."""
        robot = self.debugger.robot
        mark_wall, mark_t = self._rate_mark
        if now - mark_wall >= 0.5:
            self._rate = (robot.t - mark_t) / (now - mark_wall) if status.mode == "running" else 0.0
            self._rate_mark = (now, robot.t)
        state = self.state(status.stop)
        self.seq += 1
        frame = self.frame(full, status, state)
        plot = self.operate.plot_since(self.seq)  # taken always: a full frame has them in its history
        if plot is not None and not full:
            frame["plot"] = plot
        if self._pending_stamps:
            self._stamps[self.seq] = self._pending_stamps
            if len(self._stamps) > STAMPED_FRAMES:
                for old in sorted(self._stamps)[:-STAMPED_FRAMES]:
                    del self._stamps[old]
        self._sent = state
        self.forget_pending()
        return frame

    # -- latency -------------------------------------------------------------------------------------

    def ack(self, seq: int, received: float) -> None:
        """A page has drawn frame ``seq`` at ``received`` (``time.perf_counter``): its transitions' latency."""
        self.operate.ack(seq, received)
        stamps = self._stamps.pop(seq, None)
        if stamps:
            with self._lock:
                self._latency.extend(received - s for s in stamps)

    def latency_ms(self) -> list[float]:
        """Latency samples so far: transition in the simulation -> the page has drawn it, ms."""
        with self._lock:
            return [x * 1e3 for x in self._latency]
