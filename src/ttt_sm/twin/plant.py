"""The arm's physics: three DC drives, their gears and loads, the pen servo, the sensors.

:class:`Plant` is the physical arm of the simulation.  It packs the
parameter file into the memory of the compiled plant step
(``_plant.plant_step``), powers the arm on at a pose, and reads the sensors
back: per DC drive an armature circuit with back-EMF, a motor with viscous
and Coulomb friction, a gear with ratio, clearance and stiffness, a load
with inertia, viscous friction and gravity, hard stops, a relative
quadrature encoder on the motor shaft with an index switch; a hobby servo
with a slew-rate limit, a lag and gear play, and the wiper of its position
potentiometer read by the board's ADC (docs/model.md; docs/hardware.md,
"The pen servo's feedback").  It reads the
actuator commands (H-bridge duties, the servo's PWM duty) and nothing of the
controller.  The simulated arm (:class:`ttt_sm.twin.sim.ArmSim`) fuses it
with the cascade controller.

Drives are numbered 1, 2, 3 as in the thesis; arrays of three are indexed
0..2 (drive 1 first).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..arm.protocol import Sensors
from ..params import ArmParams
from . import _plant as P
from . import layout
from ._buffers import flat_view
from ._plant import gravity_torques_py
from .errors import SimError

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


def gravity_torques(params: ArmParams, q: Angles) -> np.ndarray:
    """Gravity torques on joints 1..3 (N m) at load angles `q` (q = 0 hangs down).

    Joint 2 carries link 2, link 3 and the tool; joint 3 carries link 3 and
    the tool (at the end of L3).  Joint 1 turns about the vertical: none.
    The formula is the plant step's own (``_plant.gravity_torques``).
    """
    g2, g23 = gravity_coefficients(params)
    return np.array([0.0, *gravity_torques_py(g2, g23, q[1], q[2])])


def gear_play(tau: float, clearance: float, stiffness: float) -> float:
    """How far a link sits behind its motor (rad, joint side) under the load torque `tau` (N m).

    Half the gear clearance plus the gear's elastic deflection, on the
    side the torque pushes; 0 without torque.  The plant's power-on and the
    gear-play compensation (``app/compensation.py``) use it.
    """
    return 0.0 if tau == 0.0 else math.copysign(clearance / 2 + abs(tau) / stiffness, tau)


def gravity_coefficients(params: ArmParams) -> tuple[float, float]:
    """(g2, g23), N m: gravity torques are -g2 sin q2 - g23 sin(q2 + q3) on joint 2, -g23 sin(q2 + q3) on 3."""
    m, geo = params.masses, params.true_geometry  # the arm as built
    g2 = G * (m.link2_kg * m.link2_com + (m.link3_kg + m.tool_kg) * geo.L2)
    g23 = G * (m.link3_kg * m.link3_com + m.tool_kg * geo.L3)
    return g2, g23


def check_pose(params: ArmParams, q0: Angles | None) -> np.ndarray:
    """`q0` (default :data:`REST_POSE`) as 4 floats within the joint limits, else SimError."""
    q = np.array(REST_POSE if q0 is None else q0, dtype=float)
    if q.shape != (4,) or not np.all(np.isfinite(q)):
        raise SimError(f"q0 must be 4 finite joint angles (rad), got {q0!r}")
    lo, hi = np.array(params.joint_min), np.array(params.joint_max)
    bad = np.flatnonzero((q < lo) | (q > hi))
    if bad.size:
        j = int(bad[0])
        raise SimError(f"q0[{j}] = {q[j]:.4f} rad lies outside joint {j + 1}'s limits "
                       f"[{lo[j]:.4f}, {hi[j]:.4f}]")
    return q


class Plant:
    """The physical arm, powered on at a pose, stepped by the actuator commands.

    Parameters
    ----------
    params : ArmParams
        The parameter file.
    q0 : array of 4 floats
        True joint angles at power-on (rad), within the limits (:func:`check_pose`).
        The gears start engaged on the side gravity loads them; encoder
        counts are 0 at power-on.
    rng : numpy Generator
        Seeds the current-measurement noise (one generator per drive).
    substeps : int
        Sub-steps per control step (see :data:`SUBSTEPS`).
    current_noise_a : float
        Standard deviation of the current measurement noise, A.

    Attributes
    ----------
    buffer : ndarray, shape (``layout.N_PR``, ``layout.PLANT_WIDTH``)
        The plant's float memory; ``pp``, ``ps`` (3 rows each), ``pg`` and
        ``pgs`` are views of its rows (``layout.PR_*``).
    ints : ndarray of int64, shape (3, ``layout.N_PI``)
        Counters, index switches, hard-stop contact, noise generators.
    """

    def __init__(self, params: ArmParams, q0: np.ndarray, rng: np.random.Generator,
                 substeps: int = SUBSTEPS, current_noise_a: float = CURRENT_NOISE_A) -> None:
        if substeps < 1:
            raise SimError(f"substeps must be >= 1, got {substeps}")
        self.params = params
        self.substeps = int(substeps)
        self.dt = params.control.dt
        self.buffer = np.zeros((layout.N_PR, layout.PLANT_WIDTH))
        self.pp, self.ps = self.buffer[layout.PR_PP:layout.PR_PP + 3], self.buffer[layout.PR_PS:layout.PR_PS + 3]
        self.pg, self.pgs = self.buffer[layout.PR_PG], self.buffer[layout.PR_PGS]
        self.ints = np.zeros((3, layout.N_PI), dtype=np.int64)
        self._fill_drives(params, self.dt / self.substeps)
        self._fill_global(params, self.substeps, current_noise_a)
        self._power_on(np.asarray(q0, dtype=float), rng)
        # flat views: the per-chart-step accessors read plain Python numbers
        self.psv = flat_view(self.ps)
        self.pgsv = flat_view(self.pgs)
        self.intsv = flat_view(self.ints)

    def _fill_drives(self, params: ArmParams, h: float) -> None:
        for d, p in enumerate(params.drives):
            row = self.pp[d]
            row[layout.PP_SUPPLY] = p.supply_v
            row[layout.PP_R] = p.resistance_ohm
            row[layout.PP_KT] = p.torque_constant
            row[layout.PP_JM] = p.rotor_inertia
            row[layout.PP_BM] = p.motor_viscous
            row[layout.PP_TC] = p.motor_coulomb
            row[layout.PP_N] = p.gear_ratio
            row[layout.PP_JL] = p.load_inertia
            row[layout.PP_BL] = p.load_viscous
            row[layout.PP_CLEAR] = p.gear_clearance
            row[layout.PP_K] = p.gear_stiffness
            row[layout.PP_CG] = p.gear_damping
            row[layout.PP_DTH_M] = 2.0 * math.pi / p.encoder_counts
            row[layout.PP_QMIN] = p.limit_min_rad
            row[layout.PP_QMAX] = p.limit_max_rad
            row[layout.PP_QIDX] = p.index_rad
            x = h * p.resistance_ohm / p.inductance_h
            row[layout.PP_EL_DECAY] = math.exp(-x)
            row[layout.PP_EL_AVG] = -math.expm1(-x) / x
            row[layout.PP_INV_R] = 1.0 / p.resistance_ohm
            row[layout.PP_INV_N] = 1.0 / p.gear_ratio
            row[layout.PP_H_JM] = h / p.rotor_inertia
            row[layout.PP_FC_H] = h * p.motor_coulomb / p.rotor_inertia
            row[layout.PP_VISC_M] = 1.0 / (1.0 + h * p.motor_viscous / p.rotor_inertia)
            row[layout.PP_H_JL] = h / p.load_inertia
            row[layout.PP_VISC_L] = 1.0 / (1.0 + h * p.load_viscous / p.load_inertia)
            row[layout.PP_TH_IDX] = p.gear_ratio * p.index_rad

    def _fill_global(self, params: ArmParams, substeps: int, noise: float) -> None:
        s, pg = params.servo, self.pg
        pg[layout.PG_DT] = params.control.dt
        pg[layout.PG_NSUB] = substeps
        pg[layout.PG_GRAV2], pg[layout.PG_GRAV23] = gravity_coefficients(params)
        pg[layout.PG_SV_MIN:layout.PG_SV_MIN + layout.SERVO_CALIBRATION_SIZE] = s.calibration
        pg[layout.PG_SV_RATE] = s.rate_rad_s
        pg[layout.PG_SV_TAU] = s.time_constant_s
        pg[layout.PG_SV_CLEAR] = s.clearance_rad
        pg[layout.PG_I_NOISE] = noise
        pg[layout.PG_SV_INV_TAU] = 1.0 / s.time_constant_s
        pg[layout.PG_H] = params.control.dt / substeps
        k = s.feedback_counts_per_rad
        pg[layout.PG_FB_K] = k
        pg[layout.PG_FB_C0] = s.feedback_counts(0.0)
        pg[layout.PG_FB_NOISE] = s.feedback_noise_lsb
        pg[layout.PG_FB_ALPHA] = 1.0 if s.feedback_tau_s == 0.0 else -math.expm1(-pg[layout.PG_H] / s.feedback_tau_s)
        pg[layout.PG_FB_FULL] = 2.0 ** s.feedback_bits - 1.0
        self._fb = (s.feedback_cal_a_rad, s.feedback_cal_a_counts, 1.0 / k)  # the PC's calibration
    def _power_on(self, q0: np.ndarray, rng: np.random.Generator) -> None:
        ps, pi, pp = self.ps, self.ints, self.pp
        tau = gravity_torques(self.params, q0)
        for d, p in enumerate(self.params.drives):
            # the gear rests engaged on the side gravity pushes it, deflected by the load
            ps[d, layout.PS_Q] = q0[d]
            ps[d, layout.PS_TH] = p.gear_ratio * (q0[d] - gear_play(tau[d], p.gear_clearance, p.gear_stiffness))
            pi[d, layout.PI_C0] = math.floor(ps[d, layout.PS_TH] / pp[d, layout.PP_DTH_M])
            pi[d, layout.PI_INDEX] = int(ps[d, layout.PS_TH] > pp[d, layout.PP_TH_IDX])
            pi[d, layout.PI_RNG] = int(rng.integers(0, P.LCG_MASK))
        pi[0, layout.PI_FB_RNG] = int(rng.integers(0, P.LCG_MASK))  # drawn after the drives': their noise is as it was
        servo = self.params.servo
        self.pgs[layout.PGS_SV_CMD] = servo.angle_for_duty(servo.duty_for_angle(q0[3]))
        self.pgs[layout.PGS_SV_TH] = q0[3]
        self.pgs[layout.PGS_SV_Q] = q0[3]
        self.pgs[layout.PGS_FB_V] = q0[3]
        self.pgs[layout.PGS_FB_COUNTS] = P.feedback_counts(self.pg, self.pgs, self.ints)

    # ---- stepping and sensors ---------------------------------------------------

    def step(self, act: np.ndarray) -> None:
        """One control step on its own under the actuator commands `act` (``layout.ACT_*``).

        The simulated arm does not call this: its fused loop runs the same
        compiled step beside the controller's (``_kernel.run_steps``).
        """
        P.plant_step(self.pp, self.pg, self.ps, self.pgs, self.ints, act)

    @property
    def t(self) -> float:
        """Time since power-on, s."""
        return self.pgsv[layout.PGS_T]

    @property
    def counts(self) -> np.ndarray:
        """Encoder counts of drives 1..3 since power-on (a view: what the controller reads)."""
        return self.ints[:, layout.PI_COUNTS]

    @property
    def feedback_counts(self) -> int:
        """The ADC's last reading of the servo's feedback wire, counts (what a board's STATUS carries)."""
        return int(self.pgsv[layout.PGS_FB_COUNTS])

    def sensors(self) -> Sensors:
        """The readings of the encoders, index switches, current sensors and the servo's feedback now."""
        v, n, ps, w, i, g = self.intsv, layout.N_PI, self.psv, layout.PLANT_WIDTH, layout.PS_I_MEAS, self.pgsv
        cn, ix, ic, ie = layout.PI_COUNTS, layout.PI_INDEX, layout.PI_INDEX_COUNT, layout.PI_INDEX_EDGES
        a0, c0, inv_k = self._fb
        # plain reads of the flat views, and the named tuple made as a tuple (its generated __new__ is
        # a Python call more): it runs every chart step
        return tuple.__new__(Sensors, (  # type: ignore[type-var]
            (v[cn], v[n + cn], v[2 * n + cn]), (v[ix] == 1, v[n + ix] == 1, v[2 * n + ix] == 1),
            (v[ic], v[n + ic], v[2 * n + ic]), (v[ie], v[n + ie], v[2 * n + ie]),
            (ps[i], ps[w + i], ps[2 * w + i]), g[layout.PGS_T], a0 + (g[layout.PGS_FB_COUNTS] - c0) * inv_k))


__all__ = ["Plant", "SimError", "REST_POSE", "SUBSTEPS", "CURRENT_NOISE_A", "G", "Angles",
           "check_pose", "gear_play", "gravity_coefficients", "gravity_torques",
           "gravity_torques_py"]
