"""The plant's step, compiled: three DC drives, their gears and loads, the pen servo, the sensors.

One call of :func:`plant_step` is one control step of the physical arm: it
reads the actuator commands ``act`` (H-bridge duties and on/off flags, the
servo's PWM duty: the layout of ``_cascade.ACT_*``) and integrates over
``n_sub`` sub-steps, per DC drive: armature current (exact exponential over
each sub-step), motor with implicit viscous and Coulomb friction (stick
without chattering), gear clearance as a dead-zone spring with contact
damping, load with gravity, hard stops, the index switch; then the servo
(first-order position loop, slew-rate limit, gear play) and its feedback
wire (the potentiometer on its output shaft, through an RC filter to the
board's ADC).  At the end it quantizes the motor angles into integer encoder
counts, samples the currents with noise and the feedback wire into ADC
counts with noise: what the controller reads next.

Memory: per-drive parameter rows ``pp[d, PP_*]``, global parameters
``pg[PG_*]``, per-drive float state ``ps[d, PS_*]``, global state
``pgs[PGS_*]`` and per-drive integer state ``pi[d, PI_*]`` (the counters,
index switch, hard-stop contact and the noise generator).  The ``PP_``,
``PG_``, ``PS_``, ``PGS_`` and ``PI_`` names are the only way code should
index them.  The float blocks are rows of one buffer ``pf[PR_*]`` of
:data:`WIDTH` columns.
docs/model.md derives the equations.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._cascade import ACT_BRIDGE, ACT_DUTY, ACT_SV_DUTY

# ---- per-drive parameter row pp[d, PP_*] (SI units; joint = load side) ------
PP_SUPPLY = 0  # supply voltage (V)
PP_R = 1  # armature resistance (ohm)
PP_KT = 2  # torque constant = back-EMF constant (N m / A = V s / rad)
PP_JM = 3  # rotor inertia (kg m^2, motor shaft)
PP_BM = 4  # motor viscous friction (N m s / rad)
PP_TC = 5  # motor Coulomb (= static) friction (N m)
PP_N = 6  # gear ratio (motor angle / joint angle)
PP_JL = 7  # load inertia (kg m^2, joint)
PP_BL = 8  # load viscous friction (N m s / rad)
PP_CLEAR = 9  # total gear clearance at the joint (rad)
PP_K = 10  # gear stiffness at the joint when engaged (N m / rad)
PP_CG = 11  # gear contact damping at the joint (N m s / rad)
PP_DTH_M = 12  # motor angle of one encoder count (rad)
PP_QMIN = 13  # hard stops (joint, rad)
PP_QMAX = 14
PP_QIDX = 15  # index switch angle (motor-side joint angle, rad)
PP_EL_DECAY = 16  # exp(-h R / L): current decay over one sub-step
PP_EL_AVG = 17  # (1 - exp(-h R / L)) L / (R h): mean of that decay over the sub-step
# derived per sub-step h, so the sub-step multiplies instead of dividing
PP_INV_R = 18  # 1 / R
PP_INV_N = 19  # 1 / N
PP_H_JM = 20  # h / Jm
PP_FC_H = 21  # h Tc / Jm: speed change Coulomb friction can stop within one sub-step
PP_VISC_M = 22  # 1 / (1 + h Bm / Jm): implicit motor viscous friction
PP_H_JL = 23  # h / Jl
PP_VISC_L = 24  # 1 / (1 + h Bl / Jl)
PP_TH_IDX = 25  # motor angle of the index switch, N * index angle
N_PP = 26

# ---- global parameters pg[PG_*] ----------------------------------------------
PG_DT = 0  # control step (s)
PG_NSUB = 1  # sub-steps per control step (stored as a float)
PG_GRAV2 = 2  # g * (m2 c2 + (m3 + m_tool) L2): joint-2 gravity from sin(q2) (N m)
PG_GRAV23 = 3  # g * (m3 c3 + m_tool L3): gravity from sin(q2 + q3) on joints 2 and 3 (N m)
PG_SV_MIN = 4  # servo: range (rad), pulse widths and period (s), slew rate (rad/s),
PG_SV_MAX = 5  #        lag time constant (s), gear clearance (rad)
PG_SV_PMIN = 6
PG_SV_PMAX = 7
PG_SV_PERIOD = 8
PG_SV_RATE = 9
PG_SV_TAU = 10
PG_SV_CLEAR = 11
PG_I_NOISE = 12  # standard deviation of the current measurement noise (A)
PG_SV_INV_TAU = 13  # 1 / PG_SV_TAU
PG_H = 14  # the sub-step, PG_DT / PG_NSUB (s)
PG_FB_K = 15  # servo feedback: ADC counts per rad of the output shaft (the calibration's slope)
PG_FB_C0 = 16  #                 ADC counts at 0 rad
PG_FB_NOISE = 17  #              rms noise of one reading (counts)
PG_FB_ALPHA = 18  #              the RC filter's step over one sub-step, 1 - exp(-h / tau) (1: no filter)
PG_FB_FULL = 19  #               the ADC's full scale, 2^bits - 1 (counts)
N_PG = 20

# ---- per-drive float state ps[d, PS_*] ----------------------------------------
PS_I = 0  # armature current (A)
PS_TH = 1  # motor shaft angle (rad, absolute: the encoder's edges sit at fixed angles)
PS_WM = 2  # motor shaft speed (rad/s)
PS_Q = 3  # load (joint) angle (rad)
PS_WQ = 4  # load speed (rad/s)
PS_I_MEAS = 5  # measured current (A)
N_PS = 6

# ---- global state pgs[PGS_*] ---------------------------------------------------
PGS_T = 0  # simulated time (s)
PGS_SV_CMD = 1  # angle the servo's PWM duty commands (rad)
PGS_SV_TH = 2  # servo's internal (motor-side) angle (rad)
PGS_SV_Q = 3  # servo output angle q4 after its gear clearance (rad)
PGS_FB_V = 4  # the feedback wire after the RC filter, as the angle it stands for (rad)
PGS_FB_COUNTS = 5  # the ADC's reading of it (integer counts, stored as a float)
N_PGS = 6

# ---- per-drive integer state pi[d, PI_*] -----------------------------------------
PI_C0 = 0  # counter value of the motor angle at power-on (counts are relative to it)
PI_COUNTS = 1  # encoder counts
PI_INDEX = 2  # index switch level (1: motor-side joint angle above the switch)
PI_INDEX_COUNT = 3  # counts latched at the last index edge
PI_INDEX_EDGES = 4  # number of index edges seen
PI_AT_LIMIT = 5  # -1 / +1 when the load rests on its lower / upper hard stop, else 0
PI_RNG = 6  # state of the current-noise generator (31-bit LCG)
PI_FB_RNG = 7  # row 0 only: state of the servo feedback's noise generator (31-bit LCG)
N_PI = 8

# ---- one float buffer pf[PR_*, :WIDTH]: each block is a row or three -----------------
PR_PP = 0  # 3 rows: pp
PR_PS = 3  # 3 rows: ps
PR_PG = 6  # pg
PR_PGS = 7  # pgs
N_PR = 8
WIDTH = max(N_PP, N_PS, N_PG, N_PGS)

LCG_MASK = 0x7FFFFFFF  # a 31-bit linear congruential generator (glibc's constants),
_LCG_A = 1103515245  # exact in int64 both compiled and as plain Python; no division
_LCG_C = 12345


@njit(cache=True)
def _clip(x: float, lo: float, hi: float) -> float:
    return lo if x < lo else (hi if x > hi else x)


@njit(cache=True)
def _gauss(pi: np.ndarray, d: int, column: int = PI_RNG) -> float:
    """Approximately normal N(0, 1) from four uniforms of the generator in ``pi[d, column]``."""
    acc = 0.0
    s = pi[d, column]
    for _ in range(4):
        s = (s * _LCG_A + _LCG_C) & LCG_MASK
        acc += s * (1.0 / 2147483648.0)
    pi[d, column] = s
    return (acc - 2.0) * 1.7320508075688772  # the sum of 4 uniforms has variance 1/3


@njit(cache=True, inline="always")  # inlined (numba IR): no call with arrays unpacked, see _kernel.py
def _integrate_drive(d: int, n_sub: int, h: float, tau0: float, dtau_dq: float, dtau_dt: float,
                     pp: np.ndarray, ps: np.ndarray, pi: np.ndarray, duty: float, bridge_off: bool) -> None:
    """Advance drive d's plant over one control step in `n_sub` sub-steps of h.

    The load torque from gravity is ``tau0 + dtau_dq * (q - q_start) + dtau_dt * t``
    (t from the start of the step): its own angle enters exactly to first
    order, the other pitch joint's motion as its speed at the start of the
    step.  Each sub-step is semi-implicit: see docs/model.md.  The state is
    kept in locals over the sub-steps (this loop is the twin's hot spot).
    """
    # parameters
    supply, kt, inv_r = pp[d, PP_SUPPLY], pp[d, PP_KT], pp[d, PP_INV_R]
    el_decay, el_avg = pp[d, PP_EL_DECAY], pp[d, PP_EL_AVG]
    inv_n, half = pp[d, PP_INV_N], 0.5 * pp[d, PP_CLEAR]
    k_gear, c_gear = pp[d, PP_K], pp[d, PP_CG]
    h_jm, fc, visc_m = pp[d, PP_H_JM], pp[d, PP_FC_H], pp[d, PP_VISC_M]
    h_jl, visc_l = pp[d, PP_H_JL], pp[d, PP_VISC_L]
    q_min, q_max, th_idx = pp[d, PP_QMIN], pp[d, PP_QMAX], pp[d, PP_TH_IDX]
    u = supply * duty
    # state
    i = ps[d, PS_I]
    wm, th = ps[d, PS_WM], ps[d, PS_TH]
    wq, q = ps[d, PS_WQ], ps[d, PS_Q]
    q_start = q
    level = pi[d, PI_INDEX]
    lim = pi[d, PI_AT_LIMIT]
    for k in range(n_sub):
        # armature: L di/dt = u - R i - Ke w, exact for the back-EMF held over the sub-step
        if bridge_off:
            # bridge off: no current path but the freewheel diodes, which
            # return a remaining current to the supply (u = -sign(i) V) until
            # it is zero; the back-EMF stays below the supply, so none starts
            if i == 0.0:
                i_avg = 0.0
            else:
                i_ss = ((-supply if i > 0.0 else supply) - kt * wm) * inv_r
                i1 = i_ss + (i - i_ss) * el_decay
                if (i1 > 0.0) == (i > 0.0):
                    i_avg = i_ss + (i - i_ss) * el_avg
                    i = i1
                else:
                    i_avg = 0.5 * i * i / (i - i1)  # linear decay to zero within the sub-step
                    i = 0.0
        else:
            i_ss = (u - kt * wm) * inv_r
            i_avg = i_ss + (i - i_ss) * el_avg
            i = i_ss + (i - i_ss) * el_decay
        # gear: dead-zone spring with contact damping, the clearance split evenly around 0
        delta = th * inv_n - q
        tg = 0.0
        if delta > half:
            tg = k_gear * (delta - half) + c_gear * (wm * inv_n - wq)
            tg = tg if tg > 0.0 else 0.0  # a contact pushes, never pulls
        elif delta < -half:
            tg = k_gear * (delta + half) + c_gear * (wm * inv_n - wq)
            tg = tg if tg < 0.0 else 0.0
        # motor: viscous and Coulomb friction implicit in the new speed; it
        # sticks when friction can hold the torque over the whole sub-step
        v = wm + (kt * i_avg - tg * inv_n) * h_jm
        if v > fc:
            wm = (v - fc) * visc_m
        elif v < -fc:
            wm = (v + fc) * visc_m
        else:
            wm = 0.0
        # load: gear torque, gravity, implicit viscous friction
        tau = tau0 + dtau_dq * (q - q_start) + dtau_dt * (k * h)
        wq = (wq + (tg + tau) * h_jl) * visc_l
        th += h * wm
        q += h * wq
        # hard stops: inelastic, the load never passes them
        lim = 0
        if q <= q_min:
            q = q_min
            wq = wq if wq > 0.0 else 0.0
            lim = -1
        elif q >= q_max:
            q = q_max
            wq = wq if wq < 0.0 else 0.0
            lim = 1
        # index switch: a level on the motor-side joint angle (th / N against
        # the switch angle); the counter latches the count at the edge itself
        # (index capture), whatever the direction
        new_level = 1 if th > th_idx else 0
        if new_level != level:
            level = new_level
            pi[d, PI_INDEX_EDGES] += 1
            pi[d, PI_INDEX_COUNT] = int(math.floor(th_idx / pp[d, PP_DTH_M])) - pi[d, PI_C0]
    ps[d, PS_I] = i
    ps[d, PS_WM], ps[d, PS_TH] = wm, th
    ps[d, PS_WQ], ps[d, PS_Q] = wq, q
    pi[d, PI_INDEX] = level
    pi[d, PI_AT_LIMIT] = lim


@njit(cache=True)
def servo_angle_for_duty(duty: float, pg: np.ndarray) -> float:
    """Angle a PWM duty commands (the Servo.angle_for_duty of params.py)."""
    frac = (duty * pg[PG_SV_PERIOD] - pg[PG_SV_PMIN]) / (pg[PG_SV_PMAX] - pg[PG_SV_PMIN])
    frac = _clip(frac, 0.0, 1.0)
    return pg[PG_SV_MIN] + frac * (pg[PG_SV_MAX] - pg[PG_SV_MIN])


@njit(cache=True)
def _integrate_servo(cmd: float, n_sub: int, h: float, pg: np.ndarray, pgs: np.ndarray) -> None:
    """Hobby servo over one control step: first-order position loop, slew-rate limit, gear play.

    The feedback wire's RC filter follows the output angle (the potentiometer sits on the output shaft).
    """
    inv_tau, rate_max, half = pg[PG_SV_INV_TAU], pg[PG_SV_RATE], 0.5 * pg[PG_SV_CLEAR]
    alpha = pg[PG_FB_ALPHA]
    th, q, v = pgs[PGS_SV_TH], pgs[PGS_SV_Q], pgs[PGS_FB_V]
    for _ in range(n_sub):
        th += h * _clip((cmd - th) * inv_tau, -rate_max, rate_max)
        if th - q > half:
            q = th - half
        elif th - q < -half:
            q = th + half
        v += alpha * (q - v)
    pgs[PGS_SV_TH], pgs[PGS_SV_Q], pgs[PGS_FB_V] = th, q, v


@njit(cache=True)
def feedback_counts(pg: np.ndarray, pgs: np.ndarray, pi: np.ndarray) -> float:
    """The ADC's reading of the servo's feedback wire now: the filtered angle in counts, noisy, rounded, clipped."""
    c = math.floor(pg[PG_FB_C0] + pg[PG_FB_K] * pgs[PGS_FB_V] + pg[PG_FB_NOISE] * _gauss(pi, 0, PI_FB_RNG) + 0.5)
    return _clip(c, 0.0, pg[PG_FB_FULL])


@njit(cache=True, inline="always")  # inlined into the fused loop
def plant_step(pp: np.ndarray, pg: np.ndarray, ps: np.ndarray, pgs: np.ndarray, pi: np.ndarray,
               act: np.ndarray) -> None:
    """One control step of the arm's physics under the actuator commands `act`; sensors updated at its end."""
    n_sub = int(pg[PG_NSUB])
    h = pg[PG_H]
    sv_cmd = servo_angle_for_duty(act[ACT_SV_DUTY], pg)
    pgs[PGS_SV_CMD] = sv_cmd
    # gravity on the pitch joints from the true load angles (q = 0 hangs
    # down), linearised about the start of the control step
    q2, q23 = ps[1, PS_Q], ps[1, PS_Q] + ps[2, PS_Q]
    w2, w3 = ps[1, PS_WQ], ps[2, PS_WQ]
    s2, c2 = pg[PG_GRAV2] * math.sin(q2), pg[PG_GRAV2] * math.cos(q2)
    s23, c23 = pg[PG_GRAV23] * math.sin(q23), pg[PG_GRAV23] * math.cos(q23)
    for d in range(3):  # one call site: the inlined drive is compiled once
        if d == 0:
            tau0, dtau_dq, dtau_dt = 0.0, 0.0, 0.0  # joint 1 turns about the vertical
        elif d == 1:
            tau0, dtau_dq, dtau_dt = -s2 - s23, -c2 - c23, -c23 * w3
        else:
            tau0, dtau_dq, dtau_dt = -s23, -c23, -c23 * w2
        _integrate_drive(d, n_sub, h, tau0, dtau_dq, dtau_dt, pp, ps, pi, act[ACT_DUTY + d],
                         act[ACT_BRIDGE + d] == 0.0)
    _integrate_servo(sv_cmd, n_sub, h, pg, pgs)
    for d in range(3):
        # the quadrature counter: integer edges at fixed motor angles, relative to power-on
        pi[d, PI_COUNTS] = int(math.floor(ps[d, PS_TH] / pp[d, PP_DTH_M])) - pi[d, PI_C0]
        ps[d, PS_I_MEAS] = ps[d, PS_I] + pg[PG_I_NOISE] * _gauss(pi, d)
    pgs[PGS_FB_COUNTS] = feedback_counts(pg, pgs, pi)
    pgs[PGS_T] += pg[PG_DT]
