"""One control step, run on a clock (drawn in docs/architecture.md, "One control step").

One control step: read the sensors; every `chart_divider`-th step tick the
chart stages (task stages produce the tool pose, inverse kinematics turns it
into joint setpoints, joint stages such as the drive-initialisation charts
pass or replace them); clamp to the joint limits; then the setpoint filters,
cascade controllers and plant advance one step (``arm.step``: inside the
simulated arm, or in the microcontroller of a hardware arm).

The scheduler is typed on :class:`~ttt_sm.arm.Arm`: it reads what a real arm
reports and never the simulation's ground truth.

Charts plug in as *stages*: objects with ``tick(signals)`` that read and write
the :class:`Signals` of the current chart step.  A plain path is a task stage
(:class:`PathStage`); the chart runtime of a later issue supplies chart stages.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from ..arm import Arm, Sensors
from ..params import ArmParams
from ..twin.kinematics import IKError, IKSolver, fk
from .clock import Clock, VirtualClock


class Signals:
    """The signals of one chart step, as the debugger and a trace see them.

    Stages read and write these fields; the scheduler fills `t`, `q_des` (from
    IK of `task`) and `q_set` (clamped) around them.  `sensors` is read from
    the arm on first use in a chart step, so steps that need none pay nothing.
    """

    __slots__ = ("t", "task", "fr_sw", "q_des", "q_set", "ik_iterations", "ik_error",
                 "_read_sensors", "_sensors")

    def __init__(self, read_sensors: Callable[[], Sensors] | None = None) -> None:
        self.t = 0.0
        self.task: np.ndarray | list[float] = np.full(4, np.nan)  # X, Y, Z, phi; NaN: no task pose
        self.fr_sw = False
        self.q_des: np.ndarray | Sequence[float] = np.full(4, np.nan)  # IK output
        self.q_set: np.ndarray | Sequence[float] = np.full(4, np.nan)  # to the controllers
        self.ik_iterations = 0
        self.ik_error: str | None = None
        self._read_sensors = read_sensors
        self._sensors: Sensors | None = None

    @property
    def sensors(self) -> Sensors | None:
        """Encoder counts, index switches and currents at the start of this chart step."""
        if self._sensors is None and self._read_sensors is not None:
            self._sensors = self._read_sensors()
        return self._sensors

    def new_step(self, t: float) -> None:
        """Start a chart step at time `t`: sensors are read afresh when asked for."""
        self.t = t
        self._sensors = None
        self.ik_error = None


class Stage(Protocol):
    """Something ticked at the chart rate: a chart, or a plain setpoint source."""

    def tick(self, signals: Signals) -> None:
        """Read and write the signals of this chart step."""


class PathStage:
    """A task stage that plays precomputed tool poses, one row per chart tick.

    After the last row it holds the last pose; `done` tells when it got there.
    """

    def __init__(self, samples: np.ndarray, fr_sw: bool = False) -> None:
        if samples.ndim != 2 or samples.shape[1] != 4 or len(samples) == 0:
            raise ValueError(f"path samples must have shape (n, 4), got {samples.shape}")
        self.samples = samples
        self.fr_sw = fr_sw
        self.index = 0

    @property
    def done(self) -> bool:
        """True once the last pose has been sent."""
        return self.index >= len(self.samples)

    def tick(self, signals: Signals) -> None:
        """Send the next pose."""
        i = min(self.index, len(self.samples) - 1)
        signals.task = self.samples[i]
        signals.fr_sw = self.fr_sw
        self.index += 1


@dataclass
class Record:
    """Per chart tick history of a run, for plots and precision figures."""

    t: list[float] = field(default_factory=list)
    task: list[np.ndarray] = field(default_factory=list)
    q_set: list[np.ndarray] = field(default_factory=list)
    q_encoder: list[np.ndarray] = field(default_factory=list)

    def arrays(self) -> dict[str, np.ndarray]:
        """The history as arrays, one row per chart tick."""
        return {"t": np.asarray(self.t), "task": np.asarray(self.task),
                "q_set": np.asarray(self.q_set), "q_encoder": np.asarray(self.q_encoder)}


class Scheduler:
    """Runs the control step (docs/architecture.md) on a virtual or wall clock.

    Parameters
    ----------
    params : ArmParams
        The arm.
    arm : Arm
        The arm with its controllers: the simulated arm, or a hardware backend.
    task_stages, joint_stages : sequence of Stage
        Ticked at the chart rate before and after inverse kinematics.
    clock : Clock, optional
        Virtual time by default.
    record : bool
        Keep a per-chart-tick :class:`Record` (costs time; off for benchmarks).
    """

    def __init__(self, params: ArmParams, arm: Arm, task_stages: Sequence[Stage] = (),
                 joint_stages: Sequence[Stage] = (), clock: Clock | None = None,
                 ik: IKSolver | None = None, record: bool = False) -> None:
        self.params = params
        self.arm = arm
        self.task_stages = list(task_stages)
        self.joint_stages = list(joint_stages)
        self.clock = clock if clock is not None else VirtualClock()
        self.ik = ik if ik is not None else IKSolver(params)
        self.divider = params.control.chart_divider
        self.q_min = tuple(params.joint_min)
        self.q_max = tuple(params.joint_max)
        # Joint limits apply in encoder coordinates only once a drive's offset
        # is known (mark_homed); the servo is absolute, so its limits always apply.
        self._lo = [-math.inf, -math.inf, -math.inf, self.q_min[3]]
        self._hi = [math.inf, math.inf, math.inf, self.q_max[3]]
        self.signals = Signals(arm.sensors)
        self.steps = 0
        self.chart_ticks = 0
        self.ik_failures = 0
        self.limit_clamps = 0
        self.record = Record() if record else None
        self._hold: Sequence[float] = [*arm.encoder_angles(), arm.servo_setpoint]
        self._clock_started = False
        self._period0 = 0
        self._ik_pose: list[float] = []  # the last pose solved, and its answer
        self._ik_q: Sequence[float] = (math.nan,) * 4

    @property
    def t(self) -> float:
        """The arm's time, s."""
        return self.arm.t

    @property
    def homed(self) -> tuple[bool, bool, bool, bool]:
        """Whether each joint's limits are enforced (drives once initialised, the servo always)."""
        return tuple(math.isfinite(v) for v in self._lo)  # type: ignore[return-value]

    def mark_homed(self, drive: int) -> None:
        """Enforce drive `drive`'s (1-3) joint limits from now on: its encoder offset is known."""
        self._lo[drive - 1] = self.q_min[drive - 1]
        self._hi[drive - 1] = self.q_max[drive - 1]

    def forget_homing(self) -> None:
        """Stop enforcing the drives' joint limits: their offsets are being searched again (a re-initialisation)."""
        for drive in (1, 2, 3):
            self._lo[drive - 1] = -math.inf
            self._hi[drive - 1] = math.inf

    def mark_all_homed(self) -> None:
        """Enforce every drive's limits and hold where the arm is: all offsets are known.

        For an arm whose offsets were set without the init charts (in
        simulation, ``ArmSim.assume_initialised``: tests and the bench).
        """
        for drive in (1, 2, 3):
            self.mark_homed(drive)
        self._hold = [*self.arm.encoder_angles(), self.arm.servo_setpoint]

    def set_clock(self, clock: Clock) -> None:
        """Switch clocks; the new clock's period 0 is the next control step."""
        self.clock = clock
        self._clock_started = False
        self._period0 = self.steps

    def tick_charts(self) -> Signals:
        """One chart step: task stages, IK, joint stages, clamp, setpoints."""
        s = self.signals
        s.new_step(self.arm.t)
        for stage in self.task_stages:
            stage.tick(s)
        task = s.task
        # a new list of numbers (tolist for an array, a copy for a list)
        pose: list[float] = task.tolist() if isinstance(task, np.ndarray) else list(task)
        if pose == self._ik_pose:
            # The same pose as last step (the arm waits): IK is a function of
            # the pose and its warm start, so the answer is the last one.
            s.q_des = self._ik_q
            s.ik_iterations = 0
        elif math.isfinite(pose[0] + pose[1] + pose[2] + pose[3]):
            try:
                q_ik, s.ik_iterations = self.ik.solve_pose(*pose)
            except IKError as exc:
                # Unreachable pose: hold the last good joint setpoints (a safe
                # state) and report; never pass a wrong answer to the drives.
                self.ik_failures += 1
                s.ik_error = str(exc)
                s.q_des = list(self._hold)
            else:
                s.q_des = q_ik
                self._ik_pose, self._ik_q = pose, q_ik
        else:
            s.q_des = list(self._hold)
        s.q_set = s.q_des
        for stage in self.joint_stages:
            stage.tick(s)
        q_set = s.q_set
        q: list[float] = q_set.tolist() if type(q_set) is np.ndarray else q_set  # type: ignore[assignment]
        lo, hi = self._lo, self._hi
        q1, q2, q3, q4 = q
        if (q1 < lo[0] or q1 > hi[0] or q2 < lo[1] or q2 > hi[1] or q3 < lo[2] or q3 > hi[2]
                or q4 < lo[3] or q4 > hi[3]):
            q = [min(max(v, lo[i]), hi[i]) for i, v in enumerate(q)]
            self.limit_clamps += 1
            s.q_set = q
        self._hold = q
        self.arm.set_setpoints(q, s.fr_sw)
        self.chart_ticks += 1
        if self.record is not None:
            r = self.record
            r.t.append(s.t)
            r.task.append(np.array(task, dtype=float))
            r.q_set.append(np.array(q))
            r.q_encoder.append(np.array(self.arm.encoder_angles()))
        return s

    def control_step(self) -> None:
        """One control step (charts first when this step is a chart step)."""
        self._start_clock()
        if self.steps % self.divider == 0:
            self.tick_charts()
        self.clock.wait_period(self.steps - self._period0)
        self.arm.step(1)
        self.steps += 1

    def run_for(self, seconds: float) -> None:
        """Run whole chart steps for `seconds` of simulated time."""
        self.run_until(lambda: False, seconds)

    def ticks_for(self, seconds: float) -> int:
        """The chart steps `run_until` runs for `seconds` of simulated time, at most."""
        return int(round(seconds * self.params.control.rate_hz / self.divider))

    def run_until(self, predicate: Callable[[], bool], timeout_s: float) -> bool:
        """Run chart steps until `predicate()` holds (checked after each); False on timeout."""
        self._start_clock()
        n_ticks = self.ticks_for(timeout_s)
        paced = self.clock.paced
        for _ in range(n_ticks):
            while self.steps % self.divider:
                self.control_step()
            self.tick_charts()
            if paced:
                for _ in range(self.divider):
                    self.clock.wait_period(self.steps - self._period0)
                    self.arm.step(1)
                    self.steps += 1
            else:
                self.arm.step(self.divider)
                self.steps += self.divider
            if predicate():
                return True
        return False

    def _start_clock(self) -> None:
        if not self._clock_started:
            self.clock.start()
            self._clock_started = True


def tool_path(params: ArmParams, q: np.ndarray) -> np.ndarray:
    """Tool poses [x, y, z, phi] by forward kinematics of joint angles, one row per row of `q`."""
    return np.array([fk(row, params.geometry) for row in np.atleast_2d(q)])
