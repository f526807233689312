"""Inverse kinematics in closed form: the oracle the tests hold the solver to (thesis section 3.4)."""

from __future__ import annotations

import math
from typing import Any

import numba
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
    q1, q2, q3, q4, why, shortfall = closed_form_q_py(x, y, z, phi, g.L1, g.L2, g.L3, g.L4, g.l_f, elbow_up)
    if why == CLOSER_THAN_LF:
        raise UnreachableTargetError(target, shortfall, f"closer than l_f = {g.l_f} m to the base axis")
    if why == OUTSIDE_ANNULUS:
        raise UnreachableTargetError(target, shortfall, "outside the reach of links L2, L3")
    return np.array([wrap_angle_py(q1), q2, q3, q4])


#: Why :func:`closed_form_q` found no solution (its fifth result): none, the target is closer than ``l_f``
#: to the base axis, or the servo axis lies outside the annulus links L2, L3 reach.
REACHED, CLOSER_THAN_LF, OUTSIDE_ANNULUS = 0, 1, 2


@numba.njit(cache=True)
def closed_form_q(x: float, y: float, z: float, phi: float, L1: float, L2: float, L3: float, L4: float,
                  l_f: float, elbow_up: bool) -> tuple[float, float, float, float, int, float]:
    """The closed form, once for every caller: ``(q1, q2, q3, q4, why, shortfall)``.

    q1..q4 in rad (q1 not wrapped: :func:`wrap_angle`) and ``why`` :data:`REACHED`; or NaN angles,
    ``why`` :data:`CLOSER_THAN_LF` or :data:`OUTSIDE_ANNULUS` and the shortfall
    in metres.  Compiled for a grid of targets (:func:`~.workspace.solve_grid`);
    :data:`closed_form_q_py` is the same function in plain Python, for one target
    (:func:`ik_closed_form`, :func:`solve_point`: a call into compiled code costs
    more than these few lines).
    """
    nan = math.nan
    u, v = x + l_f, y  # from the base axis
    r_sq = u * u + v * v - l_f * l_f
    if not r_sq >= 0.0:
        return nan, nan, nan, nan, CLOSER_THAN_LF, l_f - math.hypot(u, v)
    r = math.sqrt(r_sq)
    q1 = math.atan2(v, u) - math.atan2(r, l_f)  # in (-2 pi, 2 pi): wrap_angle puts it in (-pi, pi]
    r_w = r - L4 * math.sin(phi)  # servo axis, in the arm plane
    h_w = (L1 - z) - L4 * math.cos(phi)
    dist = math.hypot(r_w, h_w)
    if not (abs(L2 - L3) <= dist <= L2 + L3):
        return nan, nan, nan, nan, OUTSIDE_ANNULUS, max(dist - (L2 + L3), abs(L2 - L3) - dist)
    c3 = (dist * dist - L2 * L2 - L3 * L3) / (2.0 * L2 * L3)
    q3 = math.acos(min(1.0, max(-1.0, c3)))
    if elbow_up:
        q3 = -q3
    q2 = math.atan2(r_w, h_w) - math.atan2(L3 * math.sin(q3), L2 + L3 * math.cos(q3))
    return q1, q2, q3, phi - q2 - q3, REACHED, 0.0


closed_form_q_py = getattr(closed_form_q, "py_func", closed_form_q)


@numba.njit(cache=True)
def wrap_angle(a: float) -> float:
    """`a` (rad) as the same angle in (-pi, pi]."""
    return math.atan2(math.sin(a), math.cos(a))


wrap_angle_py = getattr(wrap_angle, "py_func", wrap_angle)


def solve_point(x: float, y: float, z: float, phi: float, geometry: Geometry,
                elbow_up: bool = True) -> tuple[float, float, float, float] | None:
    """:func:`ik_closed_form` on plain floats: q1..q4 (rad), or None where out of reach.

    No arrays and no exceptions, for the IK race's timing (``ttt-sm bench`` section ``ik_race``);
    q1 is not wrapped (the same angle as :func:`ik_closed_form`'s, which is in (-pi, pi]).
    """
    g = geometry
    q1, q2, q3, q4, why, _ = closed_form_q_py(x, y, z, phi, g.L1, g.L2, g.L3, g.L4, g.l_f, elbow_up)
    return None if why != REACHED else (q1, q2, q3, q4)
