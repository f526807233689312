"""The cascade controller's step, compiled: what runs in the microcontroller of a real arm.

One call of :func:`cascade_step` is one control step (thesis fig. 3.6) of the
three DC drives' controllers and the servo's PWM.  It reads the encoder
counts and writes the actuator commands; it sees nothing of the plant's
state.  Per DC drive:

1. read the encoder: ``q_meas = counts * rad_per_count + offset_estimate``;
2. speed from a filtered backward difference of ``q_meas`` (no tachometer);
3. advance the second-order setpoint filter (cut-off switched by ``fr_sw``);
4. outer position PID -> speed setpoint (clamped), inner speed PID -> PWM
   duty (saturated to -1..1), both with clamping anti-windup;
5. the duty computed now reaches the H-bridge one step later (the
   one-sample computation delay the tuning model assumes).

The servo's angle setpoint becomes its PWM duty (the pulse width the
servo's electronics read as that angle).

Memory, so that the step can be ported to C as it is (docs/model.md, "The
controller step"): per-drive parameter rows ``cp[d, CP_*]``, global
parameters ``cg[CG_*]``, per-drive state ``cs[d, CS_*]``, global state
``cgs[CGS_*]``, per-drive modes ``cm[d]`` (integers) and the outputs
``act[ACT_*]``; the input is ``counts[d]`` (integers).  All floats are
float64.  The ``CP_``, ``CG_``, ``CS_``, ``CGS_`` and ``ACT_`` names are the
only way code should index them.  The float blocks are rows of one
buffer ``cf[CR_*]`` of :data:`WIDTH` columns (one array for the fused loop to
take, cut into its blocks by slicing rows: see ``_kernel.py``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

# ---- per-drive parameter row cp[d, CP_*] (SI units; joint side) -------------
CP_RPC = 0  # joint angle of one encoder count (rad)
CP_KP_POS = 1  # outer position PID: speed setpoint per rad (1/s), ...
CP_KI_POS = 2  # ... per rad s (1/s^2)
CP_KD_POS = 3  # ... per rad/s (dimensionless)
CP_KFF = 4  # speed feedforward from the setpoint filter's derivative
CP_WMAX = 5  # speed setpoint clamp (joint rad/s)
CP_KP_SPD = 6  # inner speed PID: duty per rad/s (s/rad), ...
CP_KI_SPD = 7  # ... per rad (1/rad)
CP_KD_SPD = 8  # ... per rad/s^2 (s^2/rad)
CP_ALPHA_W = 9  # speed filter: w += alpha * (w_raw - w)
N_CP = 10

# ---- global parameters cg[CG_*] ----------------------------------------------
CG_DT = 0  # control step (s)
CG_SF_NORMAL = 1  # setpoint filter, normal: a11 a12 b1 a21 a22 b2 (6 values)
CG_SF_SLOW = 7  # setpoint filter, slow (fr_sw on): same layout
CG_SV_MIN = 13  # servo: angle range (rad) ...
CG_SV_MAX = 14
CG_SV_PMIN = 15  # ... the pulse widths at its ends and the PWM period (s)
CG_SV_PMAX = 16
CG_SV_PERIOD = 17
N_CG = 18

# ---- per-drive state cs[d, CS_*] ----------------------------------------------
CS_R_RAW = 0  # position setpoint as given (encoder coordinates, rad)
CS_R_F = 1  # filtered setpoint (rad)
CS_R_FD = 2  # its derivative (rad/s)
CS_Q_PREV = 3  # previous measured angle, for the speed estimate
CS_W_MEAS = 4  # filtered speed estimate (rad/s)
CS_INT_POS = 5  # outer integrator (rad/s)
CS_INT_SPD = 6  # inner integrator (duty)
CS_W_REF = 7  # speed setpoint (rad/s)
CS_DUTY_CMD = 8  # duty computed this step (applied next step)
CS_OFFSET = 9  # offset estimate of the encoder (rad)
CS_OPEN_DUTY = 10  # duty in open-loop mode
N_CS = 11

# ---- global state cgs[CGS_*] --------------------------------------------------
CGS_FR_SW = 0  # 1.0 while slow moves are selected (fr_sw)
CGS_SV_SET = 1  # servo angle setpoint (rad)
CGS_SV_DUTY = 2  # its PWM duty (0..1) ...
CGS_SV_DUTY_OF = 3  # ... computed for this setpoint (NaN: not yet), so that it is computed once per setpoint
N_CGS = 4

# ---- outputs act[ACT_*]: what the plant (the H-bridges, the servo) receives ---
ACT_DUTY = 0  # 3 values: PWM duty applied to each H-bridge now (-1..1)
ACT_BRIDGE = 3  # 3 values: 1.0 while the bridge is on, 0.0 while off (the motor coasts)
ACT_SV_DUTY = 6  # servo PWM duty (0..1)
N_ACT = 7

# ---- modes cm[d] ------------------------------------------------------------------
MODE_OFF = 0  # controller and H-bridge off: the motor coasts (no current)
MODE_CLOSED = 1  # cascade control
MODE_OPEN = 2  # fixed duty (tests, experiments); duty 0 shorts the motor (brakes)

# ---- one float buffer cf[CR_*, :WIDTH]: each block is a row or three ----------------
CR_CP = 0  # 3 rows: cp
CR_CS = 3  # 3 rows: cs
CR_CG = 6  # cg
CR_CGS = 7  # cgs
CR_ACT = 8  # act
N_CR = 9
WIDTH = max(N_CP, N_CS, N_CG, N_CGS, N_ACT)


@njit(cache=True)
def _clip(x: float, lo: float, hi: float) -> float:
    return lo if x < lo else (hi if x > hi else x)


@njit(cache=True)
def servo_duty_for_angle(angle: float, cg: np.ndarray) -> float:
    """PWM duty (0..1) that commands `angle` (clipped to the range): ``Servo.duty_for_angle`` of params.py."""
    lo, hi = cg[CG_SV_MIN], cg[CG_SV_MAX]
    a = _clip(angle, lo, hi)
    frac = (a - lo) / (hi - lo)
    return (cg[CG_SV_PMIN] + frac * (cg[CG_SV_PMAX] - cg[CG_SV_PMIN])) / cg[CG_SV_PERIOD]


@njit(cache=True, inline="always")  # inlined (numba IR): no call with arrays unpacked, see _kernel.py
def _control_drive(d: int, cp: np.ndarray, cg: np.ndarray, cs: np.ndarray, mode: int, count: int,
                   slow: bool, dt: float) -> float:
    """Filters and cascade of drive d for one control step (fig. 3.6); returns the duty the bridge gets now."""
    q_meas = count * cp[d, CP_RPC] + cs[d, CS_OFFSET]
    # speed from a filtered derivative of the encoder angle (no tachometer)
    w_raw = (q_meas - cs[d, CS_Q_PREV]) / dt
    cs[d, CS_Q_PREV] = q_meas
    w_prev = cs[d, CS_W_MEAS]
    w_meas = w_prev + cp[d, CP_ALPHA_W] * (w_raw - w_prev)
    cs[d, CS_W_MEAS] = w_meas
    # second-order setpoint filter, exact discretisation (state: angle, rate)
    b = CG_SF_SLOW if slow else CG_SF_NORMAL
    r = cs[d, CS_R_F]
    v = cs[d, CS_R_FD]
    u = cs[d, CS_R_RAW]
    cs[d, CS_R_F] = cg[b] * r + cg[b + 1] * v + cg[b + 2] * u
    cs[d, CS_R_FD] = cg[b + 3] * r + cg[b + 4] * v + cg[b + 5] * u

    duty = 0.0
    if mode == MODE_CLOSED:
        # outer loop: position PID -> speed setpoint, clamped to the drive's speed
        e = cs[d, CS_R_F] - q_meas
        wmax = cp[d, CP_WMAX]
        i_pos = cs[d, CS_INT_POS] + cp[d, CP_KI_POS] * e * dt
        w_ff = cp[d, CP_KFF] * cs[d, CS_R_FD]
        w_d = cp[d, CP_KD_POS] * (cs[d, CS_R_FD] - w_meas)
        w_u = cp[d, CP_KP_POS] * e + i_pos + w_d + w_ff
        w_ref = _clip(w_u, -wmax, wmax)
        # clamping anti-windup: keep the integral only if it does not push further into the clamp
        if w_ref == w_u or (w_u > wmax) != (e > 0.0):
            cs[d, CS_INT_POS] = i_pos
        cs[d, CS_W_REF] = w_ref
        # inner loop: speed PID (derivative on the measurement) -> PWM duty
        ew = w_ref - w_meas
        i_spd = cs[d, CS_INT_SPD] + cp[d, CP_KI_SPD] * ew * dt
        u_d = -cp[d, CP_KD_SPD] * (w_meas - w_prev) / dt
        u_w = cp[d, CP_KP_SPD] * ew + i_spd + u_d
        duty = _clip(u_w, -1.0, 1.0)  # PWM saturation
        if duty == u_w or (u_w > 1.0) != (ew > 0.0):
            cs[d, CS_INT_SPD] = i_spd
    else:
        cs[d, CS_INT_POS] = 0.0
        cs[d, CS_INT_SPD] = 0.0
        cs[d, CS_W_REF] = 0.0
        if mode == MODE_OPEN:
            duty = _clip(cs[d, CS_OPEN_DUTY], -1.0, 1.0)  # PWM saturation
    # one-sample computation delay: the bridge gets last step's command
    applied = cs[d, CS_DUTY_CMD]
    cs[d, CS_DUTY_CMD] = duty
    return applied


@njit(cache=True, inline="always")  # inlined into the fused loop
def cascade_step(cp: np.ndarray, cg: np.ndarray, cs: np.ndarray, cgs: np.ndarray, cm: np.ndarray,
                 counts: np.ndarray, act: np.ndarray) -> None:
    """One control step of the controllers: encoder `counts` (3 integers) in, `act` out.

    Reads ``counts[d]`` and the setpoints in ``cs``/``cgs``; updates the state
    ``cs``; writes the H-bridge duties and on/off flags and the servo duty
    into ``act``.  Nothing else is read or written.
    """
    dt = cg[CG_DT]
    slow = cgs[CGS_FR_SW] > 0.5
    for d in range(3):
        mode = cm[d]
        act[ACT_DUTY + d] = _control_drive(d, cp, cg, cs, mode, counts[d], slow, dt)
        act[ACT_BRIDGE + d] = 0.0 if mode == MODE_OFF else 1.0
    sv_set = cgs[CGS_SV_SET]
    if sv_set != cgs[CGS_SV_DUTY_OF]:
        cgs[CGS_SV_DUTY] = servo_duty_for_angle(sv_set, cg)
        cgs[CGS_SV_DUTY_OF] = sv_set
    act[ACT_SV_DUTY] = cgs[CGS_SV_DUTY]
