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
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..arm import Arm
from ..charts.drive_init import DriveInit1, DriveInit2, DriveInit3
from ..params import ArmParams
from ..sched.scheduler import Scheduler, Signals
from ..twin.kinematics import link_points
from ..twin.plant import ArmSim


def servo_init_angle(params: ArmParams) -> float:
    """Servo angle during initialisation: the pen vertical (phi = 0) once drives 2 and 3 park."""
    return -(params.drives[1].park_rad + params.drives[2].park_rad)


def make_init_charts(params: ArmParams, listeners: Sequence[object] = ()) -> tuple[
        DriveInit1, DriveInit2, DriveInit3]:
    """The three init charts with the switch and parking angles of `params`."""
    d1, d2, d3 = params.drives
    period = params.control.chart_dt
    lst = list(listeners)
    c1 = DriveInit1(tick_period_s=period, listeners=lst,
                    data={"index_angle": d1.index_rad, "park": d1.park_rad})
    c2 = DriveInit2(tick_period_s=period, listeners=lst,
                    data={"index_angle": d2.index_rad, "park": d2.park_rad})
    c3 = DriveInit3(tick_period_s=period, listeners=lst,
                    data={"index_angle": d3.index_rad, "park": d3.park_rad})
    return c1, c2, c3


class DriveInitStage:
    """Joint stage: the Encoder blocks and the three init charts between IK and the drives."""

    def __init__(self, params: ArmParams, arm: Arm, sched: Scheduler,
                 charts: tuple[DriveInit1, DriveInit2, DriveInit3]) -> None:
        self.arm = arm
        self.sched = sched
        self.charts = charts
        self.rad_per_count = [d.rad_per_count for d in params.drives]
        self.servo_init = servo_init_angle(params)
        self.applied = [0.0, 0.0, 0.0]
        #: Inputs forced by a test or scenario, applied after the Encoder blocks: (chart index, name) -> value.
        self.overrides: dict[tuple[int, str], object] = {}
        self.done = False  # every drive passes its commanded position through
        # the charts' data as plain dictionaries: inputs are written every chart step
        self._inputs = tuple(vars(c) for c in charts)
        self.failed = False  # a chart gave up (a switch not found)

    def _update_status(self) -> None:
        # Reading the configuration costs microseconds: only after a transition.
        self.done = all("pass_pos" in c.active_ids for c in self.charts)
        self.failed = any("failed" in c.active_ids for c in self.charts)

    def tick(self, signals: Signals) -> None:
        """Encoder blocks in, charts ticked, offsets applied, pos_out out."""
        c1, c2, c3 = self.charts
        q_set = signals.q_set
        pos_in = q_set.tolist() if type(q_set) is np.ndarray else q_set
        # Each chart reads the others' flags as they were at the end of the last step.
        ini_23, ini2, ini3 = c1.ini_23, c2.ini2, c3.ini3
        if self.done:
            # Initialised: only pos_in and the flags matter; skip the Encoder blocks.
            d1, d2, d3 = self._inputs
            d1["pos_in"], d1["ini2"], d1["ini3"] = pos_in[0], ini2, ini3
            d2["pos_in"], d2["ini1"], d2["ini3"] = pos_in[1], ini_23, ini3
            d3["pos_in"], d3["ini1"], d3["ini2"] = pos_in[2], ini_23, ini2
            if not self.overrides and not (d1["_queue"] or d2["_queue"] or d3["_queue"]):
                # the offsets are set for good: tick and pass on (every chart step of a game)
                t1, t2, t3 = c1.tick(), c2.tick(), c3.tick()
                if t1 or t2 or t3:
                    self._update_status()
                signals.q_set = [c1.pos_out, c2.pos_out, c3.pos_out, pos_in[3]]
                return
        else:
            sensors = signals.sensors
            assert sensors is not None
            enc = self.arm.encoder_angles()
            offsets = self.arm.offset_estimates()
            idx, counts, rpc = sensors.index, sensors.index_count, self.rad_per_count
            latched = [counts[d] * rpc[d] + offsets[d] for d in range(3)]
            # vars(...).update: the inputs are plain attributes; this skips the
            # chart's state-name check on every assignment (a hot path).
            vars(c1).update(pos_in=pos_in[0], index=idx[0], pos_Encoder=enc[0], index_pos=latched[0],
                            ini2=ini2, ini3=ini3)
            vars(c2).update(pos_in=pos_in[1], index=idx[1], index_pos=latched[1], ini1=ini_23, ini3=ini3)
            vars(c3).update(pos_in=pos_in[2], index=idx[2], index_pos=latched[2], ini1=ini_23, ini2=ini2)
        for (d, name), value in self.overrides.items():
            setattr(self.charts[d], name, value)
        # Posted events may move a chart without a tick transition.
        moved = bool(c1._queue or c2._queue or c3._queue)
        applied = self.applied
        for d, chart in enumerate(self.charts):
            if chart.tick() is not None:
                moved = True
            if chart.offset != applied[d]:
                self.arm.set_offset_estimate(d + 1, chart.offset)
                applied[d] = chart.offset
                self.sched.mark_homed(d + 1)
        if moved:
            self._update_status()
        servo = pos_in[3] if self.done else self.servo_init
        # a list: the next stages and the scheduler read it as floats (no array round trip)
        signals.q_set = [c1.pos_out, c2.pos_out, c3.pos_out, servo]


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

    def __init__(self, params: ArmParams, sim: ArmSim, allowance_rad: float) -> None:
        self.params = params
        self.sim = sim
        self.truth = sim.truth
        allowance = np.array([allowance_rad, 0.0, 0.0])
        self.lo = np.array([d.limit_min_rad for d in params.drives]) - allowance
        self.hi = np.array([d.limit_max_rad for d in params.drives]) + allowance
        self.limit_violations = 0
        self.zone_ticks = 0
        self.max_overtravel_rad = 0.0

    def tick(self, signals: Signals) -> None:
        """Check this chart step's setpoints and the true tool position."""
        sim, truth = self.sim, self.truth
        q_true_cmd = np.asarray(signals.q_set[:3]) - sim.offset_estimate + truth.offsets
        over = np.maximum(q_true_cmd - self.hi, self.lo - q_true_cmd)
        self.max_overtravel_rad = max(self.max_overtravel_rad, float(over.max()))
        if np.any(over > 0):
            self.limit_violations += 1
        board = self.params.board
        if any(board.in_zone(x, y, z) for x, y, z in link_points(truth.q, self.params.geometry)):
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


def random_power_on(params: ArmParams, rng: np.random.Generator) -> np.ndarray:
    """A pose anywhere between the hard stops (drives 1-3), servo at its init angle."""
    lo = np.array([d.limit_min_rad for d in params.drives])
    hi = np.array([d.limit_max_rad for d in params.drives])
    return np.append(rng.uniform(lo, hi), servo_init_angle(params))


def settled_pose(params: ArmParams, q_start: np.ndarray | None, seconds: float, seed: int) -> np.ndarray:
    """Where the unpowered arm comes to rest from `q_start` under gravity and friction."""
    sim = ArmSim(params, seed=seed, q0=q_start)
    sim.settle_unpowered(seconds)
    return sim.truth.q


def run_init(params: ArmParams, seed: int = 0, q_start: np.ndarray | None = None,
             settle_s: float = 2.0, timeout_s: float = 40.0) -> InitRun:
    """Initialise the twin once.

    The arm is placed at `q_start` (default: its rest pose) and left unpowered
    for `settle_s`, so gravity brings the pitch joints down as it would before
    anyone switches the arm on (drive 2 "near zero", section 3.1.2).  Then the
    arm is powered: the encoders start counting from zero there, the
    controllers hold where the arm stands, and the init charts take over.
    """
    q_power_on = settled_pose(params, q_start, settle_s, seed) if settle_s > 0 else q_start
    sim = ArmSim(params, seed=seed, q0=q_power_on)
    q0_true = sim.truth.q
    sched = Scheduler(params, sim)
    charts = make_init_charts(params)
    stage = DriveInitStage(params, sim, sched, charts)
    # Drive 1 may push its setpoint past a stop by its stall band (and one more step) to find it.
    one_step = charts[0].search_speed * params.control.chart_dt
    monitor = InitMonitor(params, sim, allowance_rad=charts[0].stall_lag + one_step)
    sched.joint_stages = [stage, monitor]
    t0 = sim.t
    sched.run_until(lambda: stage.done or stage.failed, timeout_s)
    return InitRun(
        q_power_on=tuple(float(v) for v in q0_true),  # type: ignore[arg-type]
        success=stage.done,
        time_s=round(sim.t - t0, 4),
        limit_violations=monitor.limit_violations,
        board_zone_ticks=monitor.zone_ticks,
        offset_error_rad=tuple(float(v) for v in sim.offset_estimate - sim.truth.offsets),  # type: ignore
        max_overtravel_rad=round(monitor.max_overtravel_rad, 5),
    )


def init_report(params: ArmParams, starts: int, seed: int = 0) -> dict[str, Any]:
    """Initialise from `starts` random power-on poses: what `ttt-sm init --json` prints."""
    rng = np.random.default_rng(seed)
    wall0 = time.perf_counter()
    runs = [run_init(params, seed=seed + k, q_start=random_power_on(params, rng)) for k in range(starts)]
    times = [r.time_s for r in runs]
    offset_errors = [abs(e) for r in runs if r.success for e in r.offset_error_rad]
    count = min(d.rad_per_count for d in params.drives)
    return {
        "runs": len(runs),
        "successes": sum(r.success for r in runs),
        "limit_violations": sum(r.limit_violations for r in runs),
        "board_zone_entries": sum(r.board_zone_ticks > 0 for r in runs),
        "max_time_s": round(max(times), 3),
        "mean_time_s": round(float(np.mean(times)), 3),
        "max_offset_error_rad": float(max(offset_errors)) if offset_errors else math.nan,
        "one_count_rad": count,
        "max_overtravel_rad": max(r.max_overtravel_rad for r in runs),
        "wall_time_s": round(time.perf_counter() - wall0, 2),
        "failed_power_on_deg": [[round(math.degrees(v), 1) for v in r.q_power_on] for r in runs
                                if not r.success],
    }
