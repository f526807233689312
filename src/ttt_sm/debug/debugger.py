"""The step-through debugger's engine: run, pause, step, breakpoints, inputs, replay.

:class:`Debugger` drives a :class:`~ttt_sm.app.robot.Robot` one control step
at a time and stops *between control steps*.  A chart tick is the first part
of the control step it starts (every ``chart_divider``-th step), so when a
breakpoint hits at chart tick *k* the debugger stops right after the control
step holding tick *k*: the charts show the configuration and data that tick
produced, and the twin has moved one control step (1 ms) since.

It watches the charts through python-statemachine listeners only (a
:class:`~ttt_sm.runtime.listeners.Trace` and a
:class:`~.breakpoints.BreakListener`), so it sees exactly what the library did.

Everything the user changes (inputs set or forced, events posted) is recorded
with the control step it was applied at; :meth:`Debugger.replay` rebuilds the
robot from its recipe (parameters, seed, power-on pose), re-applies them at the
same steps and runs to a chart tick, and tells whether it arrived in exactly the
state recorded when the session was there before.

A robot built with the game (:class:`~.replay.GameRecipe`, ``ttt-sm debug
--game``) carries the Game and AlgorithmActivator charts and plays its game
from inside the chart steps (the simulated person, the camera, the engine):
stepping the robot plays the game, and a breakpoint on ``Game.drawing``
stops at the robot's turn.

Besides the trace it keeps a :class:`~.timeline.Timeline` (when each state
was entered and left) and the charts' data as they were just before the last
chart tick, for :meth:`Debugger.data_diff`.

Bounded in memory: the trace keeps the newest :data:`TRACE_KEEP` transitions
(a ring buffer); given a ``trace_path``, the whole trace is streamed to that
file as it happens, each line flushed (:class:`~ttt_sm.runtime.recordfile.RecordFile`:
a head line, the transitions, a mark at each replay, and an ending that
says how the session ended, written by :meth:`Debugger.end_trace`).
"""

from __future__ import annotations

import math
import operator
import signal
import threading
from collections import deque
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from ..app.game import GameSession
from ..app.game_errors import GameError
from ..app.robot import Robot, RobotError
from ..arm import Arm
from ..params import ArmParams
from ..runtime import Data, TickChart, UnknownEventError
from ..runtime.errors import GraphvizMissingError
from ..runtime.export import render_active
from ..runtime.listeners import Trace
from ..runtime.recordfile import RecordFile
from ..twin.truth import GroundTruth
from .breakpoints import BreakListener, Breakpoint, ChartIndex, Hit, parse_breakpoint
from .errors import DebugError
from .names import RobotNames, datum_decl, parse_input_value
from .records import Action, DataChange, DataDiff, StopKind, StopReason
from .replay import ArmRecipe, GameRecipe, Recipe, ReplayResult, RobotRecipe, differences, fingerprint, game_of
from .timeline import Timeline, TimelineWindow

#: The longest one command (run, next, step, tick) may run unless raised, seconds of
#: simulated time: a typo like ``run 1e12`` would never end.  ``ttt-sm debug --max-run``.
DEFAULT_MAX_RUN_S = 600.0
#: A long run tells :attr:`Debugger.progress` where it is every this many simulated seconds.
PROGRESS_EVERY_S = 5.0
#: At most this many fingerprints are kept to check replays against (each a few kB): past
#: it every other old one is dropped, so a session that runs for hours (a GUI calls the
#: debugger 30 times a second) holds them spread over its whole run in bounded memory.
MAX_FINGERPRINTS = 512
#: Transitions the trace keeps in memory (the newest); the trace file, if any, gets them all.
TRACE_KEEP = 5000


class Debugger:
    """Step through a :class:`Robot`'s charts: the API under ``ttt-sm debug`` (and a GUI).

    Parameters
    ----------
    robot : Robot
        The robot to debug.  Listeners are added to its charts.
    recipe : Recipe, optional
        How to build the same robot again, for :meth:`replay`.  By default it
        is read from the robot when it has not run yet (parameters, seed and
        the pose it was powered on in); :meth:`build` records it too.
    max_run_s : float
        The longest one command may run, seconds of simulated time
        (:data:`DEFAULT_MAX_RUN_S`); longer is refused before a step is taken.
    trace_path : path, optional
        Stream the whole trace to this file as it happens (JSON Lines, each
        line flushed); opened now, so an ``OSError`` says it cannot be written
        before anything runs.  :meth:`end_trace` writes its last line.
    trace_keep : int
        Transitions kept in memory (:data:`TRACE_KEEP`), the newest.
    """

    def __init__(self, robot: Robot, recipe: Recipe | None = None, *,
                 max_run_s: float = DEFAULT_MAX_RUN_S, trace_path: str | Path | None = None,
                 trace_keep: int = TRACE_KEEP) -> None:
        if recipe is None and robot.steps == 0:
            recipe = RobotRecipe.of(robot)
        if not (isinstance(max_run_s, (int, float)) and math.isfinite(max_run_s) and max_run_s > 0):
            raise DebugError(f"max_run_s must be a positive number of seconds, got {max_run_s!r}")
        self.recipe = recipe
        self.max_run_s = float(max_run_s)
        #: ``progress(t, t_end)``, called every :data:`PROGRESS_EVERY_S` of simulated time while a
        #: command runs (the REPL shows it on a terminal); None: silent.
        self.progress: Callable[[float, float], None] | None = None
        self._furthest_steps = robot.steps
        self.breakpoints: list[Breakpoint] = []
        self.listener = BreakListener(self.breakpoints)
        self.actions: list[Action] = []
        self.forced: dict[tuple[str, str], Any] = {}
        self._next_id = 1
        self._pause = threading.Event()
        self._fingerprints: dict[int, dict[str, Any]] = {}
        self._names = RobotNames(lambda: self.robot)
        self._listeners: list[object] = []
        self.trace_keep = trace_keep
        #: The file the whole trace streams to (None: the kept transitions only).
        self.trace_file: RecordFile | None = None
        if trace_path is not None:
            self.trace_file = RecordFile(trace_path)
            self.trace_file.add(self._trace_head(robot))
        self._attach(robot)
        self._remember()

    @classmethod
    def build(cls, params: ArmParams, seed: int = 0, q_start: Sequence[float] | None = None,
              settle_s: float = 0.0, *, game: bool = False, person: str = "simulated",
              max_run_s: float = DEFAULT_MAX_RUN_S, trace_path: str | Path | None = None,
              record_root: Path | None = None, arm: Arm | None = None,
              truth: GroundTruth | None = None) -> Debugger:
        """A debugger on a new robot, with its recipe for :meth:`replay`.

        ``game``: the robot plays a game (:class:`~.replay.GameRecipe`: the Game
        and AlgorithmActivator charts, a simulated person, the camera read
        in-process, the strong engine; the robot draws O).  ``person``: who plays
        against it, ``"simulated"`` or ``"page"`` (a person at the ``/game`` page).
        ``trace_path``: stream the whole trace there (see the class).
        ``record_root``: with ``game``, the game's record is written to
        ``record_root/game-1/game.jsonl`` as it is played.
        ``arm`` (and the ``truth`` it offers): another arm than the twin
        (``--arm serial:PORT``); the robot is built on it once (no replay).
        """
        if arm is not None:
            arm_recipe = ArmRecipe(params, arm, truth, seed, game=game, person=person, record_root=record_root)
            return cls(arm_recipe.build(), arm_recipe, max_run_s=max_run_s, trace_path=trace_path)
        pose = None if q_start is None else tuple(float(v) for v in q_start)
        recipe: Recipe = GameRecipe(params, seed, pose, settle_s, person=person, record_root=record_root) \
            if game else RobotRecipe(params, seed, pose, settle_s)
        return cls(recipe.build(), recipe, max_run_s=max_run_s, trace_path=trace_path)

    def _attach(self, robot: Robot) -> None:
        self.robot = robot
        self.trace = Trace(sink=self.trace_file, limit=self.trace_keep)
        self.state_history = Timeline()
        for chart in robot.charts.values():
            chart.add_listener(self.trace, self.listener, *self._listeners)
        self.state_history.observe(robot.charts.values())
        self._divider = robot.params.control.chart_divider
        self._dt = robot.params.control.dt
        self._watch_charts(robot)
        self._before: list[Any] | None = None
        self._before_tick = 0
        self._game_stopped = _game_error(robot) is not None
        robot.charts_replaced.append(self._charts_replaced)

    def _watch_charts(self, robot: Robot) -> None:
        self._index = ChartIndex(dict(robot.charts))
        self._names.forget()
        # The charts' data just before the last chart tick (for data_diff): one
        # itemgetter per chart over its data (the instance dict, or a buffered chart's view).
        self._data_getters = [(name, [d.name for d in c.declarations()], c.data_mapping())
                              for name, c in robot.charts.items()]
        self._getters = [(_values_of(names), d) for _, names, d in self._data_getters]

    def _charts_replaced(self, charts: Sequence[TickChart]) -> None:
        """The Safety chart's reset gave the robot new drive-initialisation and Control charts
        (:meth:`Robot.reinitialise`): the trace, the breakpoints, the timeline and every view see them."""
        for chart in charts:
            chart.add_listener(self.trace, self.listener, *self._listeners)
        self.state_history.observe(charts)
        self._watch_charts(self.robot)

    @property
    def game(self) -> GameSession | None:
        """The game around the charts (``build(..., game=True)``), else None."""
        return game_of(self.robot)

    def add_listener(self, listener: object) -> None:
        """Attach a python-statemachine listener to every chart, now and after each replay's rebuild.

        A view over the session (a GUI counting the transitions taken) sees
        the charts the debugger runs, whichever robot that is.
        """
        self._listeners.append(listener)
        for chart in self.robot.charts.values():
            chart.add_listener(listener)

    # -- where we are ------------------------------------------------------------

    @property
    def chart_names(self) -> list[str]:
        return list(self.robot.charts)

    def chart(self, name: str) -> TickChart:
        """A chart by name; :class:`DebugError` names the charts there are."""
        self._index.structure(name)
        return self.robot.charts[name]

    def where(self) -> dict[str, list[str]]:
        """Each chart's active states, outermost first (document order)."""
        out = {}
        for name, chart in self.robot.charts.items():
            active = set(chart.configuration_values)
            out[name] = [s.id for s in type(chart).structure().states if s.id in active]
        return out

    def signals(self) -> dict[str, Any]:
        """The robot's signals now (SI units)."""
        return self.robot.signal_values()

    def datum_decl(self, chart: str, name: str) -> Data:
        """The declaration of a chart datum (name, unit, default, doc, kind)."""
        return datum_decl(self.robot, chart, name)

    def timeline(self, chart: str, seconds: float | None = None) -> TimelineWindow:
        """When the chart's states were entered and left, over the last ``seconds`` of chart
        time (None: all the bounded history holds); see :class:`~.timeline.Timeline`."""
        c = self.chart(chart)
        if seconds is not None and not (isinstance(seconds, (int, float)) and math.isfinite(seconds)
                                        and seconds > 0):
            raise DebugError(f"timeline: the time must be a positive number of seconds, got {seconds!r}")
        period = c.tick_period_s or self.robot.params.control.chart_dt
        return self.state_history.window(chart, c.tick_count, period, seconds)

    def data_diff(self, chart: str | None = None) -> DataDiff | None:
        """The chart data that changed since just before the last chart tick (None: no tick run yet).

        ``chart``: one chart, or every chart.  The values before the tick are
        kept as the debugger runs each chart tick, at the cost of one copy of
        the declared data per tick.
        """
        if chart is not None:
            self.chart(chart)
        if self._before is None:
            return None
        changes: list[DataChange] = []
        for (name, names, d), before in zip(self._data_getters, self._before, strict=True):
            if chart is not None and name != chart:
                continue
            decls = {x.name: x for x in self.robot.charts[name].declarations()}
            for datum, old in zip(names, before, strict=True):
                new = d[datum]
                if not _same(old, new):
                    decl = decls[datum]
                    changes.append(DataChange(name, datum, decl.kind, decl.unit, old, new))
        return DataDiff(self._before_tick, tuple(changes))

    # -- breakpoints -------------------------------------------------------------

    def add_breakpoint(self, text: str) -> Breakpoint:
        """Add a breakpoint from its command text, e.g. ``"enter DriveInit1.turn_back"``,
        ``"transition DriveInit1 turn_fwd->turn_back"``, ``"event DriveInit1.tick"``,
        ``"when DriveInit1.pos_Encoder > 1.0"``."""
        bp = parse_breakpoint(self._next_id, text, self._index, self._names)
        if bp.condition is not None:
            bp.last_value = bp.condition.evaluate(self._names)
        self._next_id += 1
        self.breakpoints.append(bp)
        return bp

    def _find(self, bp_id: int) -> Breakpoint:
        for bp in self.breakpoints:
            if bp.id == bp_id:
                return bp
        known = ", ".join(str(b.id) for b in self.breakpoints) or "none"
        raise DebugError(f"no breakpoint {bp_id}; breakpoints: {known}")

    def delete(self, bp_id: int | None = None) -> None:
        """Delete one breakpoint, or all of them (``None``)."""
        if bp_id is None:
            self.breakpoints.clear()
        else:
            self.breakpoints.remove(self._find(bp_id))

    def enable(self, bp_id: int, enabled: bool = True) -> None:
        bp = self._find(bp_id)
        if enabled and not bp.enabled and bp.condition is not None:
            bp.last_value = bp.condition.evaluate(self._names)  # hits when it *becomes* true
        bp.enabled = enabled

    def disable(self, bp_id: int) -> None:
        self.enable(bp_id, False)

    # -- running -----------------------------------------------------------------

    def pause(self) -> None:
        """Ask a running :meth:`run` / :meth:`next` to stop after the current control step.

        Safe to call from another thread (a GUI's pause button).
        """
        self._pause.set()

    def step(self, n: int = 1) -> StopReason:
        """Run ``n`` control steps (fewer if a breakpoint hits)."""
        _check_count(n, "step")
        self._check_bound(n * self._dt, "step", f"{n} control steps ({n * self._dt:g} s)")
        return self._advance(n, end="done")

    def tick(self, n: int = 1) -> StopReason:
        """Run up to and through the next ``n`` chart ticks (fewer if a breakpoint hits)."""
        _check_count(n, "tick")
        seconds = n * self._divider * self._dt
        self._check_bound(seconds, "tick", f"{n} chart ticks ({seconds:g} s)")
        return self._advance((n + 1) * self._divider, ticks=n, end="done")

    def next(self, timeout_s: float = 10.0) -> StopReason:
        """Run until some chart takes a transition, at most ``timeout_s`` simulated seconds."""
        return self._advance(self._steps_for(timeout_s, "next"), until_transition=True, end="timeout")

    def run(self, max_seconds: float = 60.0) -> StopReason:
        """Run until a breakpoint hits, ``max_seconds`` of simulated time pass, or a pause."""
        return self._advance(self._steps_for(max_seconds, "run"), end="timeout")

    def _steps_for(self, seconds: float, what: str) -> int:
        if not (isinstance(seconds, (int, float)) and math.isfinite(seconds) and seconds > 0):
            raise DebugError(f"{what}: the time must be a positive number of seconds, got {seconds!r}")
        self._check_bound(seconds, what, f"{seconds:g} s")
        return max(1, int(round(seconds / self._dt)))

    def _check_bound(self, seconds: float, what: str, asked: str) -> None:
        if seconds > self.max_run_s * (1 + 1e-9):
            raise DebugError(f"{what}: {asked} is beyond {self.max_run_s:g} s of simulated time, the longest one"
                             f" command runs (start the debugger with --max-run SECONDS to allow more)")

    def _advance(self, max_steps: int, *, ticks: int | None = None, until_transition: bool = False,
                 end: StopKind = "timeout") -> StopReason:
        robot = self.robot
        listener = self.listener
        charts = list(robot.charts.values())
        divider = self._divider
        listener.hits.clear()
        self._pause.clear()
        trace = self.trace
        first = trace.count
        ticks_done = 0
        kind: StopKind = end
        when = [bp for bp in self.breakpoints if bp.enabled and bp.kind == "when"]
        watch_events = any(bp.enabled and bp.kind == "event" for bp in self.breakpoints)
        report_every = max(1, int(round(PROGRESS_EVERY_S / self._dt)))
        t_end = robot.t + max_steps * self._dt
        game_error = self._game_error_now
        with self._sigint_pauses():
            for done in range(1, max_steps + 1):
                ticking = robot.steps % divider == 0
                pending = [[e for e, _ in c.pending_events] for c in charts] \
                    if ticking and watch_events else None
                mark = trace.count
                if ticking:
                    self._keep_before_tick()
                robot.control_step()
                if ticking:
                    ticks_done += 1
                    if pending is not None:
                        for chart, events in zip(charts, pending, strict=True):
                            if events:
                                listener.events_handled(chart, events)
                    if when:
                        self._check_conditions(when)
                if listener.hits:
                    kind = "breakpoint"
                    break
                if ticking and game_error():
                    kind = "game"
                    break
                if until_transition and trace.count > mark:
                    kind = "transition"
                    break
                if ticks is not None and ticks_done >= ticks:
                    kind = "done"
                    break
                if self._pause.is_set():
                    kind = "paused"
                    break
                if self.progress is not None and done % report_every == 0:
                    self.progress(robot.t, t_end)
        self._remember()
        detail = str(_game_error(robot)) if kind == "game" else ""
        return StopReason(kind, robot.t, robot.steps, robot.chart_ticks, tuple(listener.hits),
                          tuple(trace.since(first)), detail)

    def _game_error_now(self) -> bool:
        """The game's flow stopped with an error in the chart step just run (reported once)."""
        if self._game_stopped or _game_error(self.robot) is None:
            return False
        self._game_stopped = True
        return True

    def _keep_before_tick(self) -> None:
        self._before = [get(d) for get, d in self._getters]
        self._before_tick = self.robot.chart_ticks + 1

    def _check_conditions(self, when: list[Breakpoint]) -> None:
        tick = self.robot.chart_ticks
        for bp in when:
            assert bp.condition is not None
            value = bp.condition.evaluate(self._names)
            if value and not bp.last_value:
                bp.hits += 1
                self.listener.hits.append(Hit(bp.id, bp.spec, None, tick, "became true"))
            bp.last_value = value

    @contextmanager
    def _sigint_pauses(self) -> Iterator[None]:
        """Ctrl-C pauses at the next step boundary instead of breaking a step in half."""
        if threading.current_thread() is not threading.main_thread():
            yield
            return
        try:
            previous = signal.signal(signal.SIGINT, lambda _sig, _frame: self._pause.set())
        except ValueError:
            yield
            return
        try:
            yield
        finally:
            signal.signal(signal.SIGINT, previous)

    # -- inputs and events (recorded for replay) ---------------------------------

    def parse_value(self, chart: str, name: str, text: str) -> Any:
        """A value typed for a chart input, by its declared unit (see :func:`.names.parse_input_value`)."""
        return parse_input_value(self.datum_decl(chart, name), f"{chart}.{name}", text)

    def set_input(self, chart: str, name: str, value: Any, force: bool = False) -> Any:
        """Set a chart input (``force``: keep it against the wiring until :meth:`release`).

        A string is parsed by :meth:`parse_value`.  Returns the value set.
        """
        if isinstance(value, str):
            value = self.parse_value(chart, name, value)
        action = Action(self.robot.steps, "force" if force else "set", chart, name, value)
        self._apply(action, self.robot)
        self._record(action)
        return value

    def release(self, chart: str | None = None, name: str | None = None) -> list[tuple[str, str]]:
        """Stop forcing one input, or every forced input (no arguments); returns those released."""
        if chart is None:
            keys = list(self.forced)
        else:
            if name is None or (chart, name) not in self.forced:
                forced = ", ".join(f"{c}.{n}" for c, n in self.forced) or "none"
                raise DebugError(f"{chart}.{name} is not forced; forced: {forced}")
            keys = [(chart, name)]
        for c, n in keys:
            action = Action(self.robot.steps, "release", c, n)
            self._apply(action, self.robot)
            self._record(action)
        return keys

    def post(self, chart: str, event: str, **data: Any) -> None:
        """Post an event to a chart; it is handled at the chart's next tick."""
        action = Action(self.robot.steps, "post", chart, event, data=dict(data))
        self._apply(action, self.robot)
        self._record(action)

    def game_input(self, name: str, **data: Any) -> None:
        """An input of the person at a GUI (``cell`` row= column=, ``play``, ``symbol`` symbol=, ``engine``
        engine=; :meth:`GameSession.person_input`), recorded with its control step like a posted event,
        so a replay repeats the person's clicks where they happened.  A refused one (not the person's
        turn, a locked symbol) raises :class:`DebugError` and is not recorded."""
        action = Action(self.robot.steps, "game", "Game", name, data=dict(data))
        self._apply(action, self.robot)
        self._record(action)

    def start_over(self, recipe: Recipe) -> None:
        """A new run from power-on on the robot ``recipe`` builds (a new game): the inputs recorded,
        the replay fingerprints and how far the session has been are those of the new run only;
        breakpoints are kept."""
        old = game_of(self.robot)
        if old is not None:
            old.close()  # its record ends (as interrupted, unless the game ended)
        self.recipe = recipe
        self.actions = []
        self.forced = {}
        self._fingerprints = {}
        self._attach(recipe.build())
        if self.trace_file is not None:  # the trace goes on: the transitions after this mark are the new run's
            self.trace_file.add({"event": "start_over", **self.where_now()})
        self._furthest_steps = self.robot.steps
        self._remember()
        for bp in self.breakpoints:
            if bp.condition is not None:
                bp.last_value = bp.condition.evaluate(self._names)

    def _apply(self, action: Action, robot: Robot) -> None:
        if action.kind == "game":
            game = game_of(robot)
            if game is None:
                raise DebugError("this robot plays no game: build it with the game (ttt-sm gui --game)")
            try:
                game.person_input(action.name, **action.data)
            except GameError as exc:
                raise DebugError(str(exc)) from None
            return
        try:
            if action.kind in ("set", "force"):
                robot.set_input(action.chart, action.name, action.value, force=action.kind == "force")
                if action.kind == "force":
                    self.forced[(action.chart, action.name)] = action.value
            elif action.kind == "release":
                robot.release(action.chart, action.name)
                self.forced.pop((action.chart, action.name), None)
            else:
                robot.post(action.chart, action.name, **action.data)
        except (RobotError, UnknownEventError) as exc:
            raise DebugError(str(exc)) from None

    def _record(self, action: Action) -> None:
        self.actions.append(action)
        # The future after this step is no longer what the session saw.
        self._fingerprints = {k: v for k, v in self._fingerprints.items() if k <= action.steps}
        self._remember()
        # Conditions keep their last checked value: one the user just made true
        # hits at the next chart tick.
        self._names.forget()

    # -- trace, diagrams ---------------------------------------------------------

    def save_trace(self, path: str | Path) -> Path:
        """Write the transitions the trace keeps (the newest :attr:`trace_keep`) as JSON Lines.

        All of them since power-on (or the last replay) while no more have
        happened; :attr:`trace.dropped <ttt_sm.runtime.listeners.Trace.dropped>`
        says how many older ones were let go (the trace file has them).
        """
        try:
            return self.trace.write_jsonl(path)
        except (OSError, ValueError) as exc:  # ValueError: a NUL in the name
            raise DebugError(f"trace save: cannot write {str(path)!r}: {getattr(exc, 'strerror', None) or exc}"
                             ) from None

    def _trace_head(self, robot: Robot) -> dict[str, Any]:
        recipe = self.recipe
        return {"event": "trace", "charts": list(robot.charts),
                "seed": getattr(recipe, "seed", None), "q_start": getattr(recipe, "q_start", None),
                "settle_s": getattr(recipe, "settle_s", None), "game": isinstance(recipe, GameRecipe),
                "dt_s": robot.params.control.dt, "chart_divider": robot.params.control.chart_divider,
                "kept_in_memory": self.trace_keep}

    def where_now(self) -> dict[str, Any]:
        """Where the session stands: chart tick, control steps, simulated time (for a record's lines)."""
        robot = self.robot
        return {"tick": robot.chart_ticks, "steps": robot.steps, "t": round(robot.t, 6)}

    def end_trace(self, how: str = "finished", **data: Any) -> Path | None:
        """End the trace file (if any) with ``how`` (``finished``, ``interrupted``, ``error``) and where
        the session stood; its path.  Only the first call writes."""
        if self.trace_file is None:
            return None
        self.trace_file.end(how, **data, **self.where_now(), transitions=self.trace.count)
        return self.trace_file.path

    def diagram(self, chart: str, path: str | Path | None = None) -> Path:
        """Write the chart's diagram with its active states highlighted.

        The format follows the extension: ``.svg``, ``.png`` (Graphviz), ``.dot``,
        ``.md``/``.mmd`` (Mermaid).  Default: ``out/debug/<Chart>-tick<N>.svg``.
        """
        c = self.chart(chart)
        if path is None:
            path = Path("out/debug") / f"{chart}-tick{self.robot.chart_ticks}.svg"
        path = Path(path)
        formats = {".svg": "svg", ".png": "png", ".dot": "dot", ".gv": "dot", ".md": "mermaid",
                   ".mmd": "mermaid"}
        fmt = formats.get(path.suffix.lower())
        if fmt is None:
            raise DebugError(f"diagram: unknown extension {path.suffix or '(none)'!r} of {str(path)!r};"
                             f" use {', '.join(formats)}")
        try:
            picture = render_active(c, fmt)
        except GraphvizMissingError as exc:
            raise DebugError(str(exc)) from None
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            if isinstance(picture, bytes):
                path.write_bytes(picture)
            else:
                path.write_text(picture, encoding="utf-8")
        except OSError as exc:
            raise DebugError(f"diagram: cannot write {str(path)!r}: {exc.strerror or exc}") from None
        return path

    # -- replay ------------------------------------------------------------------

    def fingerprint(self) -> dict[str, Any]:
        """Everything a replay must reproduce, now (see :func:`.replay.fingerprint`)."""
        return fingerprint(self.robot, self.forced)

    def _remember(self) -> None:
        if self.robot.sim is None:  # no twin, nothing a replay could compare
            return
        kept = self._fingerprints
        kept[self.robot.steps] = self.fingerprint()
        if len(kept) > MAX_FINGERPRINTS:
            # Thin the older half (every other one), keep the recent half whole.
            steps = sorted(kept)
            old = steps[:len(steps) // 2]
            for s in old[1::2]:
                del kept[s]
        self._furthest_steps = max(self._furthest_steps, self.robot.steps)

    @property
    def furthest_tick(self) -> int:
        """The furthest chart tick the session has run to: :meth:`replay` takes any tick up to it."""
        return (self._furthest_steps + self._divider - 1) // self._divider

    def steps_of_tick(self, tick: int) -> int:
        """The control step count right after chart tick ``tick`` (0: power-on)."""
        return 0 if tick == 0 else (tick - 1) * self._divider + 1

    def replay(self, tick: int) -> ReplayResult:
        """Rebuild the robot and run it to chart ``tick``, re-applying the recorded inputs.

        It stops where a breakpoint at that tick stops: right after the control
        step holding the tick (:meth:`steps_of_tick`).  Inputs and events
        recorded after that point are dropped (the session continues from the
        replayed past).  Breakpoints do not hit during a replay; the trace is
        recorded anew.
        """
        if not isinstance(tick, int) or tick < 0:
            raise DebugError(f"replay: the chart tick must be a whole number >= 0, got {tick!r}")
        if self.steps_of_tick(tick) > self._furthest_steps:
            raise DebugError(f"replay: chart tick {tick} lies beyond where this session has been (chart tick"
                             f" {self.furthest_tick}); replay goes back, run goes forward")
        return self.replay_to_step(self.steps_of_tick(tick))

    def replay_to_step(self, steps: int) -> ReplayResult:
        """:meth:`replay` to any control step count (a position between two ticks, too)."""
        if self.recipe is None:
            raise DebugError("replay needs the robot's recipe: build with Debugger.build(...) or"
                             " pass recipe=RobotRecipe(params, seed, q_start, settle_s)")
        if not isinstance(steps, int) or steps < 0:
            raise DebugError(f"replay: the step must be a whole number >= 0, got {steps!r}")
        if steps > self._furthest_steps:
            raise DebugError(f"replay: control step {steps} lies beyond where this session has been (step"
                             f" {self._furthest_steps}); replay goes back, run goes forward")
        target = steps
        kept = [a for a in self.actions if a.steps <= target]
        dropped = len(self.actions) - len(kept)
        self.forced = {}
        old = game_of(self.robot)
        if old is not None and old.record.attached:
            old.record.close()  # the rebuilt game writes its record anew, to the same file
        self._attach(self.recipe.build())
        robot = self.robot
        queue = deque(kept)
        self.listener.muted = True
        self.trace.sink = None  # the trace file has these transitions already: a mark stands for them
        try:
            while True:
                while queue and queue[0].steps == robot.steps:
                    self._apply(queue.popleft(), robot)
                if robot.steps >= target:
                    break
                if robot.steps % self._divider == 0:
                    self._keep_before_tick()
                robot.control_step()
        finally:
            self.listener.muted = False
            self.trace.sink = self.trace_file
            if self.trace_file is not None:
                self.trace_file.add({"event": "replay", **self.where_now(), "actions": len(kept)})
        self._game_stopped = _game_error(robot) is not None
        self.actions = kept
        now = self.fingerprint()
        before = self._fingerprints.get(target)
        diffs = tuple(differences(before, now)) if before is not None else ()
        if dropped:
            self._fingerprints = {k: v for k, v in self._fingerprints.items() if k <= target}
        self._fingerprints[target] = now if before is None else before
        for bp in self.breakpoints:
            if bp.condition is not None:
                bp.last_value = bp.condition.evaluate(self._names)
        return ReplayResult(robot.chart_ticks, robot.steps, robot.t, len(kept), dropped,
                            None if before is None else not diffs, diffs)


def _game_error(robot: Robot) -> Exception | None:
    """Why the robot's game flow stopped before the end, if it did."""
    game = game_of(robot)
    return None if game is None or game.driver is None else game.driver.error


def _values_of(names: Sequence[str]) -> Callable[[Mapping[str, Any]], tuple[Any, ...]]:
    """A fast reader of the named values of a chart's data, as a tuple (one C call per chart tick)."""
    if len(names) > 1:
        return operator.itemgetter(*names)
    return lambda d: tuple(d[n] for n in names)


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    try:
        return bool(a == b)
    except (TypeError, ValueError):  # arrays compare element-wise
        return a is b


def _check_count(n: int, what: str) -> None:
    if not isinstance(n, int) or n < 1:
        raise DebugError(f"{what}: the count must be a whole number >= 1, got {n!r}")


