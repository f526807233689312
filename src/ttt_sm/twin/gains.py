"""The cascade controllers of the DC drives (thesis section 3.2, fig. 3.6): their data.

Per DC drive: a second-order setpoint filter (cut-off switched by ``fr_sw``),
an outer position PID whose output, the speed setpoint, is clamped to what
the drive can do, an inner speed PID whose output is the PWM duty, and a
speed estimate from the filtered derivative of the encoder angle.  The loops
themselves run in the controller's compiled step (``_cascade.cascade_step``,
held by :class:`ttt_sm.twin.cascade.CascadeController`); this module holds
their gains (:class:`Gains`, computed by :func:`ttt_sm.twin.tuning.design_gains`)
and the pure functions that turn parameters into filter coefficients, so that
the controller step and the tuning model use the very same numbers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.linalg import expm

from ..params import ArmParams, ControlParams, DriveParams

#: The speed setpoint is clamped to this fraction of the drive's no-load
#: speed at full supply, leaving duty headroom for acceleration, gravity and
#: friction (with the whole supply spent on back-EMF the loop could not
#: correct anything).
MAX_SPEED_FRACTION = 0.85

#: Damping ratio of the setpoint filters: critically damped, so a filtered
#: step never overshoots (a drawing arm must not overshoot its strokes).
SETPOINT_FILTER_ZETA = 1.0


@dataclass(frozen=True)
class DriveGains:
    """Gains of one drive's cascade and the margins of its two loops.

    Units: the outer loop maps a joint angle error (rad) to a speed setpoint
    (rad/s): ``kp_pos`` 1/s, ``ki_pos`` 1/s^2, ``kd_pos`` dimensionless; the
    inner loop maps a joint speed error (rad/s) to a PWM duty (-1..1):
    ``kp_speed`` s/rad, ``ki_speed`` 1/rad, ``kd_speed`` s^2/rad.
    ``kff_speed`` multiplies the setpoint filter's derivative, fed forward
    into the speed setpoint.  Margins are of the sampled loops with the ZOH,
    the one-sample computation delay and the speed filter (tuning.py).
    """

    kp_pos: float
    ki_pos: float
    kd_pos: float
    kff_speed: float
    max_speed_rad_s: float
    kp_speed: float
    ki_speed: float
    kd_speed: float
    inner_crossover_hz: float
    inner_phase_margin_deg: float
    inner_gain_margin_db: float
    outer_crossover_hz: float
    outer_phase_margin_deg: float
    outer_gain_margin_db: float


@dataclass(frozen=True)
class Gains:
    """The gains of the three DC drives (index 0 is drive 1)."""

    drives: tuple[DriveGains, DriveGains, DriveGains]

    def drive(self, number: int) -> DriveGains:
        """Gains of drive `number` (1, 2 or 3, as in the thesis)."""
        return self.drives[check_drive(number) - 1]


class DriveNumberError(ValueError):
    """A drive number outside 1..3 (drives are numbered as in the thesis)."""


def check_drive(number: int) -> int:
    """Return `number` if it names a DC drive (1, 2 or 3), else raise DriveNumberError."""
    if not isinstance(number, (int, np.integer)) or isinstance(number, bool) or not 1 <= number <= 3:
        raise DriveNumberError(f"drive must be 1, 2 or 3 (thesis numbering), got {number!r}")
    return int(number)


def max_joint_speed(drive: DriveParams) -> float:
    """Speed setpoint clamp of a drive, joint rad/s (MAX_SPEED_FRACTION of no-load speed)."""
    return MAX_SPEED_FRACTION * drive.supply_v / (drive.torque_constant * drive.gear_ratio)


def speed_filter_alpha(control: ControlParams) -> float:
    """Gain of the first-order speed filter ``w += alpha (w_raw - w)`` per control step."""
    return 1.0 - math.exp(-2.0 * math.pi * control.speed_filter_hz * control.dt)


def setpoint_filter_matrices(cutoff_hz: float, dt: float,
                             zeta: float = SETPOINT_FILTER_ZETA) -> tuple[np.ndarray, np.ndarray]:
    """Exact (ZOH) discretisation of the second-order setpoint filter.

    The filter ``r'' = w^2 (u - r) - 2 zeta w r'`` with ``w = 2 pi cutoff_hz``
    has the state ``[r, r']``; returns ``(Ad, Bd)`` with shapes (2, 2) and
    (2,), so that ``x[k+1] = Ad x[k] + Bd u[k]``.  Its DC gain is 1, and
    because the state is an angle and a rate, switching the cut-off between
    steps (``fr_sw``) is bumpless.
    """
    w = 2.0 * math.pi * cutoff_hz
    a = np.array([[0.0, 1.0, 0.0], [-w * w, -2.0 * zeta * w, w * w], [0.0, 0.0, 0.0]])
    e = expm(a * dt)
    return e[:2, :2].copy(), e[:2, 2].copy()


def setpoint_filter_row(cutoff_hz: float, dt: float) -> np.ndarray:
    """The six coefficients ``a11 a12 b1 a21 a22 b2`` the controller step reads (``CG_SF_*``)."""
    ad, bd = setpoint_filter_matrices(cutoff_hz, dt)
    return np.array([ad[0, 0], ad[0, 1], bd[0], ad[1, 0], ad[1, 1], bd[1]])


def filter_cutoff_hz(params: ArmParams, fr_sw: bool) -> float:
    """Cut-off of the setpoint filters: the slow one while `fr_sw` asks for slow moves."""
    c = params.control
    return c.setpoint_cutoff_slow_hz if fr_sw else c.setpoint_cutoff_hz


__all__ = [
    "MAX_SPEED_FRACTION", "SETPOINT_FILTER_ZETA", "DriveGains", "Gains", "DriveNumberError",
    "check_drive", "max_joint_speed", "speed_filter_alpha", "setpoint_filter_matrices",
    "setpoint_filter_row", "filter_cutoff_hz", "THESIS_SAFETY", "preset_params",
]


#: The Safety chart's thresholds the "thesis" preset needs at least: its loops answer a command later
#: (a stall would read after 30 ms) and trail a moving setpoint further (docs/tuning.md).
THESIS_SAFETY = {"silent_s": 0.2, "max_following_error_rad": 0.08}


def preset_params(params: ArmParams) -> ArmParams:
    """`params` with what the file's tuning preset needs of the rest: the "thesis" preset's slower loops
    need a longer stall window and a wider following error in the Safety chart (:data:`THESIS_SAFETY`),
    and the thesis fed no gear play forward (``gear_play_compensation = 0``)."""
    if params.tuning.preset != "thesis":
        return params
    s = params.safety
    wider = {k: max(v, getattr(s, k)) for k, v in THESIS_SAFETY.items()}
    return replace(params, safety=replace(s, **wider), control=replace(params.control, gear_play_compensation=0.0))
