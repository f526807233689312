"""The thesis' precision experiment: a staircase of setpoints measured three ways (section 3.5).

The thesis commands a staircase along one global axis (figs. 3.14-3.18):
small steps and big steps, along Z and along X.  The setpoints go the way
every pose goes (inverse kinematics, the drive setpoints, the cascade
controllers, the arm), and three values are compared over time:

- **desired vs FK**: the staircase against forward kinematics of the encoder
  angles: the error of the controllers and of inverse kinematics (the
  encoders sit on the motors, so they do not see the gear clearance);
- **FK vs sensor**: forward kinematics against a triangulation sensor that
  watches the tool: the clearances (gears, servo), the gears' elastic
  deflection and the link lengths forward kinematics assumes;
- **desired vs sensor**: the overall error.

:func:`run_staircase` runs it on the twin: a :class:`~.robot.Robot`
initialises with its init charts and waits in ``wait_1``; then a task stage
(:class:`~ttt_sm.sched.scheduler.PathStage`, after the Control chart's, whose
pose it replaces) moves the tool to the staircase's start and plays the
stairs, one pose per chart tick.  A joint stage run last (:class:`~.recorders.StairRecorder`)
records, per chart tick, the desired pose, forward kinematics of the encoders
(with the servo's commanded angle: it has no encoder) and one reading of the
sensor (:mod:`ttt_sm.twin.sensor`, on the true tool: simulation only).

Per step (:class:`StepErrors`): the **static error**, the mean error over the
last ``STATIC_WINDOW_S`` of the step's hold, and the **dynamic error**, the
mean |error| over the first ``DYNAMIC_WINDOW_S`` after the step (how far the
measured value lags the stairs while it follows them).  Lengths in the
results are millimetres.  :mod:`.precision_plot` draws the figures.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..params import ArmParams, Tuning
from ..sched.scheduler import PathStage, Signals
from ..twin.kinematics import fk, jacobian
from ..twin.plant import gear_play, gravity_torques
from ..twin.sensor import SensorMount, SensorSpec, TriangulationSensor
from .recorders import StairRecorder
from .robot import Robot

AXES = ("x", "y", "z")
STEP_KINDS = ("small", "big")
#: The size of one stair, m (the thesis gives its figures, not the numbers: chosen so that the small
#: steps are of the order of the controllers' dynamic error and the big ones a slew of the drives).
STEP_M = {"small": 0.0005, "big": 0.01}
#: Stairs after the starting level (the default; ``--count``).
STAIRS = 5
#: How long each stair is held, s: the thesis' controllers settle in about 1 s (section 3.2).
HOLD_S = 1.5
#: Held at the starting level before the first stair, s.
PRE_ROLL_S = 1.0
#: How fast the tool moves from the waiting pose to the staircase's start, m/s.
APPROACH_M_S = 0.05
#: The static error is the mean error over the last part of each hold, s.
STATIC_WINDOW_S = 0.3
#: The dynamic error is the mean |error| over the first part after each step, s.
DYNAMIC_WINDOW_S = 0.5
#: Where each staircase starts (x, y, z of the pen tip, m; pen vertical): over the field, in free space
#: 3 cm above the board, so that the staircase runs where the arm draws.
START_M = {"x": (-0.025, 0.25, 0.03), "y": (0.0, 0.225, 0.03), "z": (0.0, 0.25, 0.03)}
#: The sensor sits this far before the start along the staircase's axis, looking along it, m: the
#: readings start at 7 cm, inside the 5-15 cm range, and the big staircase (5 cm) ends at 12 cm.
SENSOR_STANDOFF_M = 0.07
#: The three comparisons of section 3.5, by name: (minuend, subtrahend).
COMPARISONS = {"desired_vs_fk": ("desired", "fk"), "fk_vs_sensor": ("fk", "sensor"),
               "desired_vs_sensor": ("desired", "sensor")}
#: The two parts of FK vs sensor (item by item: ``fk - sensor = lengths + clearance``): the lengths
#: forward kinematics assumes against the arm's true ones (``[geometry]`` vs ``[as_built]``: FK of the
#: same encoder angles with each), and what is left (clearances, the gears' deflection, the sensor).
PARTS = {"lengths": ("fk", "fk_as_built"), "clearance": ("fk_as_built", "sensor")}
#: Which thesis figure each staircase reproduces (Y: section 3.5.2 says it matches X; no figure).
THESIS_FIGURE = {("z", "small"): "3.15", ("z", "big"): "3.16", ("x", "small"): "3.17", ("x", "big"): "3.18"}


class PrecisionError(ValueError):
    """A staircase that cannot be run or measured (bad request, no ground truth, the Safety chart tripped)."""


def axis_vector(axis: str) -> np.ndarray:
    """The global unit vector of `axis` ("x", "y" or "z")."""
    if axis not in AXES:
        raise PrecisionError(f"unknown axis {axis!r}; choose from {', '.join(AXES)}")
    v = np.zeros(3)
    v[AXES.index(axis)] = 1.0
    return v


@dataclass(frozen=True)
class StaircaseSpec:
    """One staircase: along `axis`, `count` stairs of `step_m` each held `hold_s`, from `start` (m)."""

    axis: str
    steps: str
    step_m: float
    count: int
    hold_s: float
    start: tuple[float, float, float]

    @classmethod
    def of(cls, axis: str, steps: str, count: int = STAIRS, hold_s: float = HOLD_S) -> StaircaseSpec:
        """The staircase of section 3.5 along `axis` with `steps` ("small" or "big") stairs."""
        axis_vector(axis)
        if steps not in STEP_KINDS:
            raise PrecisionError(f"unknown steps {steps!r}; choose from {', '.join(STEP_KINDS)}")
        if not isinstance(count, int) or not 1 <= count <= 20:
            raise PrecisionError(f"count must be a whole number of stairs in 1..20, got {count!r}")
        if not (math.isfinite(hold_s) and 0.6 <= hold_s <= 10.0):
            raise PrecisionError(f"hold must lie in 0.6..10 s (the static window is {STATIC_WINDOW_S} s and the"
                                 f" dynamic {DYNAMIC_WINDOW_S} s), got {hold_s}")
        step = STEP_M[steps]
        reach = SENSOR_STANDOFF_M + count * step
        if reach > 0.15:
            raise PrecisionError(f"{count} {steps} stairs ({count * step * 1000:g} mm) leave the sensor's range:"
                                 f" at most {int((0.15 - SENSOR_STANDOFF_M) / step)}")
        return cls(axis, steps, step, count, float(hold_s), START_M[axis])

    def levels(self) -> np.ndarray:
        """The stairs' positions along the axis, m (level 0 is the start)."""
        a = AXES.index(self.axis)
        return self.start[a] + self.step_m * np.arange(self.count + 1)

    def default_mount(self) -> SensorMount:
        """The sensor SENSOR_STANDOFF_M before the start, its beam along the staircase's axis."""
        e = axis_vector(self.axis)
        origin = np.asarray(self.start) - SENSOR_STANDOFF_M * e
        return SensorMount(tuple(float(v) for v in origin), tuple(float(v) for v in e))  # type: ignore[arg-type]


def staircase_poses(spec: StaircaseSpec, frm: tuple[float, float, float, float], chart_dt: float
                    ) -> tuple[np.ndarray, int, list[int]]:
    """The task poses (x, y, z, phi), one per chart tick: the approach from `frm`, the pre-roll, the stairs.

    Returns the poses, the tick the pre-roll starts at and the tick of each stair.
    """
    start = np.array([*spec.start, 0.0])
    approach = _approach(np.asarray(frm, dtype=float), start, chart_dt)
    n_app = len(approach)
    settle = int(round(PRE_ROLL_S / chart_dt))
    hold = int(round(spec.hold_s / chart_dt))
    rows = [approach, np.repeat(start[None, :], settle, axis=0)]
    a = AXES.index(spec.axis)
    ticks = []
    tick = n_app + settle
    for k in range(1, spec.count + 1):
        level = start.copy()
        level[a] += k * spec.step_m
        rows.append(np.repeat(level[None, :], hold, axis=0))
        ticks.append(tick)
        tick += hold
    return np.vstack(rows), n_app, ticks


@dataclass(frozen=True)
class StepErrors:
    """One stair's errors for one comparison, mm: static (signed mean over the end of the hold) and dynamic."""

    stair: int
    static_mm: float | None
    dynamic_mm: float | None


@dataclass(frozen=True)
class StaircaseResult:
    """What ``ttt-sm precision staircase`` reports; lengths mm, times s."""

    axis: str
    steps: str
    tuning: str
    step_mm: float
    stairs: int
    hold_s: float
    seed: int
    thesis_figure: str | None
    sensor: dict[str, Any]
    errors: dict[str, list[StepErrors]]
    summary: dict[str, dict[str, float | None]]
    clearance_bound_mm: float
    sensor_out_of_range: int
    samples: int
    sim_time_s: float
    wall_time_s: float
    reading: list[str]
    t: np.ndarray = field(repr=False, compare=False)
    series: dict[str, np.ndarray] = field(repr=False, compare=False)
    stair_times: tuple[float, ...] = ()

    def report(self) -> dict[str, Any]:
        """The result as plain data (no arrays): what ``--json`` prints.

        ``errors`` and ``summary`` hold the three comparisons of :data:`COMPARISONS` and the two parts
        of FK vs sensor of :data:`PARTS`.
        """
        return {
            "axis": self.axis, "steps": self.steps, "tuning": self.tuning, "step_mm": self.step_mm,
            "stairs": self.stairs, "hold_s": self.hold_s, "seed": self.seed, "thesis_figure": self.thesis_figure,
            "sensor": self.sensor,
            "errors": {k: [{"stair": e.stair, "static_mm": e.static_mm, "dynamic_mm": e.dynamic_mm} for e in v]
                       for k, v in self.errors.items()},
            "summary": self.summary, "clearance_bound_mm": self.clearance_bound_mm,
            "sensor_out_of_range": self.sensor_out_of_range, "samples": self.samples,
            "sim_time_s": self.sim_time_s, "wall_time_s": self.wall_time_s, "reading": self.reading,
        }


def _mean(values: np.ndarray) -> float | None:
    ok = values[np.isfinite(values)]
    return float(np.mean(ok)) if ok.size else None


def _round(v: float | None, digits: int = 4) -> float | None:
    return None if v is None else round(v, digits)


def step_errors(t: np.ndarray, err_m: np.ndarray, stair_times: list[float], hold_s: float) -> list[StepErrors]:
    """The static and dynamic error of each stair from an error series (m; NaN where there is no value)."""
    out = []
    for k, t0 in enumerate(stair_times, start=1):
        t_end = t0 + hold_s
        static = err_m[(t >= t_end - STATIC_WINDOW_S) & (t < t_end)]
        dynamic = err_m[(t >= t0) & (t < t0 + DYNAMIC_WINDOW_S)]
        s, d = _mean(static), _mean(np.abs(dynamic))
        out.append(StepErrors(k, _round(None if s is None else s * 1e3), _round(None if d is None else d * 1e3)))
    return out


def clearance_bound_m(params: ArmParams, q: np.ndarray, axis: np.ndarray, spec: SensorSpec) -> float:
    """How far FK of the encoders and the true tool may differ along `axis` at joint angles `q` (m).

    Each drive's half clearance, its gear's deflection under gravity (the
    plant's :func:`~ttt_sm.twin.plant.gear_play`) and one encoder count,
    the servo's half clearance, each times the joint's lever on the axis
    (the Jacobian, eq. 3.30), plus the sensor's resolution and four
    standard deviations of its noise.  The length errors of the arm as built
    come on top (:func:`length_error_m`).
    """
    J = jacobian(q, params.geometry)
    row = np.abs(axis @ J[:3])
    tau = gravity_torques(params, q)
    play = [abs(gear_play(float(tau[j]), d.gear_clearance, d.gear_stiffness)) + d.gear_clearance / 2
            + d.rad_per_count for j, d in enumerate(params.drives)]
    play.append(params.servo.clearance_rad / 2)
    return float(row @ np.asarray(play)) + spec.resolution_m + 4 * spec.noise_m


class StaircaseStage(PathStage):
    """Task stage that plays a staircase's poses and switches its recorder on for the pre-roll and the stairs.

    After the stairs it plays the way back to where the tool started (when
    ``back`` was asked for, :meth:`Staircase.start`) and then sends nothing
    more: the Control chart's pose stands again.  A Safety trip ends it at
    once (the arm is held; no pose of a staircase moves it afterwards).
    """

    def __init__(self, robot: Robot, poses: np.ndarray, first: int, end: int, recorder: StairRecorder) -> None:
        super().__init__(poses)
        self.robot = robot
        self.first, self.end = first, end
        self.recorder = recorder
        #: The simulated time the recording began at (the pre-roll's last tick), or None before.
        self.t_start: float | None = None
        self.aborted = False

    @property
    def recorded(self) -> bool:
        """True once the stairs are recorded whole (the way back may still be played)."""
        return self.index >= self.end and not self.aborted

    def tick(self, signals: Signals) -> None:
        if self.index == self.end:
            self.recorder.on = False
        if self.done:
            return
        if self.robot.tripped:
            self.recorder.on, self.aborted, self.index = False, True, len(self.samples)
            return
        if self.index == self.first - 1:
            self.recorder.on, self.t_start = True, signals.t
        super().tick(signals)


class Staircase:
    """The staircase of section 3.5 on a robot that waits in ``wait_1``: its stage, its recorder, its measurement.

    :meth:`start` puts a :class:`StaircaseStage` after the Control chart's task
    stage (its pose wins while it plays) and a :class:`StairRecorder` last
    among the joint stages; :meth:`result` measures what was recorded.
    ``ttt-sm precision staircase`` (:func:`run_staircase`) and the Operational
    page's "Staircase" both run it so.
    """

    def __init__(self, robot: Robot, spec: StaircaseSpec, tuning: str, seed: int = 0,
                 mount: SensorMount | None = None, sensor_spec: SensorSpec | None = None) -> None:
        if robot.truth is None:
            raise PrecisionError("the staircase is measured with a triangulation sensor on the simulated arm's"
                                 " true tool; this arm has none (run it on the simulated arm)")
        self.robot, self.spec, self.tuning, self.seed = robot, spec, tuning, seed
        self.sensor_spec = sensor_spec or SensorSpec()
        self.sensor = TriangulationSensor(mount or spec.default_mount(), self.sensor_spec, seed=seed + 1)
        self.axis = axis_vector(spec.axis)
        self.recorder = StairRecorder(robot, robot.truth, self.sensor, self.axis)
        self.stage: StaircaseStage | None = None
        self.ticks: list[int] = []
        self.wall0 = time.perf_counter()

    def start(self, back: bool = False) -> StaircaseStage:
        """Play it from the Control chart's pose now (``back``: and return there after the stairs)."""
        robot = self.robot
        c = robot.control
        here = (c.X_out, c.Y_out, c.Z_out, c.phi)
        chart_dt = robot.params.control.chart_dt
        poses, first, self.ticks = staircase_poses(self.spec, here, chart_dt)
        end = len(poses)
        if back:
            poses = np.vstack([poses, _approach(poses[-1], np.asarray(here, dtype=float), chart_dt)])
        self.stage = StaircaseStage(robot, poses, first, end, self.recorder)
        sched = robot.sched
        # the staircases played before go, with their recorders (between two steps: no stage list is being run)
        done = [s for s in sched.task_stages if isinstance(s, StaircaseStage) and s.done]
        gone = [s.recorder for s in done]
        sched.task_stages[:] = [s for s in sched.task_stages if s not in done]
        sched.joint_stages[:] = [s for s in sched.joint_stages if not any(s is r for r in gone)]
        sched.task_stages.append(self.stage)  # after the Control chart's stage: its pose wins
        robot.sched.joint_stages.append(self.recorder)
        return self.stage

    @property
    def playing(self) -> bool:
        """True from :meth:`start` until its last pose (the way back too) is sent."""
        return self.stage is not None and not self.stage.done

    @property
    def chart_ticks(self) -> int:
        """Chart ticks the staircase plays (its approach, pre-roll, stairs and way back)."""
        return 0 if self.stage is None else len(self.stage.samples)

    def finish(self) -> None:
        """Take the recorder off the robot (the stage sends nothing once done)."""
        self.recorder.on = False
        stages = self.robot.sched.joint_stages
        if self.recorder in stages:
            stages.remove(self.recorder)

    def result(self) -> StaircaseResult:
        """The three comparisons and their parts, per stair, of what was recorded."""
        stage = self.stage
        if stage is None or stage.t_start is None or not stage.recorded:
            raise PrecisionError("the staircase was not played to its last stair"
                                 + (f": the Safety chart tripped ({self.robot.safety.reason})"
                                    if stage is not None and stage.aborted else ""))
        robot, spec, rec = self.robot, self.spec, self.recorder.record
        params = robot.params
        chart_dt = params.control.chart_dt
        t_start, first = stage.t_start, stage.first
        t = np.asarray(rec.t)
        a = AXES.index(spec.axis)
        series = {
            "desired": np.asarray(rec.desired)[:, a], "fk": np.asarray(rec.fk)[:, a],
            "true": np.asarray(rec.true)[:, a],
            "sensor": np.array([math.nan if v is None else v for v in rec.sensor]),
        }
        stair_times = [t_start + (k - first) * chart_dt for k in self.ticks]
        tg = params.true_geometry
        q_enc = np.asarray(rec.q_encoder)
        series["fk_as_built"] = np.array([fk(q, tg)[a] for q in q_enc])
        errors = {name: step_errors(t, series[p] - series[m], stair_times, spec.hold_s)
                  for name, (p, m) in {**COMPARISONS, **PARTS}.items()}
        summary = {name: _summary(v) for name, v in errors.items()}
        sspec, sensor = self.sensor_spec, self.sensor
        bound = max(clearance_bound_m(params, q, self.axis, sspec) for q in q_enc[:: max(1, len(q_enc) // 50)])
        result = StaircaseResult(
            axis=spec.axis, steps=spec.steps, tuning=self.tuning, step_mm=spec.step_m * 1e3, stairs=spec.count,
            hold_s=spec.hold_s, seed=self.seed, thesis_figure=THESIS_FIGURE.get((spec.axis, spec.steps)),
            sensor={"origin_m": list(sensor.mount.origin), "beam": list(sensor.mount.beam),
                    "range_m": [sspec.range_min_m, sspec.range_max_m], "resolution_m": sspec.resolution_m,
                    "noise_m": sspec.noise_m},
            errors=errors, summary=summary, clearance_bound_mm=round(bound * 1e3, 4),
            sensor_out_of_range=int(sum(v is None for v in rec.sensor)), samples=len(t),
            sim_time_s=round(robot.t, 3), wall_time_s=round(time.perf_counter() - self.wall0, 3), reading=[],
            t=t - t_start, series=series, stair_times=tuple(s - t_start for s in stair_times),
        )
        return _with_reading(result)


def staircase_playing(robot: Robot) -> StaircaseStage | None:
    """The staircase the robot plays now (its way back included), or None."""
    return next((s for s in robot.sched.task_stages if isinstance(s, StaircaseStage) and not s.done), None)


def _approach(frm: np.ndarray, to: np.ndarray, chart_dt: float) -> np.ndarray:
    """Poses from `frm` to `to` (x, y, z, phi), one per chart tick, at :data:`APPROACH_M_S` at most."""
    dist = float(np.linalg.norm(to[:3] - frm[:3]))
    n = max(1, int(math.ceil(dist / APPROACH_M_S / chart_dt)))
    frac = np.linspace(0.0, 1.0, n + 1)[1:, None]
    return frm + frac * (to - frm)


def run_staircase(params: ArmParams, axis: str, steps: str, tuning: str = "ours", seed: int = 0,
                  count: int = STAIRS, hold_s: float = HOLD_S, mount: SensorMount | None = None,
                  sensor_spec: SensorSpec | None = None) -> StaircaseResult:
    """Run the staircase of section 3.5 on the twin and compare desired, FK of the encoders and the sensor.

    Parameters
    ----------
    params : ArmParams
        The arm.
    axis : {"x", "y", "z"}
        The global axis the staircase runs along.
    steps : {"small", "big"}
        :data:`STEP_M`.
    tuning : {"ours", "thesis"}
        The controllers' gains (:func:`ttt_sm.twin.tuning.gains_for`), switched in once the drives are
        initialised (:class:`~.robot.PresetGainsStage`).
    seed : int
        Seeds the twin and the sensor's noise.
    count, hold_s : int, float
        Stairs and how long each is held, s.
    mount, sensor_spec : optional
        The sensor's pose (default :meth:`StaircaseSpec.default_mount`) and its data (the thesis').
    """
    spec = StaircaseSpec.of(axis, steps, count, hold_s)
    from ..twin.tuning import PRESETS  # here: it imports python-control, which building a robot need not

    if tuning not in PRESETS:
        raise PrecisionError(f"unknown tuning {tuning!r}; choose from {', '.join(PRESETS)}")
    # the arm initialises with the designed gains and runs the preset's once initialised (PresetGainsStage)
    robot = Robot(replace(params, tuning=Tuning(tuning)), seed=seed)
    staircase = Staircase(robot, spec, tuning, seed, mount, sensor_spec)
    if not robot.run_until(lambda: robot.initialised, 40.0):
        raise PrecisionError("the drives did not initialise within 40 s")
    c = robot.control
    if not robot.run_until(lambda: not c.busy, 40.0):
        raise PrecisionError("the Control chart did not reach wait_1 within 40 s")
    stage = staircase.start()
    robot.run_until(lambda: stage.recorded, (staircase.chart_ticks + 1) * params.control.chart_dt)
    staircase.finish()
    if robot.tripped:
        raise PrecisionError(f"the Safety chart tripped during the staircase: {robot.safety.reason}")
    return staircase.result()


def _summary(errs: list[StepErrors]) -> dict[str, float | None]:
    """The largest |static| and the largest dynamic error over the stairs, mm."""
    statics = [abs(e.static_mm) for e in errs if e.static_mm is not None]
    dynamics = [e.dynamic_mm for e in errs if e.dynamic_mm is not None]
    return {"max_static_mm": max(statics) if statics else None, "max_dynamic_mm": max(dynamics) if dynamics else None}


def _with_reading(r: StaircaseResult) -> StaircaseResult:
    """The result with a short reading of what each difference is due to (the thesis' reading, ours)."""
    s = r.summary
    dfk, fks, ds = s["desired_vs_fk"], s["fk_vs_sensor"], s["desired_vs_sensor"]
    lengths, clearance = s["lengths"], s["clearance"]

    def mm(v: float | None) -> str:
        return "no reading" if v is None else f"{v:.3f} mm"

    lag = ("the stairs are smaller than the lag: the measured values trail the desired ones" if r.steps == "small"
           else "each stair is a slew of the drives")
    lines = [
        f"desired vs FK (controllers, inverse kinematics): dynamic up to {mm(dfk['max_dynamic_mm'])}, static up to"
        f" {mm(dfk['max_static_mm'])} -- the dynamic part is the controllers' lag behind the stairs ({lag}),"
        f" the static part what the controllers and the IK tolerance leave",
        f"FK vs sensor (clearances, deflection, lengths): static up to {mm(fks['max_static_mm'])}; of it the link"
        f" lengths FK assumes against the arm as built {mm(lengths['max_static_mm'])}, and the rest"
        f" {mm(clearance['max_static_mm'])} against a bound of {r.clearance_bound_mm:.3f} mm from the clearances,"
        f" the gears' deflection, one encoder count and the sensor",
        f"desired vs sensor (overall): static up to {mm(ds['max_static_mm'])}, dynamic up to"
        f" {mm(ds['max_dynamic_mm'])}",
    ]
    if r.sensor_out_of_range:
        lines.append(f"{r.sensor_out_of_range} of {r.samples} sensor readings were out of its range (null)")
    return StaircaseResult(**{**{f: getattr(r, f) for f in r.__dataclass_fields__}, "reading": lines})


__all__ = ["AXES", "STEP_KINDS", "STEP_M", "STAIRS", "HOLD_S", "STATIC_WINDOW_S", "DYNAMIC_WINDOW_S",
           "COMPARISONS", "PARTS", "THESIS_FIGURE", "PrecisionError", "StaircaseSpec",
           "StepErrors", "StaircaseResult", "StaircaseStage", "Staircase", "staircase_playing",
           "staircase_poses", "step_errors",
           "clearance_bound_m", "run_staircase"]
