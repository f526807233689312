"""Inverse kinematics in closed form: the oracle the tests hold the solver to (thesis section 3.4)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ttt_sm.params import Geometry

from .errors import UnreachableTargetError, _as_vector


def ik_closed_form(target: Any, geometry: Geometry, elbow_up: bool = True) -> np.ndarray:
    """Joint angles for a pose, solved geometrically (the oracle for tests).

    With phi given, the arm decouples: the tool lies in the arm plane at the
    distance ``l_f`` from the base axis, so the distance ``d`` of the target
    from that axis gives the reach ``r = sqrt(d^2 - l_f^2)`` (taken >= 0, the
    arm in front of the base) and q1; stepping back ``L4`` along phi gives the
    servo axis, which a planar two-link arm (L2, L3) reaches with q2, q3.

    Parameters
    ----------
    target : array_like, shape (4,)
        ``[x, y, z, phi]`` in m and rad.
    geometry : Geometry
        Link lengths, m.
    elbow_up : bool
        True picks q3 <= 0 (the working configuration), False q3 >= 0.

    Returns
    -------
    np.ndarray, shape (4,)
        q1..q4 in rad, q1 in (-pi, pi]; joint limits are not checked.

    Raises
    ------
    NonFiniteTargetError
        The target holds NaN or infinity.
    UnreachableTargetError
        The target is closer than ``l_f`` to the base axis, or the servo axis
        lies outside the annulus the two links reach; ``residual`` is that
        shortfall in metres.
    """
    # Python floats: a huge target overflows to inf quietly (and is unreachable), numpy's would warn
    x, y, z, phi = (float(c) for c in _as_vector(target, "target"))
    g = geometry
    u, v = x + g.l_f, y  # from the base axis
    r_sq = u * u + v * v - g.l_f**2
    if r_sq < 0.0:
        raise UnreachableTargetError(target, g.l_f - math.hypot(u, v),
                                     f"closer than l_f = {g.l_f} m to the base axis")
    r = math.sqrt(r_sq)
    q1 = math.atan2(v, u) - math.atan2(r, g.l_f)
    q1 = math.atan2(math.sin(q1), math.cos(q1))
    r_w = r - g.L4 * math.sin(phi)  # servo axis, in the arm plane
    h_w = (g.L1 - z) - g.L4 * math.cos(phi)
    dist = math.hypot(r_w, h_w)
    if dist > g.L2 + g.L3 or dist < abs(g.L2 - g.L3):
        shortfall = max(dist - (g.L2 + g.L3), abs(g.L2 - g.L3) - dist)
        raise UnreachableTargetError(target, shortfall, "outside the reach of links L2, L3")
    c3 = (dist**2 - g.L2**2 - g.L3**2) / (2.0 * g.L2 * g.L3)
    q3 = math.acos(min(1.0, max(-1.0, c3)))
    if elbow_up:
        q3 = -q3
    q2 = math.atan2(r_w, h_w) - math.atan2(g.L3 * math.sin(q3), g.L2 + g.L3 * math.cos(q3))
    return np.array([q1, q2, q3, phi - q2 - q3])
