"""Forward kinematics of the RRRR arm: the tool pose for joint angles (thesis section 3.4).

* :func:`fk` is eqs. 3.22-3.25 (corrected, docs/kinematics.md), on top of
  the compiled plain-number :data:`fk_floats` that hot loops call;
* :func:`link_points` gives the elbow, the wrist and the tip;
* :func:`jacobian` is eq. 3.30, the derivative inverse kinematics steps along.
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

from ttt_sm.params import Geometry


@numba.njit(cache=True)
def _fk_floats(q1: float, q2: float, q3: float, q4: float,
               L1: float, L2: float, L3: float, L4: float, l_f: float
               ) -> tuple[float, float, float, float]:
    """Tool pose (x, y, z, phi) for joint angles: eqs. 3.22-3.25, corrected."""
    r = L2 * math.sin(q2) + L3 * math.sin(q2 + q3) + L4 * math.sin(q2 + q3 + q4)  # reach in the arm plane
    h = L2 * math.cos(q2) + L3 * math.cos(q2 + q3) + L4 * math.cos(q2 + q3 + q4)  # drop below the shoulder
    s1 = math.sin(q1)
    c1 = math.cos(q1)
    return (l_f * c1 - r * s1 - l_f, l_f * s1 + r * c1, L1 - h, q2 + q3 + q4)


@numba.njit(cache=True)
def _jacobian_into(J: np.ndarray, q1: float, q2: float, q3: float, q4: float,
                   L2: float, L3: float, L4: float, l_f: float) -> None:
    """Fill the 4x4 array `J` with d(x, y, z, phi)/dq (eq. 3.30)."""
    s2, c2 = math.sin(q2), math.cos(q2)
    s23, c23 = math.sin(q2 + q3), math.cos(q2 + q3)
    s234, c234 = math.sin(q2 + q3 + q4), math.cos(q2 + q3 + q4)
    r = L2 * s2 + L3 * s23 + L4 * s234
    s1, c1 = math.sin(q1), math.cos(q1)
    # dr/dq_j (j = 2, 3, 4) and dh/dq_j; r and h depend on q2..q4 only.
    dr2, dr3, dr4 = L2 * c2 + L3 * c23 + L4 * c234, L3 * c23 + L4 * c234, L4 * c234
    dh2, dh3, dh4 = -r, -(L3 * s23 + L4 * s234), -L4 * s234
    # x = l_f c1 - r s1 - l_f
    J[0, 0], J[0, 1], J[0, 2], J[0, 3] = -l_f * s1 - r * c1, -s1 * dr2, -s1 * dr3, -s1 * dr4
    # y = l_f s1 + r c1
    J[1, 0], J[1, 1], J[1, 2], J[1, 3] = l_f * c1 - r * s1, c1 * dr2, c1 * dr3, c1 * dr4
    # z = L1 - h
    J[2, 0], J[2, 1], J[2, 2], J[2, 3] = 0.0, -dh2, -dh3, -dh4
    # phi = q2 + q3 + q4
    J[3, 0], J[3, 1], J[3, 2], J[3, 3] = 0.0, 1.0, 1.0, 1.0


#: Forward kinematics on plain floats, compiled: (q1..q4, L1, L2, L3, L4, l_f) -> (x, y, z, phi).
#: For hot loops; :func:`fk` is the documented entry point.
fk_floats = _fk_floats


def fk(q: Any, geometry: Geometry) -> np.ndarray:
    """Forward kinematics: the tool pose for joint angles (eqs. 3.21-3.25).

    Parameters
    ----------
    q : array_like, shape (4,)
        Joint angles q1..q4, rad.
    geometry : Geometry
        Link lengths, m.

    Returns
    -------
    np.ndarray, shape (4,)
        ``[x, y, z, phi]``: pen tip position (m) and tilt about the global
        X axis (rad), ``phi = q2 + q3 + q4``.
    """
    q1, q2, q3, q4 = (float(v) for v in q)
    g = geometry
    return np.array(_fk_floats(q1, q2, q3, q4, g.L1, g.L2, g.L3, g.L4, g.l_f))


def link_points(q: Any, geometry: Geometry) -> np.ndarray:
    """Positions of the elbow (joint 3), the wrist (servo axis) and the pen tip.

    Parameters
    ----------
    q : array_like, shape (4,)
        Joint angles q1..q4, rad.
    geometry : Geometry
        Link lengths, m.

    Returns
    -------
    np.ndarray, shape (3, 3)
        Rows elbow, wrist, tip; columns x, y, z (m).  The tip row equals
        ``fk(q)[:3]``.  Used to keep the whole arm, not only the pen, out of
        a zone.
    """
    q1, q2, q3, q4 = (float(v) for v in q)
    g = geometry
    c1, s1 = math.cos(q1), math.sin(q1)
    # points in frame 1 (x1 across the arm plane, y1 out along it, z1 up), eqs. 3.18-3.19
    y_e, z_e = g.L2 * math.sin(q2), -g.L2 * math.cos(q2)
    y_w, z_w = y_e + g.L3 * math.sin(q2 + q3), z_e - g.L3 * math.cos(q2 + q3)
    y_t, z_t = y_w + g.L4 * math.sin(q2 + q3 + q4), z_w - g.L4 * math.cos(q2 + q3 + q4)
    frame1 = ((0.0, y_e, z_e), (0.0, y_w, z_w), (g.l_f, y_t, z_t))
    # frame 1 to the global frame: eq. 3.20 (rotation q1 about Z, origin at (-l_f, 0, L1))
    return np.array([(c1 * x - s1 * y - g.l_f, s1 * x + c1 * y, g.L1 + z) for x, y, z in frame1])


def jacobian(q: Any, geometry: Geometry) -> np.ndarray:
    """Analytic Jacobian d[x, y, z, phi]/dq of :func:`fk` (eq. 3.30).

    Parameters
    ----------
    q : array_like, shape (4,)
        Joint angles, rad.
    geometry : Geometry
        Link lengths, m.

    Returns
    -------
    np.ndarray, shape (4, 4)
        Row i, column j is d(X_i)/d(q_j): m/rad for rows x, y, z, 1 for phi.
        Its determinant is ``-r L2 L3 sin q3`` (``r`` the reach in the arm
        plane), so it is singular with the elbow straight or with ``r = 0``.
    """
    q1, q2, q3, q4 = (float(v) for v in q)
    g = geometry
    J = np.empty((4, 4))
    _jacobian_into(J, q1, q2, q3, q4, g.L2, g.L3, g.L4, g.l_f)
    return J
