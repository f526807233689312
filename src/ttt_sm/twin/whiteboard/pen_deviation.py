"""The pen's largest deviation in its holder, computed as thesis section 3.3.2 does (eqs. 3.1-3.13).

The pen (radius ``L3``) sits in the holder's bore (radius ``L2``) of length
``L1`` with a small clearance; tilted until it touches the bore at both
ends, its axis turns by ``alpha`` about the holder's middle (fig. 3.11):

    (L1 / 2) sin(alpha) = L2 cos(alpha) - L3                   (eq. 3.4)

and the tip, ``tip_beyond`` past the holder's end, moves sideways by

    L_s = (L1 / 2 + tip_beyond) sin(alpha)                      (eq. 3.13)

Squaring eq. 3.4 gives a quadratic in ``sin(alpha)``, which
:func:`pen_deviation` solves exactly:

    (L1^2 + 4 L2^2) sin^2(alpha) + 4 L1 L3 sin(alpha) + 4 (L3^2 - L2^2) = 0

The printed derivation carries two typos (docs/whiteboard.md): eq. 3.6
squares ``L1 sin(alpha) - 2 L3`` where eq. 3.5 gives ``+ 2 L3``, and eq. 3.8
(then 3.10) has ``4 L3^2`` where ``4 L2^2`` belongs.  Both are harmless
numerically (``L2 - L3`` is a fraction of a millimetre):
:func:`pen_deviation` also solves eq. 3.10 as printed (small angle) and
reports it.

Fig. 3.11's dimensions are not in the text.  :data:`THESIS_HOLDER` is the
holder that gives the thesis' two printed results, alpha = 6.179e-3 rad
(eq. 3.11) and L_s = 0.35 mm (eq. 3.13), with a pen of 4 mm radius
(assumed): eq. 3.13 fixes ``L1`` = 53.29 mm, eq. 3.4 then the radial
clearance ``L2 - L3`` = 0.165 mm, a diametral clearance of 0.33 mm where
section 3.3.1 says "around 0.4 mm".
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class PenHolder:
    """The pen in its holder (fig. 3.11), m: the bore's length and radius, the pen's radius, the tip's reach."""

    length_m: float  # L1
    bore_radius_m: float  # L2
    pen_radius_m: float  # L3
    tip_beyond_m: float = 0.030  # the 30 mm of eq. 3.13


@dataclass(frozen=True)
class PenDeviation:
    """The largest tilt of the pen in its holder and the deviation of its tip."""

    alpha_rad: float  # eq. 3.8 corrected, solved exactly
    alpha_eq_3_10_rad: float  # eq. 3.10 as printed (small angle, L3 for L2)
    deviation_m: float  # L_s, eq. 3.13 with the exact alpha


#: The holder that reproduces the thesis' eqs. 3.11 and 3.13 (back-solved; the pen's radius assumed).
THESIS_HOLDER = PenHolder(length_m=53.287660521e-3, bore_radius_m=4.1647106837e-3, pen_radius_m=4.0e-3)
#: The clearance section 3.3.1 names for that holder, m.
THESIS_CLEARANCE_M = 0.4e-3


def _positive_root(a: float, b: float, c: float) -> float:
    disc = b * b - 4 * a * c
    if disc < 0:
        raise ValueError("the pen does not fit its holder: no tilt satisfies eq. 3.4")
    return (-b + math.sqrt(disc)) / (2 * a)


def pen_deviation(holder: PenHolder) -> PenDeviation:
    """The pen's largest tilt in `holder` and its tip's deviation (eqs. 3.1-3.13).

    Raises ValueError for a pen wider than its bore (no clearance, no tilt).
    """
    L1, L2, L3 = holder.length_m, holder.bore_radius_m, holder.pen_radius_m
    if not 0 < L3 < L2 or not L1 > 0:
        raise ValueError(f"the pen (radius {L3 * 1e3:g} mm) must be narrower than the bore (radius {L2 * 1e3:g} mm)"
                         f" of a holder of positive length ({L1 * 1e3:g} mm)")
    s = _positive_root(L1 * L1 + 4 * L2 * L2, 4 * L1 * L3, 4 * (L3 * L3 - L2 * L2))
    small = _positive_root(L1 * L1 + 4 * L3 * L3, 4 * L1 * L3, 4 * (L3 * L3 - L2 * L2))
    return PenDeviation(alpha_rad=math.asin(s), alpha_eq_3_10_rad=small,
                        deviation_m=(L1 / 2 + holder.tip_beyond_m) * s)


__all__ = ["PenHolder", "PenDeviation", "THESIS_HOLDER", "THESIS_CLEARANCE_M", "pen_deviation"]
