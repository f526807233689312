"""Run scenarios on the simulated robot and say, with file:line, what did not happen.

One scenario builds one :class:`~ttt_sm.app.robot.Robot` from its ``seed`` and
``start``, then runs its steps in order.  Steps that only look or set
(``set``, ``release``, ``post``, ``expect``, ``expect_states``, ``mark``) take
no simulated time; ``run``, ``run_until`` and ``expect`` with ``within_s`` /
``for_s`` advance the robot by whole chart steps.

A failed expectation is recorded and the scenario goes on, so one run shows
every wrong expectation.  A step that leaves the robot somewhere the next steps
do not expect stops the scenario: a ``run_until`` that times out, an input set
without ``force`` that the wiring overwrote, an error raised by a chart.

A bare-chart scenario (``chart: Game``) runs on
:class:`~.robots.ChartsOnly` instead (:mod:`.robots`: what a scenario runs on).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..files import RecordWriteError
from ..params import ArmParams
from ..runtime import TickChart, states_entered_by
from ..runtime.conditions import UNITS, ExprError, Expression, Ref
from ..runtime.listeners import Coverage
from .model import (
    ChartRef,
    ExpectEventsStep,
    ExpectStatesStep,
    ExpectStep,
    MarkStep,
    PostStep,
    ReleaseStep,
    RunStep,
    RunUntilStep,
    Scenario,
    SetStep,
    Step,
    Where,
    chart_states,
)
from .robots import RobotFactory, RobotLike, default_robot

#: A long step reports how far it is every this many seconds of simulated time.
PROGRESS_EVERY_S = 5.0

#: ``progress(scenario, step, t, t_end)``: a long step is at simulated time ``t`` of at most ``t_end``.
StepProgress = Callable[[Scenario, Step, float, float], None]


@dataclass(frozen=True)
class Failure:
    """What went wrong, at which step."""

    where: Where
    message: str

    def __str__(self) -> str:
        return f"{self.where}: {self.message}"


@dataclass(frozen=True)
class ScenarioResult:
    """The outcome of one scenario."""

    name: str
    file: str
    failures: tuple[Failure, ...]
    sim_time_s: float
    wall_time_s: float
    steps_run: int
    steps_total: int

    @property
    def passed(self) -> bool:
        return not self.failures

    def to_dict(self) -> dict[str, Any]:
        """What ``ttt-sm scenario run --json`` prints per scenario."""
        return {
            "name": self.name,
            "file": self.file,
            "passed": self.passed,
            "failures": [str(f) for f in self.failures],
            "sim_time_s": round(self.sim_time_s, 4),
            "wall_time_s": round(self.wall_time_s, 3),
            "steps_run": self.steps_run,
            "steps_total": self.steps_total,
        }


@dataclass(frozen=True)
class Entry:
    """A state entered by a chart."""

    state: str
    tick: int
    t: float


class StateLog:
    """Listener: the states each chart entered, in order (compound states too)."""

    def __init__(self) -> None:
        self.entries: dict[str, list[Entry]] = {}
        #: the local events each chart broadcast, in order (``expect_events``)
        self.events: dict[str, list[Entry]] = {}
        self.clock: Callable[[], float] = lambda: 0.0

    def record_initial(self, charts: Iterable[TickChart]) -> None:
        """The states active at construction count as entered then (parents first)."""
        for chart in charts:
            active = set(chart.configuration_values)
            log = self.entries.setdefault(chart.chart_name, [])
            log += [Entry(s.id, chart.tick_count, self.clock()) for s in chart.structure().states
                    if s.id in active]

    def after_transition(self, machine: TickChart, transition: Any) -> None:
        log = self.entries.setdefault(machine.chart_name, [])
        now = self.clock()
        log += [Entry(s.id, machine.tick_count, now) for s in states_entered_by(machine, transition)]

    def on_local_event(self, machine: TickChart, event: str, source: Any, target: Any) -> None:
        self.events.setdefault(machine.chart_name, []).append(Entry(event, machine.tick_count, self.clock()))


class _Stop(Exception):
    """Ends a scenario at a failure the next steps cannot build on."""


def _fmt(value: Any, unit: str | None = None) -> str:
    """A value as a message shows it; a number in ``unit`` (``170.002deg``) when the condition wrote one."""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if unit is not None and isinstance(value, (int, float, np.integer, np.floating)):
        return f"{float(value) / UNITS[unit]:.6g}{unit}"
    if isinstance(value, (float, np.floating)):
        return f"{float(value):.6g}"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    return repr(value)


def _seconds(s: float) -> str:
    return f"{s:g} s"


def _subsequence_gap(expected: Sequence[str], actual: Sequence[str]) -> tuple[int, int] | None:
    """None if `expected` is a subsequence of `actual`, else (k, start): expected[k] is not in
    `actual` from index `start` on (just after where expected[k - 1] was found)."""
    pos = 0
    for k, state in enumerate(expected):
        try:
            pos = actual.index(state, pos) + 1
        except ValueError:
            return k, pos
    return None


def _first_difference(expected: Sequence[str], actual: Sequence[str]) -> int | None:
    """The index where two sequences first differ (or one of them ends), None if they are equal."""
    for k, (a, b) in enumerate(zip(expected, actual, strict=False)):
        if a != b:
            return k
    return None if len(expected) == len(actual) else min(len(expected), len(actual))


def _ordinal(n: int) -> str:
    suffix = "th" if 10 <= n % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(n % 10, "th")
    return f"{n}{suffix}"


def _around(states: Sequence[str], k: int, width: int = 2) -> str:
    """The states around index k, the k-th in brackets: ``..., power_on, turn_fwd, [go_park], wait_23``;
    ``[none]`` where the list has ended."""
    lo, hi = max(0, k - width), min(len(states), k + width + 1)
    shown = [f"[{s}]" if i == k else s for i, s in enumerate(states[lo:hi], start=lo)]
    if k >= len(states):
        shown.append("[none]")
    return ", ".join([*(["..."] if lo else []), *shown, *(["..."] if hi < len(states) else [])])


def _listed(states: Sequence[str], most: int = 6) -> str:
    """``a, b, c`` (at most ``most`` of them, then how many more), or ``nothing``."""
    more = f", ... ({len(states) - most} more)" if len(states) > most else ""
    return ", ".join(states[:most]) + more if states else "nothing"


class _Run:
    """The steps of one scenario on one robot."""

    def __init__(self, scenario: Scenario, robot: RobotLike, log: StateLog,
                 progress: StepProgress | None = None) -> None:
        self.scenario = scenario
        self.progress = progress
        self.step: Step | None = None
        self.robot = robot
        self.log = log
        self.chart_dt = robot.params.control.chart_dt
        self.failures: list[Failure] = []
        self.mark: dict[str, int] = {name: 0 for name in robot.charts}  # the initial states count
        self.event_mark: dict[str, int] = {name: 0 for name in robot.charts}
        self.mark_label = "the start"
        self.pending_sets: list[tuple[SetStep, ChartRef, Any]] = []
        self.inputs_fed = scenario.bare is None  # the wiring feeds some inputs; bare charts' only the steps
        self.steps_run = 0

    # -- running -----------------------------------------------------------------------

    def run(self) -> None:
        for step in self.scenario.steps:
            self.steps_run += 1
            self.step = step
            try:
                getattr(self, f"do_{step.kind}")(step)
            except _Stop:
                return
            except ExprError as exc:
                self.failures.append(Failure(step.where, f"{step.kind}: {exc}"))
                return
            except RecordWriteError:  # the disk refused the trace: the run ends there, the scenario did not fail
                raise
            except Exception as exc:  # a chart's bug or a robot refusal: report it where it happened
                self.failures.append(Failure(step.where, f"{step.kind}: {type(exc).__name__}: {exc}"))
                return

    def fail(self, step: Step, message: str, stop: bool = False) -> None:
        self.failures.append(Failure(step.where, message))
        if stop:
            raise _Stop

    def advance(self, timeout_s: float, until: Callable[[], bool] | None = None) -> bool:
        """Run chart steps until `until()` holds (checked after each) or `timeout_s` passes.

        A long advance calls ``progress`` every :data:`PROGRESS_EVERY_S` of simulated time.
        """
        if timeout_s > self.scenario.max_step_s * (1 + 1e-9):
            assert self.step is not None
            self.fail(self.step, f"{self.step.kind}: {_seconds(timeout_s)} is beyond"
                                 f" {_seconds(self.scenario.max_step_s)} of simulated time, the longest a step"
                                 f" may run; if it is meant, put 'max_step_s: {timeout_s:g}' at the top of the file",
                      stop=True)
        every = max(1, int(round(PROGRESS_EVERY_S / self.chart_dt)))
        calls = 0
        end = self.robot.t + timeout_s

        def predicate() -> bool:
            nonlocal calls
            calls += 1
            if self.progress is not None and calls % every == 0:
                assert self.step is not None
                self.progress(self.scenario, self.step, self.robot.t, end)
            if self.pending_sets:
                self.check_pending_sets()
            return until() if until is not None else False
        return self.robot.run_until(predicate, timeout_s)

    def check_pending_sets(self) -> None:
        pending, self.pending_sets = self.pending_sets, []
        for step, ref, value in pending:
            now = self.robot.value(ref.chart, ref.name)
            if now != value:
                self.fail(step, f"set: {ref} was overwritten at the next chart step (now {_fmt(now)}):"
                                " the wiring feeds this input every chart step; add 'force: true' to"
                                " the step to hold it, and release it later", stop=True)

    # -- conditions ----------------------------------------------------------------------

    def getter(self, ref: Ref) -> Callable[[], Any]:
        robot = self.robot
        if ref.chart is not None:
            chart = robot.chart(ref.chart)
            name = ref.name
            if name in {d.name for d in chart.declarations()}:
                return lambda: getattr(chart, name)
            return lambda: name in chart.configuration_values
        if ref.name == "t":
            return lambda: robot.t
        i = ref.index - 1 if ref.index is not None else None  # written 1-based, as the thesis numbers joints
        # the arm's own accessors, without building every signal (a condition is checked every chart step)
        arm, truth = getattr(robot, "arm", None), getattr(robot, "truth", None)
        if i is not None and arm is not None:
            if ref.name == "q_encoder":
                return lambda: arm.encoder_angles()[i]
            if ref.name == "offset_estimate":
                return lambda: arm.offset_estimates()[i]
        if i is not None and truth is not None and ref.name == "q_true":  # simulation only
            return lambda: truth.angles()[i]
        name = ref.name
        if i is None:
            return lambda: robot.signal_values()[name]
        return lambda: robot.signal_values()[name][i]

    def bind(self, expr: Expression) -> Callable[[], Any]:
        return expr.bind(self.getter)

    def values(self, expr: Expression) -> str:
        """The names a condition reads, with their values now."""
        seen: dict[str, str] = {}
        for ref in expr.refs:
            if str(ref) not in seen:  # in the unit of the numbers it is compared with: 175deg, degrees
                seen[str(ref)] = _fmt(self.getter(ref)(), expr.unit_of(ref))
        listed = "; ".join(f"{k} = {v}" for k, v in seen.items())
        return f"t = {self.robot.t:.3f} s" + (f"; {listed}" if listed else "")

    def where_is(self, chart: str) -> str:
        cls = type(self.robot.chart(chart))
        kinds = chart_states(cls)
        leaves = [s for s in self.robot.chart(chart).configuration_values if kinds.get(s) == "leaf"]
        return f"{chart} is in {', '.join(sorted(leaves)) or '(no state)'}"

    # -- steps -----------------------------------------------------------------------------

    def do_set(self, step: SetStep) -> None:
        for ref, value in step.values:
            self.robot.set_input(ref.chart, ref.name, value, force=step.force)
            if self.inputs_fed and not step.force:
                self.pending_sets.append((step, ref, value))

    def do_release(self, step: ReleaseStep) -> None:
        for ref in step.targets:
            self.robot.release(ref.chart, ref.name)

    def do_post(self, step: PostStep) -> None:
        self.robot.post(step.chart, step.event, **step.data)

    def do_run(self, step: RunStep) -> None:
        self.advance(step.duration_s(self.chart_dt))

    def do_run_until(self, step: RunUntilStep) -> None:
        robot = self.robot
        t0 = robot.t
        target = step.entered or step.active
        seen = len(self.log.entries.get(target.chart, [])) if target is not None else 0
        until: Callable[[], bool]
        if step.entered is not None:
            ref = step.entered
            entries = self.log.entries.setdefault(ref.chart, [])
            start = len(entries)
            state = ref.name

            def until() -> bool:
                return len(entries) > start and any(e.state == state for e in entries[start:])
        elif step.active is not None:
            chart, state = robot.chart(step.active.chart), step.active.name
            if state in chart.configuration_values:
                return

            def until() -> bool:
                return state in chart.configuration_values
        else:
            assert step.condition is not None
            cond = self.bind(step.condition)
            if cond():
                return
            until = cond
        if self.advance(step.timeout_s, until):
            return
        if step.condition is not None:
            detail = f"values now: {self.values(step.condition)}"
        else:
            assert target is not None
            since = [e.state for e in self.log.entries.get(target.chart, [])[seen:]]
            entered = f"; it entered {', '.join(since)} meanwhile" if since else \
                "; it entered no state meanwhile"
            detail = f"{self.where_is(target.chart)}{entered}"
        self.fail(step, f"run_until: {step.missed} within {_seconds(step.timeout_s)}"
                        f" (from t = {t0:.3f} s to {robot.t:.3f} s); {detail}", stop=True)

    def do_expect(self, step: ExpectStep) -> None:
        cond = self.bind(step.condition)
        text = step.condition.text
        if step.within_s is not None:
            if cond() or self.advance(step.within_s, cond):
                return
            self.fail(step, f"expect: {text!r} did not hold within {_seconds(step.within_s)};"
                            f" {self.values(step.condition)}")
        elif step.for_s is not None:
            t0 = self.robot.t
            if not cond():
                self.fail(step, f"expect: {text!r} for {_seconds(step.for_s)}: false at once;"
                                f" {self.values(step.condition)}")
                return
            if self.advance(step.for_s, lambda: not cond()):
                self.fail(step, f"expect: {text!r} for {_seconds(step.for_s)}: false after"
                                f" {self.robot.t - t0:.3f} s; {self.values(step.condition)}")
        elif not cond():
            self.fail(step, f"expect: {text!r} is false; {self.values(step.condition)}")

    def do_expect_states(self, step: ExpectStatesStep) -> None:
        """Fail at the first state that is not as expected: which one, what was expected, what came."""
        entries = self.log.entries.get(step.chart, [])[self.mark.get(step.chart, 0):]
        actual = [e.state for e in entries]
        if step.match == "exact":
            kinds = chart_states(type(self.robot.chart(step.chart)))
            actual = [s for s in actual if kinds.get(s) == "leaf"]
        self.check_sequence(step, list(step.sequence), actual, ("leaf state", "", "entered"))

    def do_expect_events(self, step: ExpectEventsStep) -> None:
        """Fail at the first local event that is not as expected."""
        events = self.log.events.get(step.chart, [])[self.event_mark.get(step.chart, 0):]
        self.check_sequence(step, list(step.sequence), [e.state for e in events],
                            ("local event", "local event ", "sent"))

    def check_sequence(self, step: ExpectStatesStep | ExpectEventsStep, expected: list[str], actual: list[str],
                       words: tuple[str, str, str]) -> None:
        """Compare what a chart did with `expected` (exactly, or as a subsequence); fail at the first miss.

        `words`: what one item is (``leaf state``), how a missing one is named
        (``local event ``), and what the chart did with them (``entered``).
        """
        item, named, did = words
        chart, since = step.chart, self.mark_label
        if step.match == "exact":
            k = _first_difference(expected, actual)
            if k is None:
                return
            want = expected[k] if k < len(expected) else "none"
            got = actual[k] if k < len(actual) else "none"
            problem = (f"{chart}'s {_ordinal(k + 1)} {item} since {since}: expected {want}, got {got}"
                       f" (expected {_around(expected, k)}; {did} {_around(actual, k)})")
        else:
            gap = _subsequence_gap(expected, actual)
            if gap is None:
                return
            k, start = gap
            after = f" after {expected[k - 1]}" if k else ""
            problem = (f"{chart} since {since}: expected {named}{expected[k]} ({_ordinal(k + 1)} of the"
                       f" sequence){after}, got {_listed(actual[start:])}")
        self.fail(step, f"{step.kind}: {problem}; {self.where_is(chart)}")

    def do_mark(self, step: MarkStep) -> None:
        self.event_mark = {name: len(self.log.events.get(name, [])) for name in self.robot.charts}
        self.mark = {name: len(self.log.entries.get(name, [])) for name in self.robot.charts}
        self.mark_label = f"mark {step.label!r} (line {step.where.line})" if step.label else \
            f"the mark on line {step.where.line}"


def _check_start(scenario: Scenario, params: ArmParams) -> str | None:
    """Why the power-on pose is impossible, or None."""
    q = scenario.start.q_deg
    if q is None:
        return None
    for k, (angle, drive) in enumerate(zip(q[:3], params.drives, strict=False)):
        lo, hi = math.degrees(drive.limit_min_rad), math.degrees(drive.limit_max_rad)
        if not lo <= angle <= hi:
            return f"start: q{k + 1} = {angle:g} deg is beyond the joint's hard stops ({lo:g} .. {hi:g} deg)"
    return None


def run_scenario(scenario: Scenario, params: ArmParams, *, coverage: Coverage | None = None,
                 listeners: Sequence[object] = (),
                 robot_factory: RobotFactory | None = None,
                 progress: StepProgress | None = None) -> ScenarioResult:
    """Run one loaded scenario on a new robot.

    Parameters
    ----------
    scenario : Scenario
        From :func:`~.loader.load_scenario`.
    params : ArmParams
        The arm (``load_params()`` for the packaged one).
    coverage : Coverage, optional
        Observes the charts from construction (their initial states count), so
        that several scenarios add up into one report.
    listeners : sequence
        More python-statemachine listeners for the charts (a :class:`Trace` ...).
    robot_factory : callable, optional
        Builds the robot (tests use a stand-in); by default the simulated arm, or
        for a bare-chart scenario its charts alone (:class:`ChartsOnly`).
    progress : callable, optional
        ``progress(scenario, step, t, t_end)``, called every
        :data:`PROGRESS_EVERY_S` of simulated time while a step runs (the
        CLI shows it on a terminal).
    """
    wall0 = time.perf_counter()
    start_where = scenario.start.where or scenario.where or Where(scenario.file, 0)
    problem = _check_start(scenario, params)
    if problem is not None:
        return ScenarioResult(scenario.name, scenario.file, (Failure(start_where, problem),), 0.0,
                              time.perf_counter() - wall0, 0, len(scenario.steps))
    log = StateLog()
    robot = (robot_factory or default_robot)(scenario, params, [log, *listeners])
    log.clock = lambda: robot.t
    log.record_initial(robot.charts.values())
    if coverage is not None:
        coverage.observe(*robot.charts.values())
    run = _Run(scenario, robot, log, progress)
    run.run()
    return ScenarioResult(scenario.name, scenario.file, tuple(run.failures), float(robot.t),
                          time.perf_counter() - wall0, run.steps_run, len(scenario.steps))
