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
only way code should index them; ``twin/layout.py`` defines them (and
generates the firmware's ``layout.h`` from the same tables).  The float
blocks are rows of one buffer ``cf[CR_*]`` of ``layout.CONTROLLER_WIDTH``
columns (one array for the fused loop to take, cut into its blocks by
slicing rows: see ``_kernel.py``).

The setpoint filter (:func:`setpoint_filter`) and the servo's duty
(``params.servo_duty``) are written once and compiled here; the Safety
stage's model of the controller (``app/_monitor.py``) calls the same filter.
The firmware's ``cascade.c`` is this step's C port, held to it bit for bit
by ``tests/hardware/test_cascade_c.py``.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ..params import servo_duty
from . import layout
from .layout import (
    ACT_BRIDGE,
    ACT_DUTY,
    ACT_SV_DUTY,
    CG_DT,
    CG_SF_NORMAL,
    CG_SF_SLOW,
    CG_SV_MAX,
    CG_SV_MIN,
    CG_SV_PERIOD,
    CG_SV_PMAX,
    CG_SV_PMIN,
    CGS_FR_SW,
    CGS_SV_DUTY,
    CGS_SV_DUTY_OF,
    CGS_SV_SET,
    CP_ALPHA_W,
    CP_KD_POS,
    CP_KD_SPD,
    CP_KFF,
    CP_KI_POS,
    CP_KI_SPD,
    CP_KP_POS,
    CP_KP_SPD,
    CP_RPC,
    CP_WMAX,
    CS_DUTY_CMD,
    CS_INT_POS,
    CS_INT_SPD,
    CS_OFFSET,
    CS_OPEN_DUTY,
    CS_Q_PREV,
    CS_R_F,
    CS_R_FD,
    CS_R_RAW,
    CS_W_MEAS,
    CS_W_REF,
    MODE_CLOSED,
    MODE_OFF,
    MODE_OPEN,
)

# the offsets above, and the servo's formula from params/values.py, are frozen into the cached machine code:
# recompile when either changes
layout.forget_stale_compilations(__file__, servo_duty.__code__.co_filename)


@njit(cache=True)
def _clip(x: float, lo: float, hi: float) -> float:
    return lo if x < lo else (hi if x > hi else x)


#: ``params.servo_duty`` compiled: the servo's calibration, one definition for params/values.py and this step.
servo_duty_compiled = njit(cache=True, inline="always")(servo_duty)


@njit(cache=True)
def servo_duty_for_angle(angle: float, cg: np.ndarray) -> float:
    """PWM duty (0..1) that commands `angle` (clipped to the range), with the servo's calibration in `cg`."""
    return servo_duty_compiled(angle, cg[CG_SV_MIN], cg[CG_SV_MAX], cg[CG_SV_PMIN], cg[CG_SV_PMAX],
                               cg[CG_SV_PERIOD])


@njit(cache=True, inline="always")
def setpoint_filter(row: np.ndarray, k: int, r: float, v: float, u: float) -> tuple[float, float]:
    """One step of a second-order setpoint filter: the new angle and rate from ``(r, v)`` and the setpoint `u`.

    ``row[k:k + 6]`` holds ``a11 a12 b1 a21 a22 b2`` of ``x <- A x + B u``
    (``control.setpoint_filter_row``: the exact discretisation over one
    control step; the Safety stage's model uses the same over a chart
    step).  The controller step and ``app/_monitor.py`` call this one
    definition; ``cascade.c`` is its C port.
    """
    return (row[k] * r + row[k + 1] * v + row[k + 2] * u,
            row[k + 3] * r + row[k + 4] * v + row[k + 5] * u)


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
    cs[d, CS_R_F], cs[d, CS_R_FD] = setpoint_filter(cg, CG_SF_SLOW if slow else CG_SF_NORMAL,
                                                    cs[d, CS_R_F], cs[d, CS_R_FD], cs[d, CS_R_RAW])

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


# ---- the commands between steps: plain Python, as cascade.c's ttt_cascade_* do them ------------------------
# (CascadeController calls them with its numpy rows; nothing compiled calls them)

def hold(cs: np.ndarray, d: int, q: float) -> None:
    """Make drive d hold the encoder angle `q` (rad) with no bump: filters and integrators reset."""
    cs[d, CS_R_RAW] = q
    cs[d, CS_R_F] = q
    cs[d, CS_R_FD] = 0.0
    cs[d, CS_Q_PREV] = q
    cs[d, CS_W_MEAS] = 0.0
    cs[d, CS_INT_POS] = 0.0
    cs[d, CS_INT_SPD] = 0.0


def set_offset(cs: np.ndarray, d: int, offset: float) -> None:
    """Set drive d's encoder offset (rad); its setpoints and speed-estimate state move with it (no jump)."""
    shift = offset - cs[d, CS_OFFSET]
    cs[d, CS_OFFSET] = offset
    cs[d, CS_R_RAW] += shift
    cs[d, CS_R_F] += shift
    cs[d, CS_Q_PREV] += shift


def set_mode(cs: np.ndarray, cm: np.ndarray, d: int, mode: int, hold_q: float) -> None:
    """Switch drive d to `mode`; entering closed loop holds `hold_q` (its encoder angle now)."""
    if mode == MODE_CLOSED and cm[d] != MODE_CLOSED:
        hold(cs, d, hold_q)
    cm[d] = mode


def set_open_duty(cs: np.ndarray, cm: np.ndarray, d: int, duty: float) -> None:
    """Drive d open loop at a fixed duty (the step clips it to -1..1)."""
    cs[d, CS_OPEN_DUTY] = duty
    cm[d] = MODE_OPEN
