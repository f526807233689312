"""Wiring of the Safety chart (docs/safety.md) into the scheduler.

:class:`SafetyStage` is a joint stage, run after the drive-initialisation
charts and the gear-play compensation have set this chart step's setpoints.
It plays the ``Monitor`` block of the wiring table: from what the arm
reports (encoder counts and angles, currents, the offsets the init charts
set) and what the PC commanded, it computes each drive's following error
against a model of the controller's setpoint filter (the same filter,
``twin.control.setpoint_filter_row``, stepped with the same setpoints,
followed no faster than the controller's speed clamp
``twin.control.max_joint_speed``), the encoder speed from the counts, the
commanded speed (the model's) and the current.  It
feeds the Safety chart, ticks it, and carries out what the chart outputs:

- ``SafeState.hold``: the setpoints become the pose the arm had when the
  chart tripped (encoder angles and the servo's last setpoint), or, while
  the chart lifts the pen, a ramp at ``[safety] lift_speed_m_s`` to that
  pose solved by inverse kinematics at the tool height ``lift_z`` (a step
  of the setpoints would ask the drives for a current beyond the limit);
- ``SafeState.bridge_off``: that drive's bridge is switched off (``Arm.set_enabled``);
- ``SafeState.reinit`` rising: the robot restarts its drive-initialisation charts
  (:meth:`~ttt_sm.app.robot.Robot.reinitialise`) and switches the drives on again.

It reads only what a real arm reports (:class:`~ttt_sm.arm.Arm`).  Each trip
and reset is told to the robot's safety listeners (a game writes them into
its record).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ..arm import Arm
from ..charts.safety import Safety
from ..params import ArmParams
from ..sched.scheduler import Scheduler, Signals
from ..twin.control import max_joint_speed, setpoint_filter_row
from ..twin.kinematics import IKError, arm_chain_py
from .wiring import Wiring, not_wired


#: A drive counts as at its speed clamp this long after the model left it, s: the lag its
#: acceleration left behind decays with the position loop (outer crossover 6 Hz: about 30 ms).
FAST_HOLD_S = 0.1


def make_safety_chart(params: ArmParams, listeners: Sequence[object] = ()) -> Safety:
    """The Safety chart with the thresholds of ``[safety]`` and the joint limits of `params`."""
    s = params.safety
    data: dict[str, Any] = {
        "max_following_error": s.max_following_error_rad, "max_following_error_init": s.max_following_error_init_rad,
        "max_following_error_fast": s.max_following_error_fast_rad,
        "max_current": s.max_current_a, "max_current_init": s.max_current_init_a, "max_speed": s.max_speed_rad_s,
        "moving_speed": s.moving_speed_rad_s, "silent_s": s.silent_s, "limit_margin": s.limit_margin_rad,
        "lift_height": s.lift_height_m,
    }
    for k, d in enumerate(params.drives, start=1):
        data[f"q_min_{k}"] = d.limit_min_rad
        data[f"q_max_{k}"] = d.limit_max_rad
    return Safety(tick_period_s=params.control.chart_dt, listeners=list(listeners), data=data)


class CameraStatus:
    """The ``Camera`` block: whether the camera answers.  True while a robot has no camera.

    A game sets :attr:`ok` from its camera link; a fault test clears it.
    """

    def __init__(self) -> None:
        self.ok = True


class SafetyStage:
    """Joint stage: the Monitor block, the Safety chart, and the safe state it asks for.

    Parameters
    ----------
    params : ArmParams
        The arm (control rate, setpoint filters, encoder resolutions, geometry).
    arm : Arm
        What the monitor reads and the safe state commands.
    sched : Scheduler
        Its inverse kinematics solves the lift.
    chart : Safety
        The chart.
    reinitialise : callable
        Restarts the drive-initialisation charts (the robot's).
    camera : CameraStatus
        The ``Camera`` block.
    """

    def __init__(self, params: ArmParams, arm: Arm, sched: Scheduler, chart: Safety,
                 reinitialise: Callable[[], None], camera: CameraStatus) -> None:
        self.arm = arm
        self.sched = sched
        self.chart = chart
        self.camera = camera
        self._reinitialise = reinitialise
        c = params.control
        self._chart_dt = c.chart_dt
        self._steps = c.chart_divider
        self._rows = {False: tuple(setpoint_filter_row(c.setpoint_cutoff_hz, c.dt).tolist()),
                      True: tuple(setpoint_filter_row(c.setpoint_cutoff_slow_hz, c.dt).tolist())}
        self._rpc = tuple(float(d.rad_per_count) for d in params.drives)
        g = params.geometry
        self._geometry = (g.L1, g.L2, g.L3, g.L4, g.l_f)
        self._tool = (0.0, 0.0, 0.0)
        # the model of the controller's setpoint filters: angle and rate per drive (encoder coordinates),
        # and where the drive can be: the filter's angle followed no faster than the speed clamp
        self._r = list(arm.encoder_angles())
        self._v = [0.0, 0.0, 0.0]
        self._p = list(self._r)
        self._dp = [0.0, 0.0, 0.0]
        self._step_max = [max_joint_speed(d) * c.chart_dt for d in params.drives]
        self._fast = [0, 0, 0]  # chart steps the drive still counts as at its speed clamp
        self._fast_steps = max(1, round(FAST_HOLD_S / c.chart_dt))
        self._offsets = list(arm.offset_estimates())
        self._counts = list(arm.sensors().counts)
        self._pose: list[float] | None = None  # what the drives hold while the chart trips
        self._lift_for = math.nan  # the lift_z the pose was solved for
        self._lift_from: list[float] = []
        self._lift_to: list[float] | None = None  # the lift's end while the ramp runs
        self._lift_steps = 0
        s = params.safety
        self._lift_s = max(s.lift_height_m / s.lift_speed_m_s, c.chart_dt)  # how long the lift's ramp takes
        self._tripped = False
        self._reinit = False
        #: Called with (kind, data) on every trip ("safety_trip") and reset ("safety_reset").
        self.listeners: list[Callable[[str, dict[str, Any]], object]] = []
        # the Monitor block's outputs, one per drive, as this chart step computed them
        self.err: list[float] = [0.0, 0.0, 0.0]
        #: Inputs forced by a test or scenario (``Robot.set_input(..., force=True)``): name -> value.
        self.overrides: dict[str, object] = {}
        self._feed: Callable[..., None] = not_wired
        self._outputs: Callable[[], Any] = not_wired

    @property
    def link_ok(self) -> bool:
        """The ``Link`` block: the arm's own report of its link, where it has one (else True)."""
        return bool(getattr(self.arm, "link_ok", True))

    def blocks(self) -> dict[str, object]:
        """The objects holding the outputs of this stage's blocks (Link, Camera); Monitor and FK are arguments."""
        return {"Link": self, "Camera": self.camera}

    def wire(self, wiring: Wiring) -> None:
        """Compile this stage's part of the wiring table."""
        self._feed = wiring.feed([self.chart.chart_name], args=("Monitor", "FK"))
        self._outputs = wiring.collect("SafeState.tripped", "SafeState.hold", "SafeState.lift_z", "SafeState.bridge_off",
                                       "SafeState.reinit")

    def tick(self, signals: Signals) -> None:
        """Monitor in, chart ticked, the safe state out."""
        arm = self.arm
        sensors = signals.sensors
        assert sensors is not None
        enc = arm.encoder_angles()
        offsets = arm.offset_estimates()
        r, p, rpc, dt = self._r, self._p, self._rpc, self._chart_dt
        counts = sensors.counts
        err, speed, cmd, current = [0.0] * 3, [0.0] * 3, [0.0] * 3, [0.0] * 3
        for i in range(3):
            if offsets[i] != self._offsets[i]:  # the init chart moved the encoder coordinates: so do the setpoints
                r[i] += offsets[i] - self._offsets[i]
                p[i] += offsets[i] - self._offsets[i]
                self._offsets[i] = offsets[i]
            err[i] = p[i] - enc[i]
            speed[i] = abs(counts[i] - self._counts[i]) * rpc[i] / dt
            cmd[i] = self._dp[i] / dt
            current[i] = abs(sensors.current_a[i])
        self._counts = list(counts)
        self.err = err
        servo = arm.servo_setpoint
        x, y, z, phi, _, _, _, _ = arm_chain_py(enc[0], enc[1], enc[2], servo, *self._geometry)
        fast = [self._fast[0] > 0, self._fast[1] > 0, self._fast[2] > 0]
        self._feed(err, speed, cmd, current, list(enc), fast, x, y, z)
        if self.overrides:
            vars(self.chart).update(self.overrides)
        self.chart.tick()
        tripped, hold, lift_z, off, reinit = self._outputs()
        if tripped and not self._tripped:
            self._tell("safety_trip", reason=self.chart.reason, drive=self.chart.fault_drive)
        self._tripped = bool(tripped)
        if reinit and not self._reinit:
            self._restart()
            # this step's setpoints were made in the old coordinates: hold where the drives stand instead
            signals.q_set = [*arm.encoder_angles(), servo]
        self._reinit = bool(reinit)
        if hold:
            if self._pose is None:
                self._pose = [*enc, servo]
                self._tool = (x, y, phi)
            if lift_z == lift_z and lift_z != self._lift_for:  # a lift to solve (not NaN, not solved yet)
                self._lift_for = lift_z
                self._lift_from = list(self._pose)
                self._lift_to = self._lift_pose(lift_z)
                self._lift_steps = 0
            if self._lift_to is not None:  # a ramp in joint space: the move a step would make is too hard
                self._lift_steps += 1
                f = min(1.0, self._lift_steps * self._chart_dt / self._lift_s)
                self._pose = [a + f * (b - a) for a, b in zip(self._lift_from, self._lift_to, strict=True)]
                if f >= 1.0:
                    self._lift_to = None
            enabled = arm.enabled()
            for k in range(3):
                if off[k] and enabled[k]:
                    arm.set_enabled(k + 1, False)
            signals.q_set = list(self._pose)
        else:
            self._pose = None
            self._lift_for = math.nan
            self._lift_to = None
        self._advance_model(signals.q_set, bool(signals.fr_sw))

    def _lift_pose(self, lift_z: float) -> list[float]:
        """Joint setpoints with the tool where it was at the trip, at height `lift_z`; the held pose if out of reach."""
        assert self._pose is not None
        x, y, phi = self._tool
        try:
            q, _ = self.sched.ik.solve_pose(x, y, lift_z, phi)
        except IKError:
            return self._pose
        # IK answers joint angles; the drives take encoder coordinates (offsets applied: the same once initialised)
        return [float(q[0]), float(q[1]), float(q[2]), float(q[3])]

    def _advance_model(self, q_set: Sequence[float] | np.ndarray, fr_sw: bool) -> None:
        """Step the setpoint-filter model as the controller will, over the control steps of this chart step."""
        a11, a12, b1, a21, a22, b2 = self._rows[fr_sw]
        r, v, p, dp = self._r, self._v, self._p, self._dp
        for i in range(3):
            u, ri, vi = float(q_set[i]), r[i], v[i]
            for _ in range(self._steps):
                ri, vi = a11 * ri + a12 * vi + b1 * u, a21 * ri + a22 * vi + b2 * u
            r[i], v[i] = ri, vi
            step = self._step_max[i]
            dp[i] = max(-step, min(step, ri - p[i]))
            p[i] += dp[i]
            # at the clamp, and for a while after, the drive lags its acceleration behind the model
            self._fast[i] = self._fast_steps if abs(dp[i]) >= step else max(0, self._fast[i] - 1)

    def _restart(self) -> None:
        """The chart asked to re-initialise: the init charts start again, every drive switched on holding."""
        self._reinitialise()
        arm, r, v = self.arm, self._r, self._v
        offsets = arm.offset_estimates()
        for i in range(3):  # the offsets changed: the setpoints moved with them
            r[i] += offsets[i] - self._offsets[i]
            self._p[i] += offsets[i] - self._offsets[i]
        self._offsets = list(offsets)
        enc = arm.encoder_angles()
        for i, on in enumerate(arm.enabled()):
            if not on:  # switched on, a drive holds where it stands, its filter reset there
                arm.set_enabled(i + 1, True)
                r[i], v[i], self._p[i], self._dp[i] = enc[i], 0.0, enc[i], 0.0
        self._tell("safety_reset")

    def _tell(self, kind: str, **data: Any) -> None:
        for listener in self.listeners:
            listener(kind, data)
