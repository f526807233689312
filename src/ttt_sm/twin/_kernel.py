"""The 1 kHz inner loop of the twin: setpoint filters, cascade PIDs and the plant.

One control step (thesis fig. 3.6) for each DC drive:

1. read the encoder: ``q_meas = counts * rad_per_count + offset_estimate``;
2. advance the second-order setpoint filter (cut-off switched by ``fr_sw``);
3. speed from a filtered backward difference of ``q_meas``;
4. outer position PID -> speed setpoint (clamped), inner speed PID -> PWM duty
   (both with clamping anti-windup);
5. the duty computed now reaches the H-bridge one step later (the one-sample
   computation delay the tuning model assumes);
6. integrate the plant over ``n_sub`` sub-steps: armature current (exact
   exponential over each sub-step), motor with implicit viscous and Coulomb
   friction (stick without chattering), gear clearance as a dead-zone spring
   with contact damping, load with gravity, hard stops, the index switch;
7. quantize the motor angle into integer encoder counts, sample the current.

Everything lives in a few numpy arrays so that numba compiles one function
and a call costs little: per-drive parameter rows ``dp[d, P_*]``, global
parameters ``gp[G_*]``, per-drive float state ``ds[d, S_*]``, per-drive
integer state ``di[d, I_*]``, global state ``gs[GS_*]`` and an optional
record buffer ``rec[k, REC_*]``.  The ``P_``, ``G_``, ``S_``, ``I_``, ``GS_``
and ``REC_`` names below are the only way code should index them.

``NUMBA_DISABLE_JIT=1`` runs the same code as plain Python (slowly) for a
debugger.  docs/model.md derives the equations.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

# ---- per-drive parameter row dp[d, P_*] (SI units; joint = load side) ------
P_SUPPLY = 0  # supply voltage (V)
P_R = 1  # armature resistance (ohm)
P_KT = 2  # torque constant = back-EMF constant (N m / A = V s / rad)
P_JM = 3  # rotor inertia (kg m^2, motor shaft)
P_BM = 4  # motor viscous friction (N m s / rad)
P_TC = 5  # motor Coulomb (= static) friction (N m)
P_N = 6  # gear ratio (motor angle / joint angle)
P_JL = 7  # load inertia (kg m^2, joint)
P_BL = 8  # load viscous friction (N m s / rad)
P_CLEAR = 9  # total gear clearance at the joint (rad)
P_K = 10  # gear stiffness at the joint when engaged (N m / rad)
P_CG = 11  # gear contact damping at the joint (N m s / rad)
P_DTH_M = 12  # motor angle of one encoder count (rad)
P_RPC = 13  # joint angle of one encoder count (rad)
P_QMIN = 14  # hard stops (joint, rad)
P_QMAX = 15
P_QIDX = 16  # index switch angle (motor-side joint angle, rad)
P_EL_DECAY = 17  # exp(-h R / L): current decay over one sub-step
P_EL_AVG = 18  # (1 - exp(-h R / L)) L / (R h): mean of that decay over the sub-step
P_KP_POS = 19  # outer position PID (speed setpoint per rad, ...)
P_KI_POS = 20
P_KD_POS = 21
P_KFF = 22  # speed feedforward from the setpoint filter's derivative
P_WMAX = 23  # speed setpoint clamp (joint rad/s)
P_KP_SPD = 24  # inner speed PID (duty per rad/s, ...)
P_KI_SPD = 25
P_KD_SPD = 26
P_ALPHA_W = 27  # speed filter: w += alpha * (w_raw - w)
# derived per sub-step h, so the sub-step multiplies instead of dividing
P_INV_R = 28  # 1 / R
P_INV_N = 29  # 1 / N
P_H_JM = 30  # h / Jm
P_FC_H = 31  # h Tc / Jm: speed change Coulomb friction can stop within one sub-step
P_VISC_M = 32  # 1 / (1 + h Bm / Jm): implicit motor viscous friction
P_H_JL = 33  # h / Jl
P_VISC_L = 34  # 1 / (1 + h Bl / Jl)
P_TH_IDX = 35  # motor angle of the index switch, N * index angle
N_DP = 36

# ---- global parameters gp[G_*] ---------------------------------------------
G_DT = 0  # control step (s)
G_NSUB = 1  # plant sub-steps per control step (stored as a float)
G_GRAV2 = 2  # g * (m2 c2 + (m3 + m_tool) L2): joint-2 gravity from sin(q2) (N m)
G_GRAV23 = 3  # g * (m3 c3 + m_tool L3): gravity from sin(q2 + q3) on joints 2 and 3 (N m)
G_SF_NORMAL = 4  # setpoint filter, normal: a11 a12 b1 a21 a22 b2 (6 values)
G_SF_SLOW = 10  # setpoint filter, slow (fr_sw on): same layout
G_SV_MIN = 16  # servo: range (rad), pulse widths and period (s), slew rate (rad/s),
G_SV_MAX = 17  #        lag time constant (s), gear clearance (rad)
G_SV_PMIN = 18
G_SV_PMAX = 19
G_SV_PERIOD = 20
G_SV_RATE = 21
G_SV_TAU = 22
G_SV_CLEAR = 23
G_I_NOISE = 24  # standard deviation of the current measurement noise (A)
G_SV_INV_TAU = 25  # 1 / G_SV_TAU
N_GP = 26

# ---- per-drive float state ds[d, S_*] ---------------------------------------
S_I = 0  # armature current (A)
S_TH = 1  # motor shaft angle (rad, absolute: the encoder's edges sit at fixed angles)
S_WM = 2  # motor shaft speed (rad/s)
S_Q = 3  # load (joint) angle (rad)
S_WQ = 4  # load speed (rad/s)
S_R_RAW = 5  # position setpoint as given (encoder coordinates, rad)
S_R_F = 6  # filtered setpoint (rad)
S_R_FD = 7  # its derivative (rad/s)
S_Q_PREV = 8  # previous measured angle, for the speed estimate
S_W_MEAS = 9  # filtered speed estimate (rad/s)
S_INT_POS = 10  # outer integrator (rad/s)
S_INT_SPD = 11  # inner integrator (duty)
S_W_REF = 12  # speed setpoint (rad/s)
S_DUTY_CMD = 13  # duty computed this step (applied next step)
S_DUTY = 14  # duty applied to the H-bridge now
S_OFFSET = 15  # offset estimate of the encoder (rad)
S_I_MEAS = 16  # measured current (A)
S_OPEN_DUTY = 17  # duty in open-loop mode
N_DS = 18

# ---- per-drive integer state di[d, I_*] -------------------------------------
I_C0 = 0  # counter value of the motor angle at power-on (counts are relative to it)
I_COUNTS = 1  # encoder counts
I_INDEX = 2  # index switch level (1: motor-side joint angle above the switch)
I_INDEX_COUNT = 3  # counts latched at the last index edge
I_INDEX_EDGES = 4  # number of index edges seen
I_MODE = 5  # MODE_OFF, MODE_CLOSED or MODE_OPEN
I_AT_LIMIT = 6  # -1 / +1 when the load rests on its lower / upper hard stop, else 0
I_RNG = 7  # state of the current-noise generator (31-bit LCG)
N_DI = 8

MODE_OFF = 0  # controller and H-bridge off: the motor coasts (no current)
MODE_CLOSED = 1  # cascade control
MODE_OPEN = 2  # fixed duty (tests, experiments); duty 0 shorts the motor (brakes)

# ---- global state gs[GS_*] ---------------------------------------------------
GS_T = 0  # simulated time (s)
GS_FR_SW = 1  # 1.0 while slow moves are selected (fr_sw)
GS_SV_SET = 2  # servo angle setpoint as given (rad)
GS_SV_DUTY = 3  # servo PWM duty (0..1)
GS_SV_CMD = 4  # angle that duty commands (rad)
GS_SV_TH = 5  # servo's internal (motor-side) angle (rad)
GS_SV_Q = 6  # servo output angle q4 after its gear clearance (rad)
N_GS = 7

# ---- record buffer rec[k, REC_*], one row per control step (after it) -------
REC_T = 0
REC_R_RAW = 1  # 4 columns: drives 1-3, servo
REC_R_F = 5  # 4 columns: filtered setpoints, angle the servo duty commands
REC_Q_ENC = 9  # 3 columns
REC_Q_TRUE = 12  # 4 columns
REC_Q_MOTOR = 16  # 3 columns
REC_CURRENT = 19  # 3 columns (true current)
REC_DUTY = 22  # 4 columns: applied duty of drives 1-3, servo duty
REC_W_REF = 26  # 3 columns
REC_W_MEAS = 29  # 3 columns
N_REC = 32

_LCG_MASK = 0x7FFFFFFF  # a 31-bit linear congruential generator (glibc's constants),
_LCG_A = 1103515245  # exact in int64 both compiled and as plain Python; no division
_LCG_C = 12345


@njit(cache=True)
def _clip(x: float, lo: float, hi: float) -> float:
    return lo if x < lo else (hi if x > hi else x)


@njit(cache=True)
def _gauss(di: np.ndarray, d: int) -> float:
    """Approximately normal N(0, 1) from four uniforms of drive d's generator."""
    acc = 0.0
    s = di[d, I_RNG]
    for _ in range(4):
        s = (s * _LCG_A + _LCG_C) & _LCG_MASK
        acc += s * (1.0 / 2147483648.0)
    di[d, I_RNG] = s
    return (acc - 2.0) * 1.7320508075688772  # the sum of 4 uniforms has variance 1/3


@njit(cache=True)
def _control_drive(d: int, dp: np.ndarray, gp: np.ndarray, ds: np.ndarray, di: np.ndarray,
                   slow: bool, dt: float) -> None:
    """Filters and cascade controller of drive d for one control step (fig. 3.6)."""
    q_meas = di[d, I_COUNTS] * dp[d, P_RPC] + ds[d, S_OFFSET]
    # speed from a filtered derivative of the encoder angle (no tachometer)
    w_raw = (q_meas - ds[d, S_Q_PREV]) / dt
    ds[d, S_Q_PREV] = q_meas
    w_prev = ds[d, S_W_MEAS]
    w_meas = w_prev + dp[d, P_ALPHA_W] * (w_raw - w_prev)
    ds[d, S_W_MEAS] = w_meas
    # second-order setpoint filter, exact discretisation (state: angle, rate)
    b = G_SF_SLOW if slow else G_SF_NORMAL
    r = ds[d, S_R_F]
    v = ds[d, S_R_FD]
    u = ds[d, S_R_RAW]
    ds[d, S_R_F] = gp[b] * r + gp[b + 1] * v + gp[b + 2] * u
    ds[d, S_R_FD] = gp[b + 3] * r + gp[b + 4] * v + gp[b + 5] * u

    mode = di[d, I_MODE]
    duty = 0.0
    if mode == MODE_CLOSED:
        # outer loop: position PID -> speed setpoint, clamped to the drive's speed
        e = ds[d, S_R_F] - q_meas
        wmax = dp[d, P_WMAX]
        i_pos = ds[d, S_INT_POS] + dp[d, P_KI_POS] * e * dt
        w_ff = dp[d, P_KFF] * ds[d, S_R_FD]
        w_d = dp[d, P_KD_POS] * (ds[d, S_R_FD] - w_meas)
        w_u = dp[d, P_KP_POS] * e + i_pos + w_d + w_ff
        w_ref = _clip(w_u, -wmax, wmax)
        # clamping anti-windup: keep the integral only if it does not push further into the clamp
        if w_ref == w_u or (w_u > wmax) != (e > 0.0):
            ds[d, S_INT_POS] = i_pos
        ds[d, S_W_REF] = w_ref
        # inner loop: speed PID (derivative on the measurement) -> PWM duty
        ew = w_ref - w_meas
        i_spd = ds[d, S_INT_SPD] + dp[d, P_KI_SPD] * ew * dt
        u_d = -dp[d, P_KD_SPD] * (w_meas - w_prev) / dt
        u_w = dp[d, P_KP_SPD] * ew + i_spd + u_d
        duty = _clip(u_w, -1.0, 1.0)
        if duty == u_w or (u_w > 1.0) != (ew > 0.0):
            ds[d, S_INT_SPD] = i_spd
    else:
        ds[d, S_INT_POS] = 0.0
        ds[d, S_INT_SPD] = 0.0
        ds[d, S_W_REF] = 0.0
        if mode == MODE_OPEN:
            duty = _clip(ds[d, S_OPEN_DUTY], -1.0, 1.0)  # PWM saturation
    # one-sample computation delay: the bridge gets last step's command
    ds[d, S_DUTY] = ds[d, S_DUTY_CMD]
    ds[d, S_DUTY_CMD] = duty


@njit(cache=True)
def _integrate_drive(d: int, n_sub: int, h: float, tau0: float, dtau_dq: float, dtau_dt: float,
                     dp: np.ndarray, ds: np.ndarray, di: np.ndarray) -> None:
    """Advance drive d's plant over one control step in `n_sub` sub-steps of h.

    The load torque from gravity is ``tau0 + dtau_dq * (q - q_start) + dtau_dt * t``
    (t from the start of the step): its own angle enters exactly to first
    order, the other pitch joint's motion as its speed at the start of the
    step.  Each sub-step is semi-implicit: see docs/model.md.  The state is
    kept in locals over the sub-steps (this loop is the twin's hot spot).
    """
    # parameters
    supply, kt, inv_r = dp[d, P_SUPPLY], dp[d, P_KT], dp[d, P_INV_R]
    el_decay, el_avg = dp[d, P_EL_DECAY], dp[d, P_EL_AVG]
    inv_n, half = dp[d, P_INV_N], 0.5 * dp[d, P_CLEAR]
    k_gear, c_gear = dp[d, P_K], dp[d, P_CG]
    h_jm, fc, visc_m = dp[d, P_H_JM], dp[d, P_FC_H], dp[d, P_VISC_M]
    h_jl, visc_l = dp[d, P_H_JL], dp[d, P_VISC_L]
    q_min, q_max, th_idx = dp[d, P_QMIN], dp[d, P_QMAX], dp[d, P_TH_IDX]
    bridge_off = di[d, I_MODE] == MODE_OFF
    u = supply * ds[d, S_DUTY]
    # state
    i = ds[d, S_I]
    wm, th = ds[d, S_WM], ds[d, S_TH]
    wq, q = ds[d, S_WQ], ds[d, S_Q]
    q_start = q
    level = di[d, I_INDEX]
    lim = di[d, I_AT_LIMIT]
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
            di[d, I_INDEX_EDGES] += 1
            di[d, I_INDEX_COUNT] = int(math.floor(th_idx / dp[d, P_DTH_M])) - di[d, I_C0]
    ds[d, S_I] = i
    ds[d, S_WM], ds[d, S_TH] = wm, th
    ds[d, S_WQ], ds[d, S_Q] = wq, q
    di[d, I_INDEX] = level
    di[d, I_AT_LIMIT] = lim


@njit(cache=True)
def _servo_angle_for_duty(duty: float, gp: np.ndarray) -> float:
    """Angle a PWM duty commands (the Servo.angle_for_duty of params.py)."""
    frac = (duty * gp[G_SV_PERIOD] - gp[G_SV_PMIN]) / (gp[G_SV_PMAX] - gp[G_SV_PMIN])
    frac = _clip(frac, 0.0, 1.0)
    return gp[G_SV_MIN] + frac * (gp[G_SV_MAX] - gp[G_SV_MIN])


@njit(cache=True)
def _integrate_servo(cmd: float, n_sub: int, h: float, gp: np.ndarray, gs: np.ndarray) -> None:
    """Hobby servo over one control step: first-order position loop, slew-rate limit, gear play."""
    inv_tau, rate_max, half = gp[G_SV_INV_TAU], gp[G_SV_RATE], 0.5 * gp[G_SV_CLEAR]
    th, q = gs[GS_SV_TH], gs[GS_SV_Q]
    for _ in range(n_sub):
        th += h * _clip((cmd - th) * inv_tau, -rate_max, rate_max)
        if th - q > half:
            q = th - half
        elif th - q < -half:
            q = th + half
    gs[GS_SV_TH], gs[GS_SV_Q] = th, q


@njit(cache=True)
def run_steps(n: int, dp: np.ndarray, gp: np.ndarray, ds: np.ndarray, di: np.ndarray,
              gs: np.ndarray, rec: np.ndarray) -> None:
    """Run `n` control steps in place; fill `rec[:n]` if it has at least n rows."""
    dt = gp[G_DT]
    n_sub = int(gp[G_NSUB])
    h = dt / n_sub
    record = rec.shape[0] >= n
    for k in range(n):
        slow = gs[GS_FR_SW] > 0.5
        for d in range(3):
            _control_drive(d, dp, gp, ds, di, slow, dt)
        sv_cmd = _servo_angle_for_duty(gs[GS_SV_DUTY], gp)
        gs[GS_SV_CMD] = sv_cmd
        # gravity on the pitch joints from the true load angles (q = 0 hangs
        # down), linearised about the start of the control step
        q2, q23 = ds[1, S_Q], ds[1, S_Q] + ds[2, S_Q]
        w2, w3 = ds[1, S_WQ], ds[2, S_WQ]
        s2, c2 = gp[G_GRAV2] * math.sin(q2), gp[G_GRAV2] * math.cos(q2)
        s23, c23 = gp[G_GRAV23] * math.sin(q23), gp[G_GRAV23] * math.cos(q23)
        _integrate_drive(0, n_sub, h, 0.0, 0.0, 0.0, dp, ds, di)
        _integrate_drive(1, n_sub, h, -s2 - s23, -c2 - c23, -c23 * w3, dp, ds, di)
        _integrate_drive(2, n_sub, h, -s23, -c23, -c23 * w2, dp, ds, di)
        _integrate_servo(sv_cmd, n_sub, h, gp, gs)
        for d in range(3):
            # the quadrature counter: integer edges at fixed motor angles, relative to power-on
            di[d, I_COUNTS] = int(math.floor(ds[d, S_TH] / dp[d, P_DTH_M])) - di[d, I_C0]
            ds[d, S_I_MEAS] = ds[d, S_I] + gp[G_I_NOISE] * _gauss(di, d)
        gs[GS_T] += dt
        if record:
            rec[k, REC_T] = gs[GS_T]
            for d in range(3):
                rec[k, REC_R_RAW + d] = ds[d, S_R_RAW]
                rec[k, REC_R_F + d] = ds[d, S_R_F]
                rec[k, REC_Q_ENC + d] = di[d, I_COUNTS] * dp[d, P_RPC] + ds[d, S_OFFSET]
                rec[k, REC_Q_TRUE + d] = ds[d, S_Q]
                rec[k, REC_Q_MOTOR + d] = ds[d, S_TH] / dp[d, P_N]
                rec[k, REC_CURRENT + d] = ds[d, S_I]
                rec[k, REC_DUTY + d] = ds[d, S_DUTY]
                rec[k, REC_W_REF + d] = ds[d, S_W_REF]
                rec[k, REC_W_MEAS + d] = ds[d, S_W_MEAS]
            rec[k, REC_R_RAW + 3] = gs[GS_SV_SET]
            rec[k, REC_R_F + 3] = gs[GS_SV_CMD]
            rec[k, REC_Q_TRUE + 3] = gs[GS_SV_Q]
            rec[k, REC_DUTY + 3] = gs[GS_SV_DUTY]
