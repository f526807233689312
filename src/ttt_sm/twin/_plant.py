"""The plant's step, compiled: three DC drives, their gears and loads, the pen servo, the sensors.

One call of :func:`plant_step` is one control step of the physical arm: it
reads the actuator commands ``act`` (H-bridge duties and on/off flags, the
servo's PWM duty: the layout ``ACT_*`` of ``layout.py``) and integrates over
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
index them; ``twin/layout.py`` defines them.  The float blocks are rows of
one buffer ``pf[PR_*]`` of ``layout.PLANT_WIDTH`` columns.
docs/model.md derives the equations.

Gravity on the pitch joints (:func:`gravity_torques`, :func:`gravity_slopes`)
and the servo's calibration (``params.servo_angle``) are written once:
the plant's Python side (``plant.py``) and the gear-play compensation
(``app/compensation.py``) call the same functions as plain Python.
"""

from __future__ import annotations

import math
from math import cos, sin

import numpy as np
from numba import njit

from ..params import servo_angle
from . import layout
from .layout import (
    ACT_BRIDGE,
    ACT_DUTY,
    ACT_SV_DUTY,
    PG_DT,
    PG_FB_ALPHA,
    PG_FB_C0,
    PG_FB_FULL,
    PG_FB_K,
    PG_FB_NOISE,
    PG_GRAV2,
    PG_GRAV23,
    PG_H,
    PG_I_NOISE,
    PG_NSUB,
    PG_SV_CLEAR,
    PG_SV_INV_TAU,
    PG_SV_MAX,
    PG_SV_MIN,
    PG_SV_PERIOD,
    PG_SV_PMAX,
    PG_SV_PMIN,
    PG_SV_RATE,
    PGS_FB_COUNTS,
    PGS_FB_V,
    PGS_SV_CMD,
    PGS_SV_Q,
    PGS_SV_TH,
    PGS_T,
    PI_AT_LIMIT,
    PI_C0,
    PI_COUNTS,
    PI_FB_RNG,
    PI_INDEX,
    PI_INDEX_COUNT,
    PI_INDEX_EDGES,
    PI_RNG,
    PP_CG,
    PP_CLEAR,
    PP_DTH_M,
    PP_EL_AVG,
    PP_EL_DECAY,
    PP_FC_H,
    PP_H_JL,
    PP_H_JM,
    PP_INV_N,
    PP_INV_R,
    PP_K,
    PP_KT,
    PP_QMAX,
    PP_QMIN,
    PP_SUPPLY,
    PP_TH_IDX,
    PP_VISC_L,
    PP_VISC_M,
    PS_I,
    PS_I_MEAS,
    PS_Q,
    PS_TH,
    PS_WM,
    PS_WQ,
)

# the offsets above, and the servo's formula from params/values.py, are frozen into the cached machine code:
# recompile when either changes
layout.forget_stale_compilations(__file__, servo_angle.__code__.co_filename)

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


#: ``params.servo_angle`` compiled: the servo's calibration, one definition for params/values.py and this step.
servo_angle_compiled = njit(cache=True, inline="always")(servo_angle)


@njit(cache=True)
def servo_angle_for_duty(duty: float, pg: np.ndarray) -> float:
    """Angle a PWM duty commands, with the servo's calibration in `pg`."""
    return servo_angle_compiled(duty, pg[PG_SV_MIN], pg[PG_SV_MAX], pg[PG_SV_PMIN], pg[PG_SV_PMAX],
                                pg[PG_SV_PERIOD])


@njit(cache=True, inline="always")
def gravity_torques(g2: float, g23: float, q2: float, q3: float) -> tuple[float, float]:
    """Gravity torques on joints 2 and 3 (N m) at load angles `q2`, `q3` (q = 0 hangs down).

    ``g2`` and ``g23`` (N m) are ``plant.gravity_coefficients``: joint 2
    carries link 2, link 3 and the tool, joint 3 link 3 and the tool (at
    the end of L3).  Joint 1 turns about the vertical: none.  The plant's
    step, ``plant.gravity_torques`` and the gear-play compensation
    (``app/compensation.py``) all use this function.
    """
    t2 = g2 * sin(q2)
    t23 = g23 * sin(q2 + q3)
    return -t2 - t23, -t23


@njit(cache=True, inline="always")
def gravity_slopes(g2: float, g23: float, q2: float, q3: float) -> tuple[float, float]:
    """``(g2 cos q2, g23 cos(q2 + q3))``: :func:`gravity_torques`' derivatives, less their signs.

    d tau2 / d q2 = -(both), d tau2 / d q3 = d tau3 / d q2 = d tau3 / d q3 = -(the second).
    """
    return g2 * cos(q2), g23 * cos(q2 + q3)


#: :func:`gravity_torques` as plain Python (the same source), for plain-Python callers that run every
#: chart step (a numba call costs more in dispatch than this arithmetic); with ``NUMBA_DISABLE_JIT=1``
#: it is :func:`gravity_torques` itself.
gravity_torques_py = getattr(gravity_torques, "py_func", gravity_torques)


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
    g2, g23, q2, q3 = pg[PG_GRAV2], pg[PG_GRAV23], ps[1, PS_Q], ps[2, PS_Q]
    w2, w3 = ps[1, PS_WQ], ps[2, PS_WQ]
    tau2, tau3 = gravity_torques(g2, g23, q2, q3)
    c2, c23 = gravity_slopes(g2, g23, q2, q3)
    for d in range(3):  # one call site: the inlined drive is compiled once
        if d == 0:
            tau0, dtau_dq, dtau_dt = 0.0, 0.0, 0.0  # joint 1 turns about the vertical
        elif d == 1:
            tau0, dtau_dq, dtau_dt = tau2, -c2 - c23, -c23 * w3
        else:
            tau0, dtau_dq, dtau_dt = tau3, -c23, -c23 * w2
        _integrate_drive(d, n_sub, h, tau0, dtau_dq, dtau_dt, pp, ps, pi, act[ACT_DUTY + d],
                         act[ACT_BRIDGE + d] == 0.0)
    _integrate_servo(sv_cmd, n_sub, h, pg, pgs)
    for d in range(3):
        # the quadrature counter: integer edges at fixed motor angles, relative to power-on
        pi[d, PI_COUNTS] = int(math.floor(ps[d, PS_TH] / pp[d, PP_DTH_M])) - pi[d, PI_C0]
        ps[d, PS_I_MEAS] = ps[d, PS_I] + pg[PG_I_NOISE] * _gauss(pi, d)
    pgs[PGS_FB_COUNTS] = feedback_counts(pg, pgs, pi)
    pgs[PGS_T] += pg[PG_DT]
