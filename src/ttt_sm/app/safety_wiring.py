"""Wiring of the Safety chart (docs/safety.md) into the scheduler.

:class:`SafetyStage` is a joint stage, run after the drive-initialisation
charts and the gear-play compensation have set this chart step's setpoints.
It plays the ``Monitor`` block of the wiring table: from what the arm
reports (encoder counts and angles, currents, the offsets the init charts
set) and what the PC commanded, it computes each drive's following error
against a model of the controller's setpoint filter (the same filter,
``twin.gains.setpoint_filter_row``, stepped with the same setpoints,
followed no faster than the controller's speed clamp
``twin.gains.max_joint_speed``), the encoder speed from the counts, the
commanded speed (the model's) and the current; and the pen servo's error:
a model of the servo (its lag and slew rate, ``[servo]``) stepped with the
servo's setpoints, minus the angle its feedback wire reads.  It
feeds the Safety chart, ticks it, and carries out what the chart outputs:

- ``SafeState.hold``: the setpoints become the pose the arm had when the
  chart tripped (encoder angles and the servo's last setpoint), or, while
  the chart lifts the pen, a ramp at ``[safety] lift_speed_m_s`` to that
  pose solved by inverse kinematics at the tool height ``lift_z`` (a step
  of the setpoints would ask the drives for a current beyond the limit):
  the drives lift the tool, which a stuck pen servo cannot;
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
from ..twin.gains import max_joint_speed, setpoint_filter_row
from ..twin.kinematics import IKError
from . import _monitor
from . import _monitor_layout as ML
from .wiring import Wiring, WiringError, not_wired


def _chart_step_row(row: np.ndarray, steps: int) -> tuple[float, ...]:
    """A setpoint filter's row (``a11 a12 b1 a21 a22 b2``, one control step) over `steps` control steps.

    The setpoint is held over a chart step, so the filter over it is
    ``x <- A^n x + (A^(n-1) + ... + I) B u``: one update per chart step.
    """
    a = np.array([[row[0], row[1]], [row[3], row[4]]])
    b = np.array([row[2], row[5]])
    an, bn = np.eye(2), np.zeros(2)
    for _ in range(steps):
        an, bn = a @ an, a @ bn + b
    return float(an[0, 0]), float(an[0, 1]), float(bn[0]), float(an[1, 0]), float(an[1, 1]), float(bn[1])


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
        "moving_speed": s.moving_speed_rad_s, "stall_ratio": s.stall_ratio, "silent_s": s.silent_s,
        "limit_margin": s.limit_margin_rad,
        "lift_height": s.lift_height_m,
        "max_servo_error": s.max_servo_error_rad, "servo_error_s": s.servo_error_s,
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
        # the Monitor block's state, one buffer for its compiled functions (app/_monitor.py): the model
        # of the controller's setpoint filters (angle and rate per drive, in encoder coordinates), and
        # where the drive can be (the filter's angle followed no faster than the speed clamp)
        self._m = m = np.zeros(ML.N_M)
        # the same memory, read and written as plain numbers (numpy's stubs lack __buffer__)
        self._mv: Any = memoryview(m)  # type: ignore[arg-type]
        m[ML.M_ROW:ML.M_ROW + 6] = _chart_step_row(setpoint_filter_row(c.setpoint_cutoff_hz, c.dt),
                                                               c.chart_divider)
        m[ML.M_ROW_SLOW:ML.M_ROW_SLOW + 6] = _chart_step_row(
            setpoint_filter_row(c.setpoint_cutoff_slow_hz, c.dt), c.chart_divider)
        rpc = [float(d.rad_per_count) for d in params.drives]
        g = params.geometry
        m[ML.M_RPC:ML.M_RPC + 3] = rpc
        m[ML.M_SPEED_PER_COUNT:ML.M_SPEED_PER_COUNT + 3] = [r / c.chart_dt for r in rpc]
        m[ML.M_STEP_MAX:ML.M_STEP_MAX + 3] = [max_joint_speed(d) * c.chart_dt for d in params.drives]
        m[ML.M_GEOMETRY:ML.M_GEOMETRY + 5] = [g.L1, g.L2, g.L3, g.L4, g.l_f]
        m[ML.M_FAST_STEPS] = max(1, round(FAST_HOLD_S / c.chart_dt))
        m[ML.M_CHART_DT] = c.chart_dt
        m[ML.M_TICK_S] = chart.tick_period_s
        enc = arm.encoder_angles()
        m[ML.M_R:ML.M_R + 3] = enc
        m[ML.M_P:ML.M_P + 3] = enc
        m[ML.M_OFFSET:ML.M_OFFSET + 3] = arm.offset_estimates()
        sensors = arm.sensors()
        # where _monitor.step reads the arm: the simulated arm's own memory, or copies of the protocol's readings
        inplace = getattr(arm, "readings_in_place", None)
        if inplace is not None:
            src = inplace()
            self._src = (src.plant_floats, src.plant_ints, src.controller_floats)
            self._src_ix = [*src.counts, *src.currents, src.servo_counts, *src.offsets, src.servo_setpoint]
            m[ML.M_FB_CAL:ML.M_FB_CAL + 3] = src.servo_calibration
            self._copied: tuple[Any, Any, Any] | None = None
        else:
            self._src = (np.zeros(4), np.zeros(3, dtype=np.int64), np.zeros(4))
            self._src_ix = [0, 1, 2, 0, 1, 2, 3, 0, 1, 2, 3]  # counts, currents, servo_q; offsets, setpoint
            m[ML.M_FB_CAL:ML.M_FB_CAL + 3] = (0.0, 0.0, 1.0)  # the reading is in rad already
            self._copied = tuple(memoryview(a) for a in self._src)  # type: ignore[arg-type,assignment]
        m[ML.M_COUNTS:ML.M_COUNTS + 3] = sensors.counts
        m[ML.M_SV] = sensors.servo_rad
        m[ML.M_SV_RATE] = params.servo.rate_rad_s
        m[ML.M_SV_INV_TAU] = 1.0 / params.servo.time_constant_s
        self._tool = (0.0, 0.0, 0.0)
        self._pose: list[float] | None = None  # what the drives hold while the chart trips
        self._lift_for = math.nan  # the lift_z the pose was solved for
        self._lift_from: list[float] = []
        self._lift_to: list[float] | None = None  # the lift's end while the ramp runs
        self._lift_steps = 0
        s = params.safety
        self._lift_s = max(s.lift_height_m / s.lift_speed_m_s, c.chart_dt)  # how long the lift's ramp takes
        self._tripped = False
        self._reinit = False
        self._busy = False  # a trip, a hold, a reset or the end of one to carry out: the chart ticks itself
        #: Called with (kind, data) on every trip ("safety_trip") and reset ("safety_reset").
        self.listeners: list[Callable[[str, dict[str, Any]], object]] = []
        # the Safety chart's numbers, in place (the chart is buffered), and where _monitor.step finds them
        self._b = np.frombuffer(chart.data_buffer(), dtype=np.float64)
        self._ix = np.full(ML.IX_PREV + 1, -1, dtype=np.int64)
        self._chart_d = vars(chart)
        # the configuration _monitor.step ticks (a state reference, not its name: a rename fails here)
        self._watching = Safety.monitoring.value
        #: The chart's quiet tick in ``monitoring`` computed with the Monitor block (``_monitor.step``);
        #: False ticks the chart itself every chart step (the same behaviour: tests compare the two).
        self.compiled_tick = True
        #: The ``Link`` block: the arm's own report of its link, where it has one (else True), read every tick
        #: (``link_ok``, the :class:`~ttt_sm.arm.Arm` protocol's optional surface).
        self.link_ok = True
        #: Inputs forced by a test or scenario (``Robot.set_input(..., force=True)``): name -> value.
        self.overrides: dict[str, object] = {}
        self._flags: Callable[[], tuple[bool, bool, bool, bool]] = not_wired  # type: ignore[assignment]
        self._outputs: Callable[[], Any] = not_wired
        self._quiet: Callable[[], tuple[bool, bool, bool]] = not_wired  # type: ignore[assignment]
        # read every chart step: bound once (an arm without a link has no link_ok: its link is always up)
        self._offset_estimates = arm.offset_estimates
        self._has_link = hasattr(arm, "link_ok")

    def commanded_speed(self) -> list[float]:
        """Each drive's commanded speed, rad/s: the rate of the model of its setpoint filter."""
        mv, dt = self._mv, self._chart_dt
        return [mv[ML.M_DP + i] / dt for i in range(3)]

    @property
    def _out(self) -> tuple[float, ...]:
        """The Monitor block's outputs as this chart step computed them (app/_monitor.py: OUT_*)."""
        return tuple(self._mv[ML.M_OUT:ML.M_OUT + ML.N_OUT])

    @property
    def err(self) -> list[float]:
        """The Monitor block's following errors, as this chart step computed them, rad."""
        return list(self._out[ML.OUT_ERR:ML.OUT_ERR + 3])

    def blocks(self) -> dict[str, object]:
        """The objects holding the outputs of this stage's blocks (Link, Camera); Monitor and FK are arguments."""
        return {"Link": self, "Camera": self.camera}

    def wire(self, wiring: Wiring) -> None:
        """Compile this stage's part of the wiring table."""
        ports = tuple(f"{b}.{p.name}" for b in ("Monitor", "FK") for p in wiring.blocks[b].outputs)
        if ports != _monitor.PORTS:
            raise WiringError(f"the Monitor and FK blocks declare {', '.join(ports)}; the compiled monitor"
                              f" (app/_monitor.py) returns {', '.join(_monitor.PORTS)}")
        # where the Monitor block's outputs, then the FK block's (OUT_*), go in the chart's buffer, and what
        # the wiring table sends to the chart's flags: _monitor.step writes them all, every chart step
        name, slots = self.chart.chart_name, self.chart.data_slots()
        ix = self._ix
        for element, datum in wiring.routes(name, ("Monitor", "FK")):
            ix[element] = slots[datum]
        ix[ML.IX_FLAGS:ML.IX_NAMES] = [slots[f] for f in ML.FLAGS]
        self._flags = wiring.collect(*(f"{name}.{f}" for f in ML.FLAGS))
        flag_sources = {row.source.block for row in wiring.rows
                        if row.target.block == name and row.target.port in ML.FLAGS}
        others = wiring.sources(name) - {"Monitor", "FK"} - flag_sources
        if others:
            raise WiringError(f"the Safety stage writes the {name} chart's inputs from the Monitor and FK blocks and"
                              f" its flags ({', '.join(ML.FLAGS)}); the wiring table also feeds it from"
                              f" {', '.join(sorted(others))}")
        ix[ML.IX_NAMES:ML.IX_SRC] = [slots[n] for n in ML.NAMES]
        ix[ML.IX_SRC:ML.IX_PREV] = self._src_ix
        pairs = type(self.chart)._slot_prev_pairs
        self._ix = ix = np.concatenate([ix, [v for pair in pairs for v in pair]]).astype(np.int64)
        ix[ML.IX_PREV] = len(pairs)
        self._dict_prev = type(self.chart)._dict_prev_pairs
        self._outputs = wiring.collect("SafeState.tripped", "SafeState.hold", "SafeState.lift_z",
                                       "SafeState.bridge_off", "SafeState.reinit")
        # whether there is anything to carry out: the three outputs that say so (every chart step)
        self._quiet = wiring.collect("SafeState.tripped", "SafeState.hold", "SafeState.reinit")

    def tick(self, signals: Signals) -> None:
        """Monitor in, chart ticked, the safe state out: while the chart watches and nothing trips it,
        one compiled call (``_monitor.step``) does the Monitor block and the chart's tick."""
        arm = self.arm
        if self._has_link:
            self.link_ok = bool(arm.link_ok)  # type: ignore[attr-defined]
        if self._copied is not None:  # an arm with no memory to read in place: its readings, copied
            sensors = signals.sensors
            assert sensors is not None
            f, i, c = self._copied
            i[0], i[1], i[2] = sensors.counts
            f[0], f[1], f[2] = sensors.current_a
            f[3] = sensors.servo_rad
            c[0], c[1], c[2] = self._offset_estimates()
            c[3] = arm.servo_setpoint
        ini, failed, link, camera = self._flags()
        d = self._chart_d
        q = signals.q_set
        # the chart's own tick is needed for an event, a forced input, a state but monitoring, or the end of a trip
        quiet = (self.compiled_tick and not d["_queue"] and not self.overrides and not self._busy
                 and getattr(d["model"], d["state_field"]) == self._watching)
        fsrc, isrc, csrc = self._src
        k = _monitor.step(self._m, self._b, self._ix, fsrc, isrc, csrc, ini, failed, link, camera, quiet,
                          float(q[0]), float(q[1]), float(q[2]), bool(signals.fr_sw), float(q[3]))
        if k == -1:  # the chart's quiet tick, done: count it, and copy what is not in the buffer
            d["_ticks"] += 1
            for out, prev in self._dict_prev:
                d[prev] = d[out]
            return
        if self.overrides:
            self.chart.data_mapping().update(self.overrides)
        self.chart.tick()
        servo = arm.servo_setpoint
        tripped, hold, reinit = self._quiet()
        self._busy = bool(tripped or hold or reinit or self._tripped or self._reinit or self._pose is not None)
        if self._busy:
            # a trip, a hold, a reset, or the end of one
            q_safe = self._carry_out(servo)
            if q_safe is not None:
                signals.q_set = q_safe
        q = signals.q_set
        _monitor.advance(self._m, float(q[0]), float(q[1]), float(q[2]), bool(signals.fr_sw), float(q[3]))

    def _carry_out(self, servo: float) -> list[float] | None:
        """What the chart's outputs ask for this chart step: tell a trip, restart, hold or lift the pose.

        Returns the setpoints to send instead of this chart step's, or None.
        """
        arm, out = self.arm, self._out
        q_safe: list[float] | None = None
        tripped, hold, lift_z, off, reinit = self._outputs()
        if tripped and not self._tripped:
            self._tell("safety_trip", reason=self.chart.reason, drive=self.chart.fault_drive, **self._link_detail())
        self._tripped = bool(tripped)
        if reinit and not self._reinit:
            self._restart()
            # this step's setpoints were made in the old coordinates: hold where the drives stand instead
            q_safe = [*arm.encoder_angles(), servo]
        self._reinit = bool(reinit)
        if hold:
            if self._pose is None:
                self._pose = [out[12], out[13], out[14], servo]
                self._tool = (out[ML.OUT_TOOL], out[ML.OUT_TOOL + 1], out[ML.OUT_TOOL + 3])
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
            q_safe = list(self._pose)
        else:
            self._pose = None
            self._lift_for = math.nan
            self._lift_to = None
        return q_safe

    def _link_detail(self) -> dict[str, str]:
        """A lost link's own words (the arm backend's ``link_fault``), for the trip's record."""
        fault = None if self.link_ok else getattr(self.arm, "link_fault", None)
        return {} if fault is None else {"link": str(fault)}

    def _shift(self, offsets: tuple[float, float, float]) -> None:
        """The encoder offsets changed to `offsets`: the model's angles move with them."""
        mv = self._mv
        for i in range(3):
            delta = offsets[i] - mv[ML.M_OFFSET + i]
            mv[ML.M_R + i] += delta
            mv[ML.M_P + i] += delta
            mv[ML.M_OFFSET + i] = offsets[i]

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

    def _restart(self) -> None:
        """The chart asked to re-initialise: the init charts start again, every drive switched on holding."""
        self._reinitialise()
        arm, mv = self.arm, self._mv
        self._shift(arm.offset_estimates())  # they changed: the setpoints moved with them
        mv[ML.M_SV] = arm.sensors().servo_rad  # the servo's model starts again where the servo stands
        enc = arm.encoder_angles()
        for i, on in enumerate(arm.enabled()):
            if not on:  # switched on, a drive holds where it stands, its filter reset there
                arm.set_enabled(i + 1, True)
                mv[ML.M_R + i], mv[ML.M_V + i] = enc[i], 0.0
                mv[ML.M_P + i], mv[ML.M_DP + i] = enc[i], 0.0
        self._tell("safety_reset")

    def _tell(self, kind: str, **data: Any) -> None:
        for listener in self.listeners:
            listener(kind, data)
