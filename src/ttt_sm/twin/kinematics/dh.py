"""The arm's Denavit-Hartenberg table and DH forward kinematics (thesis section 3.4).

The thesis writes the arm as a product of transforms (eqs. 3.17-3.21): the
base yaw ``q1`` about the column's axis, the shoulder ``L1`` above the board
and the sideways offset ``l_f``, then three pitch rotations ``q2, q3, q4``
about the same horizontal axis with links ``L2, L3, L4`` (the angles measured
from the downward vertical).  In the standard DH convention, link ``i`` is
``Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``, after a fixed base shift
``Tx(-l_f)`` (the column stands at ``x = -l_f``, eq. 3.20):

====  ==============  =======  =====  ==========
link  theta (rad)     d (m)    a (m)  alpha (rad)
====  ==============  =======  =====  ==========
1     q1 - pi/2       L1       0      -pi/2
2     q2 + pi/2       l_f      L2     0
3     q3              0        L3     0
4     q4              0        L4     0
====  ==============  =======  =====  ==========

Joint 1's ``-pi/2`` turns frame 1's x axis away from the arm plane so that
``z1`` is the pitch axis ``(cos q1, sin q1, 0)`` and ``y1`` points down; joint
2's ``+pi/2`` makes ``q2 = 0`` the hanging link.  Frame 4's origin is the pen
tip; :func:`dh_fk` equals :func:`~ttt_sm.twin.kinematics.chain.fk` (tests).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ttt_sm.params import Geometry

#: Column names of :func:`dh_table`'s rows.
DH_COLUMNS = ("theta_offset_rad", "d_m", "a_m", "alpha_rad")


def dh_table(geometry: Geometry) -> np.ndarray:
    """The DH table: per link ``(theta offset, d, a, alpha)``; ``theta_i = q_i + offset``.

    Parameters
    ----------
    geometry : Geometry
        Link lengths, m.

    Returns
    -------
    np.ndarray, shape (4, 4)
        Rows links 1..4, columns :data:`DH_COLUMNS` (rad, m, m, rad).
    """
    g = geometry
    h = math.pi / 2
    return np.array([[-h, g.L1, 0.0, -h],
                     [h, g.l_f, g.L2, 0.0],
                     [0.0, 0.0, g.L3, 0.0],
                     [0.0, 0.0, g.L4, 0.0]])


def dh_transform(theta: float, d: float, a: float, alpha: float) -> np.ndarray:
    """One link's homogeneous transform ``Rz(theta) Tz(d) Tx(a) Rx(alpha)`` (4x4)."""
    ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    return np.array([[ct, -st * ca, st * sa, a * ct],
                     [st, ct * ca, -ct * sa, a * st],
                     [0.0, sa, ca, d],
                     [0.0, 0.0, 0.0, 1.0]])


def dh_frames(q: Any, geometry: Geometry) -> list[np.ndarray]:
    """The frames 0..4 in the global frame for joint angles `q` (rad): five 4x4 transforms."""
    base = np.eye(4)
    base[0, 3] = -geometry.l_f
    frames = [base]
    for qi, (off, d, a, alpha) in zip([float(v) for v in q], dh_table(geometry), strict=True):
        frames.append(frames[-1] @ dh_transform(qi + off, d, a, alpha))
    return frames


def dh_fk(q: Any, geometry: Geometry) -> np.ndarray:
    """Forward kinematics through the DH table: ``[x, y, z, phi]`` (m, rad), as ``fk``.

    ``phi`` is the tilt of frame 4 about the pitch axis: ``q2 + q3 + q4``, read
    from frame 4's x axis (the last link's direction) against the downward vertical.
    """
    frames = dh_frames(q, geometry)
    T = frames[-1]
    z1 = frames[1][:3, 2]  # pitch axis
    x4 = T[:3, 0]
    down = np.array([0.0, 0.0, -1.0])
    horiz = np.cross(z1, down)  # the arm plane's outward direction
    phi = math.atan2(float(x4 @ horiz), float(x4 @ down))
    return np.array([T[0, 3], T[1, 3], T[2, 3], phi])
