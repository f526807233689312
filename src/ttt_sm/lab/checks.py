"""``ttt-sm lab check``: judge a student's chart by what it does, not by how it is written.

Three kinds of check, each passed or failed with a reason in the student's
terms (which scenario step, which of their states, what the arm did):

- **scenarios**: the exercise's scenario files (bare chart or whole robot),
  run with the student's class in its slot; a failure is the runner's
  ``file:line: what happened``;
- **the twin**: the whole robot with the student's chart, the physical
  outcome measured against the simulation's ground truth: the drives
  initialised within a time bound, the encoder offset right, no command past
  a joint limit, no entry into the board zone, the Safety chart never
  tripped; for a drawing, the ink against the ideal X of eqs. 3.37-3.44;
- **coverage**: the share of the student's transitions all of that took.

The score is the number of checks passed out of all of them.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..app.chart_file import load_chart
from ..app.drawing import DrawSession
from ..app.init_wiring import InitMonitor
from ..app.recorders import DrawRecord
from ..app.robot import Robot
from ..app.slots import ChartSlots, using_slots
from ..charts import DriveInit1
from ..charts.geometry import x_start
from ..params import ArmParams
from ..runtime import TickChart
from ..runtime.listeners import Coverage
from ..scenario.loader import load_scenario
from ..scenario.runner import run_scenario
from .exercise import Exercise, read_exercise

#: How close the encoder angle must come to the true angle once a drive is initialised, rad.
OFFSET_TOLERANCE_RAD = math.radians(0.2)
#: The unpowered arm settles this long before power-on in the twin check, s (as `ttt-sm init` does, shorter).
SETTLE_S = 1.0


@dataclass(frozen=True)
class CheckResult:
    """One check: its name, whether it passed, and why not (empty when it passed)."""

    name: str
    kind: str
    passed: bool
    reason: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "kind": self.kind, "passed": self.passed, "reason": self.reason}


@dataclass(frozen=True)
class LabReport:
    """Every check of one exercise on one chart."""

    exercise: str
    chart: str
    checks: tuple[CheckResult, ...]

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    @property
    def score(self) -> tuple[int, int]:
        return sum(c.passed for c in self.checks), len(self.checks)

    def to_dict(self) -> dict[str, Any]:
        done, total = self.score
        return {"exercise": self.exercise, "chart": self.chart, "passed": self.passed,
                "score": {"passed": done, "total": total}, "checks": [c.to_dict() for c in self.checks]}

    def to_text(self) -> str:
        lines = []
        for c in self.checks:
            lines.append(f"{'PASS' if c.passed else 'FAIL'} {c.kind}: {c.name}")
            lines += [f"  {line}" for line in c.reason.splitlines()] if not c.passed else []
        done, total = self.score
        lines.append(f"score {done}/{total}: " + ("every check passed" if self.passed else "not yet"))
        return "\n".join(lines) + "\n"


def check_folder(folder: Any, params: ArmParams) -> LabReport:
    """Load the student's chart of the exercise in `folder` and run every check on it.

    A file that does not load or a class that does not fit the slot raises
    (:class:`~ttt_sm.app.chart_file.ChartFileError`, :class:`~ttt_sm.app.slots.SlotError`):
    nothing can be judged then.
    """
    ex = read_exercise(folder)
    cls, where = load_chart(ex.chart_file, ex.class_name)
    return run_checks(ex, cls, where, params)


def run_checks(ex: Exercise, cls: type[TickChart], where: str, params: ArmParams,
               coverage: Coverage | None = None) -> LabReport:
    """Every check of exercise `ex` with `cls` in its slot (the thesis' own class, for the reference).

    `coverage` records the transitions the checks take (a fresh one when None; ``lab grade`` passes its
    own to draw which transitions each student's chart took).
    """
    slots = ChartSlots().with_chart(ex.slot, cls, where)
    cov = coverage if coverage is not None else Coverage().include(cls)
    results: list[CheckResult] = []
    with using_slots(slots):
        for path in ex.scenario_files():
            scenario = load_scenario(path)
            result = run_scenario(scenario, params, coverage=cov)
            reason = "\n".join(str(f) for f in result.failures)
            results.append(CheckResult(scenario.name, "scenario", result.passed, reason))
        if ex.twin == "init":
            results += _init_on_twin(ex, slots, params, cov)
        elif ex.twin == "draw_x":
            results += _x_on_twin(ex, slots, params, cov)
    if ex.coverage > 0:
        results.append(_coverage(ex, cls, cov))
    return LabReport(ex.name, where, tuple(results))


def _states(robot: Robot, name: str) -> str:
    return ", ".join(sorted(robot.active(name)))


def _safety(robot: Robot) -> CheckResult:
    if robot.tripped:
        return CheckResult("the Safety chart never tripped", "twin", False,
                           f"at t = {robot.t:.2f} s the Safety chart tripped: {robot.safety.reason}")
    return CheckResult("the Safety chart never tripped", "twin", True)


def _init_on_twin(ex: Exercise, slots: ChartSlots, params: ArmParams, cov: Coverage) -> list[CheckResult]:
    """The whole robot initialises with the student's chart: in time, offset right, limits and board kept."""
    robot = Robot(params, seed=ex.seed, settle_s=SETTLE_S, listeners=[cov], slots=slots)
    assert robot.truth is not None  # the robot built the twin
    # drive 1 finds a hard stop by pushing its setpoint a little past it (the thesis' stall detection)
    d1 = {d.name: d.default for d in DriveInit1.declarations()}
    allowance = d1["stall_lag"] + d1["search_speed"] * params.control.chart_dt
    monitor = InitMonitor(params, robot.arm, robot.truth, allowance_rad=allowance)
    robot.sched.joint_stages.append(monitor)
    stage = robot.init_stage
    robot.run_until(lambda: robot.initialised or robot.tripped or stage.failed, ex.within_s)
    drive = int(ex.slot[-1])
    name = f"the drives initialise within {ex.within_s:g} s"
    if robot.initialised:
        results = [CheckResult(name, "twin", True)]
    else:
        why = ("the Safety chart tripped" if robot.tripped else
               "an init chart gave up" if stage.failed else f"after {ex.within_s:g} s they had not")
        chart = robot.chart(ex.slot)
        results = [CheckResult(name, "twin", False,
                               f"{why}: your {ex.slot} is in {_states(robot, ex.slot)} with pos_out ="
                               f" {math.degrees(chart.pos_out):.1f} deg, passing = {bool(chart.passing)};"
                               f" drive {drive} truly stands at {math.degrees(robot.truth.q[drive - 1]):.1f} deg")]
    error = float(robot.arm.offset_estimates()[drive - 1] - robot.truth.offsets[drive - 1])
    ok = robot.initialised and abs(error) <= OFFSET_TOLERANCE_RAD
    results.append(CheckResult(
        f"drive {drive}'s encoder reads its true angle (within {math.degrees(OFFSET_TOLERANCE_RAD):.1f} deg)",
        "twin", ok, "" if ok else f"the encoder angle is off the true angle by {math.degrees(error):.2f} deg"
                                  " (the offset your chart set is wrong, or it never set one)"))
    results.append(CheckResult(
        "no setpoint past a joint's hard stop", "twin", monitor.limit_violations == 0,
        f"{monitor.limit_violations} chart steps commanded a joint past its hard stop, by up to"
        f" {math.degrees(monitor.max_overtravel_rad):.1f} deg"))
    results.append(CheckResult(
        "the arm keeps out of the board zone", "twin", monitor.zone_ticks == 0,
        f"the arm was in the board zone for {monitor.zone_ticks} chart steps"
        f" ({monitor.zone_ticks * params.control.chart_dt:.2f} s)"))
    results.append(_safety(robot))
    return results


def _segment_distance(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ab = b - a
    t = np.clip(((points - a) @ ab) / float(ab @ ab), 0.0, 1.0)
    return np.asarray(np.hypot(*(points - (a + t[:, None] * ab)).T))


def ideal_x(params: ArmParams, row: int, column: int, size: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """The two strokes of an X of side `size` in the cell (eqs. 3.37-3.44), as (start, end) points in m."""
    x_max, y_max = params.board.field_bounds()[1], params.board.field_bounds()[3]
    x0, y0 = x_start(x_max, y_max, params.board.cell_size, row, column, size)
    return [(np.array([x0, y0]), np.array([x0 - size, y0 - size])),
            (np.array([x0, y0 - size]), np.array([x0 - size, y0]))]


def _x_on_twin(ex: Exercise, slots: ChartSlots, params: ArmParams, cov: Coverage) -> list[CheckResult]:
    """The whole robot draws an X in the middle cell with the student's Control: in time, where it belongs."""
    session = DrawSession(params, seed=ex.seed)
    robot, c = session.robot, session.robot.control
    cov.observe(c)
    session.start()
    row = column = (params.board.cells + 1) // 2
    c.row, c.column, c.symbol = row, column, 1
    session.recorder.record = DrawRecord()
    session.recorder.on = True
    strokes_before = len(robot.board.strokes)
    robot.post("Control", "button")
    robot.chart_step()
    robot.chart_step()
    done = robot.run_until(lambda: not c.busy or robot.tripped, ex.within_s)
    name = f"the X is drawn within {ex.within_s:g} s"
    results = [CheckResult(name, "twin", done and not c.busy, "" if done else
                           f"after {ex.within_s:g} s your Control was still in {_states(robot, 'Control')}"
                           f" (X_out = {c.X_out * 1e3:.1f} mm, Y_out = {c.Y_out * 1e3:.1f} mm)")]
    ink = [s.points for s in robot.board.strokes[strokes_before:] if s.author == "robot"]
    points = np.vstack(ink) if ink else np.zeros((0, 2))
    strokes = ideal_x(params, row, column, float(c.size))
    if len(points) == 0:
        results.append(CheckResult(f"the ink lies on the ideal X (rms within {ex.max_rms_mm:g} mm)", "twin", False,
                                   "the pen left no ink on the board"))
    else:
        dist = np.min([_segment_distance(points, a, b) for a, b in strokes], axis=0) * 1e3
        rms = float(np.sqrt(np.mean(dist ** 2)))
        results.append(CheckResult(f"the ink lies on the ideal X (rms within {ex.max_rms_mm:g} mm)", "twin",
                                   rms <= ex.max_rms_mm, f"the ink is {rms:.2f} mm rms (worst {dist.max():.1f} mm)"
                                   " from the X of eqs. 3.37-3.44 in the middle cell"))
    covered = _strokes_covered(points, strokes)
    results.append(CheckResult("both strokes of the X are drawn end to end", "twin", covered == "",
                               covered))
    results.append(_safety(robot))
    return results


def _strokes_covered(points: np.ndarray, strokes: list[tuple[np.ndarray, np.ndarray]],
                     tol_m: float = 0.001) -> str:
    """Empty if ink lies within `tol_m` of every millimetre of both strokes, else what is missing."""
    missing = []
    for k, (a, b) in enumerate(strokes, start=1):
        samples = a + np.linspace(0.0, 1.0, 20)[:, None] * (b - a)
        if len(points) == 0:
            missing.append(f"stroke {k} has no ink")
            continue
        near = np.array([np.min(np.hypot(*(points - s).T)) <= tol_m for s in samples])
        if not near.all():
            missing.append(f"stroke {k} has no ink along {100 * (1 - near.mean()):.0f}% of its length")
    return "; ".join(missing)


def _coverage(ex: Exercise, cls: type[TickChart], cov: Coverage) -> CheckResult:
    """The share of the chart's transitions (leaving `ex.coverage_states`, when given) the checks took."""
    [chart] = [c for c in cov.report().charts if c.chart == cls.__name__]
    by_label = {t.label: t for t in cls.structure().transitions}
    counted: Callable[[str], bool] = ((lambda label: by_label[label].source in ex.coverage_states)
                                      if ex.coverage_states else (lambda label: True))
    transitions = [t for t in chart.transitions if counted(t)]
    taken = [t for t in chart.taken if counted(t)]
    share = len(taken) / len(transitions) if transitions else 1.0
    untaken = [t for t in transitions if t not in taken]
    name = f"the checks take at least {ex.coverage:.0%} of your chart's transitions"
    return CheckResult(name, "coverage", share >= ex.coverage,
                       f"they took {len(taken)} of {len(transitions)} ({share:.0%}); never taken: "
                       + "; ".join(untaken[:5]) + (" ..." if len(untaken) > 5 else ""))
