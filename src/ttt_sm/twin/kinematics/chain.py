"""Forward kinematics of the RRRR arm: the tool pose for joint angles (thesis section 3.4).

The arm's chain of transforms (eqs. 3.17-3.25, corrected) is written once,
in :func:`arm_chain`, on plain numbers and compiled.  Everything that needs
forward kinematics is built on it:

* compiled code (the inverse kinematics' kernel) calls :func:`arm_chain`
  itself, inside its own compiled loop;
* plain Python that runs every chart step (the Control chart's tool pose,
  the whiteboard's pen and sponge) calls its Python original
  :data:`arm_chain_py`: from Python a numba call costs more in dispatch than
  the arithmetic;
* :func:`fk` is the documented entry point on arrays; :func:`arm_points`
  and :func:`link_points` give the points along the arm, the chain cut short.

:func:`jacobian` is eq. 3.30, the chain's derivative, which inverse
kinematics steps along.
"""

from __future__ import annotations

import math
from math import cos, sin
from typing import Any

import numba
import numpy as np

from ttt_sm.params import Geometry

#: Floats: (x, y, z, phi, sin q1, cos q1, sin phi, cos phi).
Chain = tuple[float, float, float, float, float, float, float, float]


@numba.njit(cache=True)
def arm_chain(q1: float, q2: float, q3: float, q4: float,
              L1: float, L2: float, L3: float, L4: float, l_f: float) -> Chain:
    """The tool pose for joint angles, with the rotations that make it (eqs. 3.17-3.25, corrected).

    The three pitch rotations about X add up (eq. 3.25), so in frame 1 the
    tool point is ``(l_f, r, -h)`` with ``r`` the reach in the arm plane and
    ``h`` the drop below the shoulder; the base yaw ``q1`` about Z and the
    shoulder's place ``(-l_f, 0, L1)`` (eq. 3.20) take it to the global
    frame.  docs/kinematics.md derives it.

    Parameters
    ----------
    q1, q2, q3, q4 : float
        Joint angles, rad.
    L1, L2, L3, L4, l_f : float
        Link lengths, m (:class:`~ttt_sm.params.Geometry`).

    Returns
    -------
    tuple of 8 floats
        ``(x, y, z, phi, s1, c1, s_phi, c_phi)``: the tool pose (m, rad) and
        the sines and cosines of ``q1`` and ``phi``, which give the tool's
        orientation: its axis towards the pen tip is
        ``(-s1 s_phi, c1 s_phi, -c_phi)``, the sponge's face normal
        ``(s1 c_phi, -c1 c_phi, -s_phi)``, the sideways offset ``l_f`` lies
        along ``(c1, s1, 0)``.
    """
    # sin and cos as bare names: the Python original runs every chart step, and a
    # global is one lookup where math.sin is two
    a23 = q2 + q3
    phi = a23 + q4
    s_phi = sin(phi)
    c_phi = cos(phi)
    r = L2 * sin(q2) + L3 * sin(a23) + L4 * s_phi  # reach in the arm plane
    h = L2 * cos(q2) + L3 * cos(a23) + L4 * c_phi  # drop below the shoulder
    s1 = sin(q1)
    c1 = cos(q1)
    return (l_f * c1 - r * s1 - l_f, l_f * s1 + r * c1, L1 - h, phi, s1, c1, s_phi, c_phi)


#: :func:`arm_chain` as plain Python (the same source), for plain-Python code that runs
#: every chart step: a numba call with nine float arguments costs several times the
#: arithmetic in dispatch.  With ``NUMBA_DISABLE_JIT=1`` it is :func:`arm_chain` itself.
arm_chain_py = getattr(arm_chain, "py_func", arm_chain)


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
    return np.array(arm_chain(q1, q2, q3, q4, g.L1, g.L2, g.L3, g.L4, g.l_f)[:4])


def arm_points(q: Any, geometry: Geometry) -> np.ndarray:
    """The points along the arm: the column's foot, the shoulder, the elbow, the wrist, the pen tip.

    Takes the arguments of :func:`fk`.

    Returns
    -------
    np.ndarray, shape (5, 3)
        Rows foot, shoulder, elbow (joint 3), wrist (the servo axis), tip;
        columns x, y, z (m).  The foot stands on the board's plane and the
        shoulder ``L1`` above it, on the base axis; the tip row equals
        ``fk(q)[:3]``.

    Notes
    -----
    The elbow and the wrist are :func:`arm_chain` cut short: with the links
    beyond them set to zero length, and without the tool's sideways offset
    ``l_f``, which the last transform (eq. 3.17) carries along frame 1's x
    axis ``(cos q1, sin q1, 0)``.
    """
    q1, q2, q3, q4 = (float(v) for v in q)
    g = geometry
    x, y, z, _, s1, c1, _, _ = arm_chain_py(q1, q2, q3, q4, g.L1, g.L2, g.L3, g.L4, g.l_f)
    x_e, y_e, z_e, _, _, _, _, _ = arm_chain_py(q1, q2, q3, q4, g.L1, g.L2, 0.0, 0.0, g.l_f)
    x_w, y_w, z_w, _, _, _, _, _ = arm_chain_py(q1, q2, q3, q4, g.L1, g.L2, g.L3, 0.0, g.l_f)
    dx, dy = g.l_f * c1, g.l_f * s1  # the tool's sideways offset
    return np.array([(-g.l_f, 0.0, 0.0), (-g.l_f, 0.0, g.L1), (x_e - dx, y_e - dy, z_e),
                     (x_w - dx, y_w - dy, z_w), (x, y, z)])


def link_points(q: Any, geometry: Geometry) -> np.ndarray:
    """Positions of the elbow (joint 3), the wrist (servo axis) and the pen tip.

    The moving rows of :func:`arm_points` (same arguments), shape (3, 3): rows
    elbow, wrist, tip; columns x, y, z (m).  The tip row equals ``fk(q)[:3]``.
    Used to keep the whole arm, not only the pen, out of a zone.
    """
    return arm_points(q, geometry)[2:]


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
