"""The simulated arm: three DC drives with their cascade controllers and the pen servo.

:class:`ArmSim` is what the scheduler steps at the control rate.  It packs
the parameter file and the gains into the arrays of the numba kernel
(``_kernel.run_steps``) and reads sensors and true states back out.  The
physics (docs/model.md): per DC drive an armature circuit with back-EMF, a
motor with viscous and Coulomb friction, a gear with ratio, clearance and
stiffness, a load with inertia, viscous friction and gravity, hard stops,
a relative quadrature encoder on the motor shaft with an index switch; a
hobby servo with a slew-rate limit, a lag and gear play.

Drives are numbered 1, 2, 3 as in the thesis wherever a method takes a
drive number; arrays of three are indexed 0..2 (drive 1 first).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..arm.protocol import Sensors
from ..params import ArmParams
from . import _kernel as K
from .control import (
    Gains,
    check_drive,
    setpoint_filter_row,
    speed_filter_alpha,
)
from .truth import ArmTruth, flat_view

#: Plant sub-steps per control step.  At 1 kHz this is a 0.1 ms step: the
#: current is integrated exactly over it, the stiffest mechanical mode (the
#: load on the gear spring, about 100 Hz) gets ~100 steps per period; the
#: fine-step test (tests/twin/test_plant.py) checks 100x more changes little.
SUBSTEPS = 10

#: Standard deviation of the motor current measurement noise, A.
CURRENT_NOISE_A = 0.01

#: Gravity, m/s^2.
G = 9.81

#: Default power-on pose (rad): base straight ahead, upper arm and forearm
#: hanging near zero where friction holds them (the thesis: drive 2 starts
#: near zero), pen servo centred.  Held by friction with the drives unpowered.
REST_POSE = (0.0, 0.04, -0.08, 0.0)


#: Joint angles as a sequence or a numpy array.
Angles = Sequence[float] | np.ndarray


class SimError(ValueError):
    """An invalid request to the simulated arm (bad pose, bad setpoints)."""


@dataclass(frozen=True)
class Trace:
    """Time series of a run, one row per control step (taken at its end).

    Columns of the (n, 4) arrays are drives 1..3 and the servo; of the
    (n, 3) arrays drives 1..3.  For the servo, ``setpoint_filtered`` is the
    angle its PWM duty commands and ``duty`` its PWM duty (0..1).
    """

    t: np.ndarray  # (n,) s
    setpoint_raw: np.ndarray  # (n, 4) rad, encoder coordinates for drives 1-3
    setpoint_filtered: np.ndarray  # (n, 4) rad
    q_encoder: np.ndarray  # (n, 3) rad, what the controllers see
    q_true: np.ndarray  # (n, 4) rad, load side
    q_motor: np.ndarray  # (n, 3) rad, motor angle / gear ratio
    current_a: np.ndarray  # (n, 3) A, true armature current
    duty: np.ndarray  # (n, 4) PWM duty applied
    speed_ref: np.ndarray  # (n, 3) rad/s, outer loop output
    speed_meas: np.ndarray  # (n, 3) rad/s, filtered encoder derivative


def gravity_torques(params: ArmParams, q: Angles) -> np.ndarray:
    """Gravity torques on joints 1..3 (N m) at load angles `q` (q = 0 hangs down).

    Joint 2 carries link 2, link 3 and the tool; joint 3 carries link 3 and
    the tool (at the end of L3).  Joint 1 turns about the vertical: none.
    """
    g2, g23 = gravity_coefficients(params)
    s23 = math.sin(q[1] + q[2])
    return np.array([0.0, -g2 * math.sin(q[1]) - g23 * s23, -g23 * s23])


def gravity_coefficients(params: ArmParams) -> tuple[float, float]:
    """(g2, g23), N m: gravity torques are -g2 sin q2 - g23 sin(q2 + q3) on joint 2, -g23 sin(q2 + q3) on 3."""
    m, geo = params.masses, params.geometry
    g2 = G * (m.link2_kg * m.link2_com + (m.link3_kg + m.tool_kg) * geo.L2)
    g23 = G * (m.link3_kg * m.link3_com + m.tool_kg * geo.L3)
    return g2, g23


class ArmSim:
    """The simulated arm with its cascade controllers, stepped at the control rate.

    Parameters
    ----------
    params : ArmParams
        The parameter file.
    gains : Gains, optional
        Controller gains; None designs them (``tuning.design_gains(params)``).
    seed : int
        Seeds the current-measurement noise; everything else is deterministic.
    q0 : sequence of 4 floats, optional
        True joint angles at power-on (rad), default :data:`REST_POSE`.  The
        gears start engaged on the side gravity loads them.  Encoder counts
        are 0 at power-on, so the controllers' angles start at 0 (offset
        estimates 0) and the drives hold where they are.
    substeps : int
        Plant sub-steps per control step (see :data:`SUBSTEPS`).
    current_noise_a : float
        Standard deviation of the current measurement noise, A.
    """

    def __init__(self, params: ArmParams, gains: Gains | None = None, seed: int = 0,
                 q0: Angles | None = None, substeps: int = SUBSTEPS,
                 current_noise_a: float = CURRENT_NOISE_A) -> None:
        if gains is None:
            from .tuning import design_gains  # tuning imports this module

            gains = design_gains(params)
        if substeps < 1:
            raise SimError(f"substeps must be >= 1, got {substeps}")
        q_start = np.array(REST_POSE if q0 is None else q0, dtype=float)
        if q_start.shape != (4,) or not np.all(np.isfinite(q_start)):
            raise SimError(f"q0 must be 4 finite joint angles (rad), got {q0!r}")
        lo, hi = np.array(params.joint_min), np.array(params.joint_max)
        bad = np.flatnonzero((q_start < lo) | (q_start > hi))
        if bad.size:
            j = int(bad[0])
            raise SimError(f"q0[{j}] = {q_start[j]:.4f} rad lies outside joint {j + 1}'s limits "
                           f"[{lo[j]:.4f}, {hi[j]:.4f}]")
        self.params = params
        self.gains = gains
        self.seed = seed
        self.substeps = int(substeps)
        self.dt = params.control.dt
        self._slow_row = setpoint_filter_row(params.control.setpoint_cutoff_slow_hz, self.dt)
        self._dp = self._drive_rows(params, gains, self.dt / self.substeps)
        self._rpc = tuple(self._dp[:, K.P_RPC].tolist())
        self._gp = self._global_row(params, self.substeps, current_noise_a)
        self._ds = np.zeros((3, K.N_DS))
        self._di = np.zeros((3, K.N_DI), dtype=np.int64)
        self._gs = np.zeros(K.N_GS)
        self._no_rec = np.zeros((0, K.N_REC))
        # Flat views of the same memory for the per-chart-step accessors: a
        # memoryview reads and writes plain Python numbers at a third of the
        # cost of numpy indexing or slicing.
        self._dsv = flat_view(self._ds)
        self._div = flat_view(self._di)
        self._gsv = flat_view(self._gs)
        self._power_on(q_start, np.random.default_rng(seed))
        #: Ground truth (true angles, offsets, tool pose ...): simulation only, never read by
        #: code typed on :class:`~ttt_sm.arm.Arm` (docs/model.md, "Ground truth").
        self.truth = ArmTruth(params, self._dp, self._gp, self._ds, self._di, self._gs)
        # Load the compiled kernel now (from numba's disk cache: ~0.3 s the first time in a
        # process), not in the first control step: zero steps change nothing.
        K.run_steps(0, self._dp, self._gp, self._ds, self._di, self._gs, self._no_rec)

    # ---- construction -------------------------------------------------------

    @staticmethod
    def _drive_rows(params: ArmParams, gains: Gains, h: float) -> np.ndarray:
        dp = np.zeros((3, K.N_DP))
        alpha = speed_filter_alpha(params.control)
        for d, (p, g) in enumerate(zip(params.drives, gains.drives, strict=True)):
            row = dp[d]
            row[K.P_SUPPLY] = p.supply_v
            row[K.P_R] = p.resistance_ohm
            row[K.P_KT] = p.torque_constant
            row[K.P_JM] = p.rotor_inertia
            row[K.P_BM] = p.motor_viscous
            row[K.P_TC] = p.motor_coulomb
            row[K.P_N] = p.gear_ratio
            row[K.P_JL] = p.load_inertia
            row[K.P_BL] = p.load_viscous
            row[K.P_CLEAR] = p.gear_clearance
            row[K.P_K] = p.gear_stiffness
            row[K.P_CG] = p.gear_damping
            row[K.P_DTH_M] = 2.0 * math.pi / p.encoder_counts
            row[K.P_RPC] = p.rad_per_count
            row[K.P_QMIN] = p.limit_min_rad
            row[K.P_QMAX] = p.limit_max_rad
            row[K.P_QIDX] = p.index_rad
            x = h * p.resistance_ohm / p.inductance_h
            row[K.P_EL_DECAY] = math.exp(-x)
            row[K.P_EL_AVG] = -math.expm1(-x) / x
            row[K.P_KP_POS] = g.kp_pos
            row[K.P_KI_POS] = g.ki_pos
            row[K.P_KD_POS] = g.kd_pos
            row[K.P_KFF] = g.kff_speed
            row[K.P_WMAX] = g.max_speed_rad_s
            row[K.P_KP_SPD] = g.kp_speed
            row[K.P_KI_SPD] = g.ki_speed
            row[K.P_KD_SPD] = g.kd_speed
            row[K.P_ALPHA_W] = alpha
            row[K.P_INV_R] = 1.0 / p.resistance_ohm
            row[K.P_INV_N] = 1.0 / p.gear_ratio
            row[K.P_H_JM] = h / p.rotor_inertia
            row[K.P_FC_H] = h * p.motor_coulomb / p.rotor_inertia
            row[K.P_VISC_M] = 1.0 / (1.0 + h * p.motor_viscous / p.rotor_inertia)
            row[K.P_H_JL] = h / p.load_inertia
            row[K.P_VISC_L] = 1.0 / (1.0 + h * p.load_viscous / p.load_inertia)
            row[K.P_TH_IDX] = p.gear_ratio * p.index_rad
        return dp

    @staticmethod
    def _global_row(params: ArmParams, substeps: int, noise: float) -> np.ndarray:
        c, s = params.control, params.servo
        gp = np.zeros(K.N_GP)
        gp[K.G_DT] = c.dt
        gp[K.G_NSUB] = substeps
        gp[K.G_GRAV2], gp[K.G_GRAV23] = gravity_coefficients(params)
        gp[K.G_SF_NORMAL:K.G_SF_NORMAL + 6] = setpoint_filter_row(c.setpoint_cutoff_hz, c.dt)
        gp[K.G_SF_SLOW:K.G_SF_SLOW + 6] = setpoint_filter_row(c.setpoint_cutoff_slow_hz, c.dt)
        gp[K.G_SV_MIN] = s.min_rad
        gp[K.G_SV_MAX] = s.max_rad
        gp[K.G_SV_PMIN] = s.pulse_min_s
        gp[K.G_SV_PMAX] = s.pulse_max_s
        gp[K.G_SV_PERIOD] = s.period_s
        gp[K.G_SV_RATE] = s.rate_rad_s
        gp[K.G_SV_TAU] = s.time_constant_s
        gp[K.G_SV_CLEAR] = s.clearance_rad
        gp[K.G_I_NOISE] = noise
        gp[K.G_SV_INV_TAU] = 1.0 / s.time_constant_s
        return gp

    def _power_on(self, q0: np.ndarray, rng: np.random.Generator) -> None:
        ds, di, dp = self._ds, self._di, self._dp
        tau = gravity_torques(self.params, q0)
        for d, p in enumerate(self.params.drives):
            # the gear rests engaged on the side gravity pushes it, deflected by the load
            t = tau[d]
            delta = 0.0 if t == 0.0 else -math.copysign(p.gear_clearance / 2 + abs(t) / p.gear_stiffness, t)
            ds[d, K.S_Q] = q0[d]
            ds[d, K.S_TH] = p.gear_ratio * (q0[d] + delta)
            di[d, K.I_C0] = math.floor(ds[d, K.S_TH] / dp[d, K.P_DTH_M])
            di[d, K.I_INDEX] = int(ds[d, K.S_TH] > dp[d, K.P_TH_IDX])
            di[d, K.I_MODE] = K.MODE_CLOSED
            di[d, K.I_RNG] = int(rng.integers(0, K._LCG_MASK))
        self._gs[K.GS_SV_SET] = q0[3]
        self._gs[K.GS_SV_DUTY] = self.params.servo.duty_for_angle(q0[3])
        self._gs[K.GS_SV_CMD] = self.params.servo.angle_for_duty(self._gs[K.GS_SV_DUTY])
        self._gs[K.GS_SV_TH] = q0[3]
        self._gs[K.GS_SV_Q] = q0[3]

    # ---- stepping -----------------------------------------------------------

    @property
    def t(self) -> float:
        """Simulated time since power-on, s."""
        return self._gsv[K.GS_T]

    def set_setpoints(self, q_des: Angles, fr_sw: bool = False) -> None:
        """Set the joint setpoints: drives 1-3 in encoder coordinates (rad), q4 the servo angle.

        `fr_sw` selects the slow setpoint filters (thesis' slow moves).  The
        servo angle is turned into its PWM duty here, as the I/O card would.
        """
        if not (math.isfinite(q_des[0]) and math.isfinite(q_des[1]) and math.isfinite(q_des[2])
                and math.isfinite(q_des[3])):
            raise SimError(f"setpoints must be 4 finite angles (rad), got {list(q_des)!r}")
        ds, n = self._dsv, K.N_DS
        ds[K.S_R_RAW] = float(q_des[0])
        ds[n + K.S_R_RAW] = float(q_des[1])
        ds[2 * n + K.S_R_RAW] = float(q_des[2])
        gs = self._gsv
        gs[K.GS_FR_SW] = 1.0 if fr_sw else 0.0
        a = float(q_des[3])
        if a != gs[K.GS_SV_SET]:
            gs[K.GS_SV_SET] = a
            gs[K.GS_SV_DUTY] = self.params.servo.duty_for_angle(a)

    def step(self, n: int = 1) -> None:
        """Advance `n` control steps."""
        K.run_steps(n, self._dp, self._gp, self._ds, self._di, self._gs, self._no_rec)

    def run(self, n: int, record: bool = True) -> Trace:
        """Advance `n` control steps and return their time series (empty if not `record`)."""
        rec = np.zeros((n if record else 0, K.N_REC))
        K.run_steps(n, self._dp, self._gp, self._ds, self._di, self._gs, rec)
        return Trace(
            t=rec[:, K.REC_T], setpoint_raw=rec[:, K.REC_R_RAW:K.REC_R_RAW + 4],
            setpoint_filtered=rec[:, K.REC_R_F:K.REC_R_F + 4],
            q_encoder=rec[:, K.REC_Q_ENC:K.REC_Q_ENC + 3], q_true=rec[:, K.REC_Q_TRUE:K.REC_Q_TRUE + 4],
            q_motor=rec[:, K.REC_Q_MOTOR:K.REC_Q_MOTOR + 3],
            current_a=rec[:, K.REC_CURRENT:K.REC_CURRENT + 3], duty=rec[:, K.REC_DUTY:K.REC_DUTY + 4],
            speed_ref=rec[:, K.REC_W_REF:K.REC_W_REF + 3], speed_meas=rec[:, K.REC_W_MEAS:K.REC_W_MEAS + 3],
        )

    def run_for(self, seconds: float, record: bool = True) -> Trace:
        """:meth:`run` for a duration, rounded to whole control steps."""
        return self.run(int(round(seconds / self.dt)), record)

    # ---- sensors (the Arm protocol) -----------------------------------------

    def sensors(self) -> Sensors:
        """The readings of the encoders, index switches and current sensors now."""
        a, b, c = self._di.tolist()
        i1, i2, i3 = self._ds[:, K.S_I_MEAS].tolist()
        cn, ix, ic, ie = K.I_COUNTS, K.I_INDEX, K.I_INDEX_COUNT, K.I_INDEX_EDGES
        return Sensors(counts=(a[cn], b[cn], c[cn]), index=(a[ix] == 1, b[ix] == 1, c[ix] == 1),
                       index_count=(a[ic], b[ic], c[ic]), index_edges=(a[ie], b[ie], c[ie]),
                       current_a=(i1, i2, i3), t=float(self._gs[K.GS_T]))

    def encoder_angles(self) -> tuple[float, float, float]:
        """What the controllers see: counts * rad_per_count + offset estimate (rad), as plain floats."""
        di, ni, ds, n = self._div, K.N_DI, self._dsv, K.N_DS
        r1, r2, r3 = self._rpc
        return (di[K.I_COUNTS] * r1 + ds[K.S_OFFSET], di[ni + K.I_COUNTS] * r2 + ds[n + K.S_OFFSET],
                di[2 * ni + K.I_COUNTS] * r3 + ds[2 * n + K.S_OFFSET])

    def offset_estimates(self) -> tuple[float, float, float]:
        """The controllers' encoder offsets (rad), 0 until a drive is initialised."""
        ds, n = self._dsv, K.N_DS
        return ds[K.S_OFFSET], ds[n + K.S_OFFSET], ds[2 * n + K.S_OFFSET]

    @property
    def servo_setpoint(self) -> float:
        """The servo angle last commanded (rad); at power-on, where the servo stands."""
        return self._gsv[K.GS_SV_SET]

    def enabled(self) -> tuple[bool, bool, bool]:
        """True per drive while its cascade controller runs."""
        di, ni, on = self._div, K.N_DI, K.MODE_CLOSED
        return di[K.I_MODE] == on, di[ni + K.I_MODE] == on, di[2 * ni + K.I_MODE] == on

    @property
    def q_encoder(self) -> np.ndarray:
        """:meth:`encoder_angles` as an array (rad)."""
        return np.array(self.encoder_angles())

    @property
    def offset_estimate(self) -> np.ndarray:
        """:meth:`offset_estimates` as an array (rad), a copy."""
        return self._ds[:, K.S_OFFSET].copy()

    @property
    def duty(self) -> np.ndarray:
        """PWM duties the controllers apply to the three H-bridges now (-1..1)."""
        return self._ds[:, K.S_DUTY].copy()

    # ---- controller management ------------------------------------------------

    def set_offset_estimate(self, drive: int, offset_rad: float) -> None:
        """Set a drive's encoder offset (rad) as the init charts estimate it.

        The drive's setpoints and speed-estimate state move with its angle, so
        the arm does not jump: the physical target stays where it was.
        """
        d = check_drive(drive) - 1
        ds = self._ds
        shift = float(offset_rad) - ds[d, K.S_OFFSET]
        ds[d, K.S_OFFSET] = float(offset_rad)
        for k in (K.S_R_RAW, K.S_R_F, K.S_Q_PREV):
            ds[d, k] += shift

    def assume_initialised(self) -> None:
        """Give every drive its true offset: simulation only, a stand-in for the init charts.

        A real arm learns its offsets from the init charts; tests and the
        bench that start from an initialised arm use this instead.
        """
        for d, off in enumerate(self.truth.offsets):
            self.set_offset_estimate(d + 1, float(off))

    def set_enabled(self, drive: int, enabled: bool) -> None:
        """Switch a drive's controller on (holding where the drive is) or off (PWM 0)."""
        d = check_drive(drive) - 1
        was = self._di[d, K.I_MODE]
        if enabled:
            if was != K.MODE_CLOSED:
                self._hold(d)
                self._di[d, K.I_MODE] = K.MODE_CLOSED
        else:
            self._di[d, K.I_MODE] = K.MODE_OFF

    def set_duty(self, drive: int, duty: float) -> None:
        """Drive open loop with a fixed PWM duty (clipped to -1..1) until set_enabled."""
        d = check_drive(drive) - 1
        self._ds[d, K.S_OPEN_DUTY] = float(duty)
        self._di[d, K.I_MODE] = K.MODE_OPEN

    def settle_unpowered(self, seconds: float) -> None:
        """Let gravity and friction act with PWM 0 for `seconds`, then restore the modes.

        Drives that were under control hold where they came to rest.
        """
        modes = self._di[:, K.I_MODE].copy()
        self._di[:, K.I_MODE] = K.MODE_OFF
        self.step(int(round(seconds / self.dt)))
        for d in range(3):
            if modes[d] == K.MODE_CLOSED:
                self._hold(d)
            self._di[d, K.I_MODE] = modes[d]

    def _hold(self, d: int) -> None:
        """Make drive d's controller hold its current encoder angle, bumplessly."""
        ds = self._ds
        q = float(self.q_encoder[d])
        ds[d, K.S_R_RAW] = q
        ds[d, K.S_R_F] = q
        ds[d, K.S_R_FD] = 0.0
        ds[d, K.S_Q_PREV] = q
        ds[d, K.S_W_MEAS] = 0.0
        ds[d, K.S_INT_POS] = 0.0
        ds[d, K.S_INT_SPD] = 0.0

    def max_speed(self) -> np.ndarray:
        """Speed setpoint clamps of drives 1..3 (rad/s)."""
        return self._dp[:, K.P_WMAX].copy()


__all__ = ["ArmSim", "Sensors", "Trace", "SimError", "REST_POSE", "SUBSTEPS", "CURRENT_NOISE_A",
           "gravity_coefficients", "gravity_torques"]
