"""Wiring of the drive-initialisation charts into the twin (thesis fig. 3.2).

:class:`DriveInitStage` is a joint stage of the scheduler: every chart step it
plays the thesis' Encoder block (index level, the encoder angle latched at the
index edge, the encoder angle itself), feeds the three charts, ticks them, and
passes their `pos_out` to the controllers.  When a chart moves its `offset`
output, the Encoder block applies it, so the drive's encoder angle becomes its
true joint angle from then on.  It reads only what a real arm reports (an
:class:`~ttt_sm.arm.Arm`).

:func:`run_init` initialises the twin from one power-on pose, and
:func:`init_report` from many, measuring what `ttt-sm init` reports; the
measurement (:class:`InitMonitor`, the offset errors) compares with the
twin's ground truth, so these exist in simulation only.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from ..arm import Arm, Sensors
from ..charts.drive_init import DriveInit1, DriveInit2, DriveInit3
from ..params import ArmParams
from ..runner import Runner, one_line, throughput
from ..sched.scheduler import Scheduler, Signals
from ..twin.gains import Gains
from ..twin.gains_cache import kept_gains
from ..twin.kinematics import link_points
from ..twin.sim import ArmSim
from ..twin.truth import GroundTruth
from .slots import THESIS_SLOTS, ChartSlots
from .wires import BLOCKS, INIT_WIRES
from .wiring import Wiring, not_wired, wire_stages


def servo_init_angle(params: ArmParams) -> float:
    """Servo angle during initialisation: the pen vertical (phi = 0) once drives 2 and 3 park."""
    return -(params.drives[1].park_rad + params.drives[2].park_rad)


def init_chart_data(params: ArmParams, offsets: Sequence[float] = (0.0, 0.0, 0.0)) -> tuple[dict[str, float], ...]:
    """What the builder sets in each init chart from `params`: switch and parking angles, the offset."""
    return tuple({"index_angle": d.index_rad, "park": d.park_rad, "offset": offsets[k]}
                 for k, d in enumerate(params.drives))


def make_init_charts(params: ArmParams, listeners: Sequence[object] = (),
                     offsets: Sequence[float] = (0.0, 0.0, 0.0),
                     slots: ChartSlots = THESIS_SLOTS) -> tuple[DriveInit1, DriveInit2, DriveInit3]:
    """The three init charts with the switch and parking angles of `params`.

    `offsets`: the encoder offsets the arm applies when the charts start (0 at
    power-on; a re-initialisation sets those that make every encoder read 0).
    `slots`: the class of each (:mod:`.slots`; the thesis' by default).
    """
    period = params.control.chart_dt
    lst = list(listeners)
    c1, c2, c3 = (slots.make(f"DriveInit{k + 1}", tick_period_s=period, listeners=lst, data=data)
                  for k, data in enumerate(init_chart_data(params, offsets)))
    # a slotted class meets the thesis chart's contract (checked when it was chosen), not its type
    return cast(tuple[DriveInit1, DriveInit2, DriveInit3], (c1, c2, c3))


class EncoderBlock:
    """The thesis' Encoder blocks of drives 1-3 (fig. 3.2): what the init charts read of the arm.

    Its outputs (the table's ``Encoder.index``, ``angle``, ``index_angle``)
    are plain sequences, refreshed by :meth:`read` from the arm's readings
    once per chart step; :attr:`applied` holds the offsets given to the arm.
    """

    def __init__(self, params: ArmParams) -> None:
        self.rad_per_count = [d.rad_per_count for d in params.drives]
        self.index: Sequence[bool] = (False, False, False)
        self.angle: Sequence[float] = (0.0, 0.0, 0.0)
        self.index_angle: Sequence[float] = (0.0, 0.0, 0.0)
        self.applied = [0.0, 0.0, 0.0]

    def read(self, sensors: Sensors, angles: Sequence[float], offsets: Sequence[float]) -> None:
        """Index levels, encoder angles, and the angles latched at the last index edges (counts + offsets)."""
        counts, rpc = sensors.index_count, self.rad_per_count
        self.index = sensors.index
        self.angle = angles
        self.index_angle = [counts[0] * rpc[0] + offsets[0], counts[1] * rpc[1] + offsets[1],
                            counts[2] * rpc[2] + offsets[2]]


class DriveInitStage:
    """Joint stage: the Encoder blocks and the three init charts between IK and the drives.

    Which input comes from where is the wiring table's (:mod:`.wires`); the
    stage runs it: Encoder blocks read, inputs fed, charts ticked, offsets
    applied, `pos_out` to the drives.  Once every drive passes its position
    through, the Encoder blocks hold their outputs (an enabled subsystem, as
    in Simulink): their wires are not fed, which saves reading the arm on
    every chart step of a game.
    """

    def __init__(self, params: ArmParams, arm: Arm, sched: Scheduler,
                 charts: tuple[DriveInit1, DriveInit2, DriveInit3]) -> None:
        self.arm = arm
        self.sched = sched
        self.charts = charts
        self.encoder = EncoderBlock(params)
        self.encoder.applied = [c.offset for c in charts]  # what the arm applies already (0 at power-on)
        self.servo_init = servo_init_angle(params)
        #: Inputs forced by a test or scenario, applied after the Encoder blocks: (chart index, name) -> value.
        self.overrides: dict[tuple[int, str], object] = {}
        self.done = False  # every drive passes its commanded position through (the table's Homing.done)
        self.failed = False  # a chart gave up (a switch not found)
        self._data = tuple(vars(c) for c in charts)  # the charts' data, as plain dictionaries
        self._feed: Callable[[Sequence[float]], None] = not_wired
        self._feed_held: Callable[[Sequence[float]], None] = not_wired
        self._setpoints: Callable[[], list[float]] = not_wired  # type: ignore[assignment]
        self._offsets: Callable[[], list[float]] = not_wired  # type: ignore[assignment]
        self._status: Callable[[], tuple[list[bool], list[bool]]] = not_wired  # type: ignore[assignment]

    @property
    def any_gave_up(self) -> bool:
        """The table's ``Homing.any_gave_up``: a chart gave up (:attr:`failed`)."""
        return self.failed

    @any_gave_up.setter
    def any_gave_up(self, value: bool) -> None:
        self.failed = value

    def blocks(self) -> dict[str, object]:
        """The objects holding the outputs of this stage's blocks (Encoder, Homing), by block name.

        The IK block's output, this chart step's joint coordinates, is the feeds' argument.
        """
        return {"Encoder": self.encoder, "Homing": self}

    def wire(self, wiring: Wiring) -> None:
        """Compile this stage's part of the wiring table."""
        names = [c.chart_name for c in self.charts]
        self._feed = wiring.feed(names, args=("IK",))
        self._feed_held = wiring.feed(names, skip=("Encoder",), args=("IK",))
        self._setpoints = wiring.collect("Drives.q_set")
        self._offsets = wiring.collect("Encoder.offset")
        self._status = wiring.collect("Homing.passing", "Homing.gave_up")

    def _update_status(self) -> None:
        passing, gave_up = self._status()
        self.done = all(passing)
        self.failed = any(gave_up)

    def tick(self, signals: Signals) -> None:
        """Encoder blocks in, charts ticked, offsets applied, pos_out out."""
        c1, c2, c3 = self.charts
        q_set = signals.q_set
        pos_in: Sequence[float] = q_set.tolist() if type(q_set) is np.ndarray else q_set  # type: ignore[assignment]
        if self.done:
            self._feed_held(pos_in)
            d1, d2, d3 = self._data
            if not self.overrides and not (d1["_queue"] or d2["_queue"] or d3["_queue"]):
                # the offsets are set for good: tick and pass on (every chart step of a game)
                t1, t2, t3 = c1.tick(), c2.tick(), c3.tick()
                if t1 or t2 or t3:
                    self._update_status()
                q = self._setpoints()
                q.append(pos_in[3])
                signals.q_set = q
                return
        else:
            sensors = signals.sensors
            assert sensors is not None
            self.encoder.read(sensors, self.arm.encoder_angles(), self.arm.offset_estimates())
            self._feed(pos_in)
        for (d, name), value in self.overrides.items():
            setattr(self.charts[d], name, value)
        # Posted events may move a chart without a tick transition.
        moved = bool(c1._queue or c2._queue or c3._queue)
        for chart in self.charts:
            if chart.tick() is not None:
                moved = True
        offsets, applied = self._offsets(), self.encoder.applied
        for d in range(3):
            if offsets[d] != applied[d]:  # the Encoder block applies a new offset from now on
                self.arm.set_offset_estimate(d + 1, offsets[d])
                applied[d] = offsets[d]
                self.sched.mark_homed(d + 1)
        if moved:
            self._update_status()
        q = self._setpoints()
        # a list: the next stages and the scheduler read it as floats (no array round trip)
        q.append(pos_in[3] if self.done else self.servo_init)
        signals.q_set = q


class InitMonitor:
    """Joint stage run last: counts board-zone entries and commands past a joint limit.

    A board-zone entry is a chart step in which the elbow, the wrist or the pen
    tip is inside the zone (:meth:`Board.in_zone`).

    A command past a limit is a setpoint, in true joint coordinates, beyond a
    hard stop; for drive 1, beyond it by more than `allowance_rad`: drive 1
    finds a stop by pushing its setpoint a little past it (that is how the
    thesis detects a stall without a limit-switch signal), and no more.
    Drives 2 and 3 get no allowance.

    Simulation only: it measures against the twin's ground truth.
    """

    def __init__(self, params: ArmParams, arm: Arm, truth: GroundTruth, allowance_rad: float) -> None:
        self.params = params
        self.arm = arm
        self.truth = truth
        allowance = np.array([allowance_rad, 0.0, 0.0])
        self.lo = np.array([d.limit_min_rad for d in params.drives]) - allowance
        self.hi = np.array([d.limit_max_rad for d in params.drives]) + allowance
        self.limit_violations = 0
        self.zone_ticks = 0
        self.max_overtravel_rad = 0.0

    def tick(self, signals: Signals) -> None:
        """Check this chart step's setpoints and the true tool position."""
        truth = self.truth
        q_true_cmd = np.asarray(signals.q_set[:3]) - np.asarray(self.arm.offset_estimates()) + truth.offsets
        over = np.maximum(q_true_cmd - self.hi, self.lo - q_true_cmd)
        self.max_overtravel_rad = max(self.max_overtravel_rad, float(over.max()))
        if np.any(over > 0):
            self.limit_violations += 1
        board = self.params.board
        if any(board.in_zone(x, y, z) for x, y, z in link_points(truth.q, self.params.true_geometry)):
            self.zone_ticks += 1


@dataclass(frozen=True)
class InitRun:
    """One initialisation from one power-on pose."""

    q_power_on: tuple[float, float, float, float]
    success: bool
    time_s: float
    limit_violations: int
    board_zone_ticks: int
    offset_error_rad: tuple[float, float, float]
    max_overtravel_rad: float
    #: Why the run has no result ("": it ran): it raised, or the pool or cluster lost it.
    error: str = ""


def random_power_on(params: ArmParams, rng: np.random.Generator) -> np.ndarray:
    """A pose anywhere between the hard stops (drives 1-3), servo at its init angle."""
    lo = np.array([d.limit_min_rad for d in params.drives])
    hi = np.array([d.limit_max_rad for d in params.drives])
    return np.append(rng.uniform(lo, hi), servo_init_angle(params))


def settled_pose(params: ArmParams, q_start: np.ndarray | None, seconds: float, seed: int,
                 gains: Gains | None = None) -> np.ndarray:
    """Where the unpowered arm comes to rest from `q_start` under gravity and friction."""
    sim = ArmSim(params, gains=gains, seed=seed, q0=q_start)
    sim.settle_unpowered(seconds)
    return sim.truth.q


#: Longest one initialisation may run, in simulated seconds, unless told otherwise (one takes 6-12 s).
DEFAULT_INIT_TIMEOUT_S = 40.0


def run_init(params: ArmParams, seed: int = 0, q_start: np.ndarray | None = None,
             settle_s: float = 2.0, timeout_s: float = DEFAULT_INIT_TIMEOUT_S, gains: Gains | None = None) -> InitRun:
    """Initialise the twin once.

    The arm is placed at `q_start` (default: its rest pose) and left unpowered
    for `settle_s`, so gravity brings the pitch joints down as it would before
    anyone switches the arm on (drive 2 "near zero", section 3.1.2).  Then the
    arm is powered: the encoders start counting from zero there, the
    controllers hold where the arm stands, and the init charts take over, for
    at most `timeout_s` of simulated time (a run that reaches it is a failure).
    `gains`: the controllers' (default: designed from `params`, which takes a
    few seconds the first time in a process; a sweep designs them once and
    hands them to every worker).
    """
    q_power_on = settled_pose(params, q_start, settle_s, seed, gains) if settle_s > 0 else q_start
    sim = ArmSim(params, gains=gains, seed=seed, q0=q_power_on)
    return init_once(params, sim, sim.truth, timeout_s)


def init_once(params: ArmParams, arm: Arm, truth: GroundTruth, timeout_s: float = DEFAULT_INIT_TIMEOUT_S) -> InitRun:
    """Run the init charts once on `arm` from where it stands, watched against `truth` (:class:`InitMonitor`).

    The twin (:func:`run_init`), or an emulated arm behind a serial link whose
    emulator sends its ground truth (``ttt-sm init --arm serial:PORT``).
    """
    q0_true = truth.q
    sched = Scheduler(params, arm)
    charts = make_init_charts(params)
    stage = DriveInitStage(params, arm, sched, charts)
    wire_stages(INIT_WIRES, {c.chart_name: c for c in charts}, [stage], BLOCKS)
    # Drive 1 may push its setpoint past a stop by its stall band (and one more step) to find it.
    one_step = charts[0].search_speed * params.control.chart_dt
    monitor = InitMonitor(params, arm, truth, allowance_rad=charts[0].stall_lag + one_step)
    sched.joint_stages = [stage, monitor]
    t0 = arm.t
    sched.run_until(lambda: stage.done or stage.failed, timeout_s)
    return InitRun(
        q_power_on=tuple(float(v) for v in q0_true),  # type: ignore[arg-type]
        success=stage.done,
        time_s=round(arm.t - t0, 4),
        limit_violations=monitor.limit_violations,
        board_zone_ticks=monitor.zone_ticks,
        offset_error_rad=tuple(float(v) for v in np.asarray(arm.offset_estimates()) - truth.offsets),  # type: ignore
        max_overtravel_rad=round(monitor.max_overtravel_rad, 5),
    )


def _init_task(params: ArmParams, seed: int, q_start: np.ndarray, timeout_s: float, gains: Gains) -> InitRun:
    """One start of a sweep, as a worker runs it (a module-level function: a pool or Dask pickles it by name)."""
    return run_init(params, seed=seed, q_start=q_start, timeout_s=timeout_s, gains=gains)


def _failed_run(q_start: np.ndarray, exc: BaseException) -> InitRun:
    """A start whose run raised or was lost by the pool or cluster: a failure, from its power-on pose."""
    return InitRun(q_power_on=tuple(float(v) for v in q_start), success=False,  # type: ignore[arg-type]
                   time_s=math.nan, limit_violations=0, board_zone_ticks=0,
                   offset_error_rad=(math.nan, math.nan, math.nan), max_overtravel_rad=0.0,
                   error=one_line(exc))


#: What a pool's fork server imports once for the init sweep's workers.
INIT_PRELOAD = ("ttt_sm.app.init_wiring",)


def init_report(params: ArmParams, starts: int, seed: int = 0, timeout_s: float = DEFAULT_INIT_TIMEOUT_S,
                status: Callable[[str], None] | None = None, arm: Arm | None = None,
                truth: GroundTruth | None = None, runner: Runner | None = None) -> dict[str, Any]:
    """Initialise from `starts` random power-on poses: what `ttt-sm init --json` prints.

    Each run is bounded by `timeout_s` of simulated time; `status` hears ``k/N``
    as the runs complete.  The runs share nothing: start k is seed + k from the
    k-th pose drawn from one generator seeded with `seed`, all drawn before any
    runs, so `runner` (:class:`~ttt_sm.runner.Runner`: this process by default,
    a local pool or a Dask cluster) changes the wall time, never the report.
    A Ctrl-C raises :class:`~ttt_sm.runner.SweepInterrupted` holding the report
    of the runs done so far (``"interrupted": true``).
    With `arm` (and its `truth`), one run on that arm from where it stands (`starts` must be 1).
    """
    runner = runner or Runner()
    wall0 = time.perf_counter()
    if arm is not None:
        if truth is None or starts != 1:
            raise ValueError("an arm behind a serial link initialises once, from where it stands, and is watched"
                             " against its emulator's ground truth" + ("" if truth else ": this one sends none"))
        if runner.backend != "local" or runner.workers != 1:
            raise ValueError("an arm behind a serial link initialises once, in this process: no --workers, no --dask")
        run = init_once(params, arm, truth, timeout_s)
        return _init_summary(params, [run], wall0, runner, interrupted=False)
    rng = np.random.default_rng(seed)
    poses = [random_power_on(params, rng) for _ in range(starts)]
    gains = kept_gains(params)
    tasks = [(params, seed + k, q, timeout_s, gains) for k, q in enumerate(poses)]
    return runner.sweep(_init_task, tasks, lambda k, exc: _failed_run(poses[k], exc),
                        lambda runs, cut: _init_summary(params, runs, wall0, runner, interrupted=cut), "init",
                        status, lambda run, runs: f"{sum(r.success for r in runs)} initialised so far")


def _init_summary(params: ArmParams, runs: list[InitRun], wall0: float, runner: Runner,
                  interrupted: bool) -> dict[str, Any]:
    """The report of `runs` (in the order of their starts), begun at `wall0` on `runner`."""
    times = [r.time_s for r in runs if not math.isnan(r.time_s)]
    offset_errors = [abs(e) for r in runs if r.success for e in r.offset_error_rad]
    count = min(d.rad_per_count for d in params.drives)
    wall_s = time.perf_counter() - wall0
    workers = runner.workers
    report: dict[str, Any] = {
        "runs": len(runs),
        "successes": sum(r.success for r in runs),
        "limit_violations": sum(r.limit_violations for r in runs),
        "board_zone_entries": sum(r.board_zone_ticks > 0 for r in runs),
        "max_time_s": round(max(times), 3) if times else math.nan,
        "mean_time_s": round(float(np.mean(times)), 3) if times else math.nan,
        "max_offset_error_rad": float(max(offset_errors)) if offset_errors else math.nan,
        "one_count_rad": count,
        "max_overtravel_rad": max((r.max_overtravel_rad for r in runs), default=0.0),
        "wall_time_s": round(wall_s, 2),
        "failed_power_on_deg": [[round(math.degrees(v), 1) for v in r.q_power_on] for r in runs
                                if not r.success],
        "workers": workers,
        "backend": runner.backend,
        "throughput_per_worker": throughput(len(runs), wall_s, workers),
        "interrupted": interrupted,
    }
    errors = [f"start at {[round(math.degrees(v), 1) for v in r.q_power_on]} deg: {r.error}" for r in runs if r.error]
    if errors:
        report["errors"] = errors
    return report
