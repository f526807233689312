"""Forward and inverse kinematics of the RRRR arm (thesis section 3.4).

The pose of the tool is ``X = [x, y, z, phi]``: the pen tip in the global
frame (metres; the board surface is z = 0, the base axis is the vertical line
x = -l_f, y = 0) and its tilt phi about the global X axis (radians; 0 points
the pen straight down, pi/2 turns the tool horizontal so the sponge on its
side faces the board).  Joint angles are ``q = [q1, q2, q3, q4]`` (radians):
base yaw, shoulder pitch, elbow pitch, pen servo; q = 0 hangs the arm straight
down.  docs/kinematics.md derives the equations and lists the thesis' typos.

* :func:`fk` and :func:`jacobian` are eqs. 3.22-3.25 and 3.30 (corrected).
* :func:`ik_closed_form` solves the inverse problem geometrically; it is the
  test oracle, not what the arm runs.
* :func:`damped_least_squares` is the thesis' iterative solver (eq. 3.35),
  with adaptive damping and a step limit that keep it converging from and
  near singular poses.
* :class:`IKSolver` wraps it for a control loop: warm start from the last
  solution, joint limits, and specific errors instead of wrong answers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numba
import numpy as np

from ttt_sm.params import ArmParams, Geometry, IKParams

#: Documented home pose (rad): elbow up, the pen 5 cm above the field centre
#: of the default arm.  Cold solves start here.
HOME_Q: tuple[float, float, float, float] = (0.0, math.radians(100.0), math.radians(-90.0),
                                             math.radians(-10.0))

# Bounds of the adaptive damping mu = lambda^2.  Below _MU_MIN the 4x4 system
# of eq. 3.35 stops being safely positive definite at an exact singularity;
# above _MU_MAX no step can lower the error any more: the target is a local
# minimum of |e| that is not a solution (unreachable), so the search stops.
_MU_MIN = 1e-14
_MU_MAX = 1e6

# Longest step of one joint in one iteration (rad).  A Newton step from far
# away can leave the region where the linear model means anything and wind a
# joint through a full turn, or into the other elbow configuration.
_MAX_STEP_RAD = 1.0

# Angle slack when comparing with joint limits (rad), against round-off.
_LIMIT_SLACK = 1e-9


# --------------------------------------------------------------------------- errors

class IKError(ValueError):
    """The inverse kinematics could not give joint angles for a target."""


class NonFiniteTargetError(IKError):
    """A target (or start pose) holds NaN or infinity."""

    def __init__(self, what: str, values: Any) -> None:
        self.values = values
        super().__init__(f"{what} must be finite, got {list(values)}; check the chart outputs")


def _pose_text(target: tuple[float, ...]) -> str:
    """``x=... m, y=... m, z=... m, phi=... deg``; a huge value in powers of ten, not 300 digits."""
    x, y, z, phi = target

    def num(v: float, places: int) -> str:
        return f"{v:.{places}f}" if abs(v) < 1e6 else f"{v:.4g}"
    return f"x={num(x, 4)} m, y={num(y, 4)} m, z={num(z, 4)} m, phi={num(math.degrees(phi), 1)} deg"


class UnreachableTargetError(IKError):
    """No joint angles reach a target: it lies outside the workspace.

    ``target`` is the pose asked for, ``residual`` the smallest error |e| found
    (m and rad mixed, as in eq. 3.33).
    """

    def __init__(self, target: Any, residual: float, detail: str = "") -> None:
        self.target = tuple(float(v) for v in target)
        self.residual = float(residual)
        super().__init__(
            f"target {_pose_text(self.target)} is "
            f"unreachable: best residual {self.residual:.3g}{'; ' + detail if detail else ''}; "
            f"move it towards the field or check the geometry in the parameter file")


class JointLimitError(IKError):
    """The only solution found puts a joint outside its limits."""

    def __init__(self, target: Any, joint: int, angle: float, lo: float, hi: float) -> None:
        self.target = tuple(float(v) for v in target)
        self.joint = joint
        self.angle = float(angle)
        super().__init__(
            f"target {_pose_text(self.target)} needs "
            f"q{joint} = {math.degrees(angle):.1f} deg, outside its limits "
            f"[{math.degrees(lo):.1f}, {math.degrees(hi):.1f}] deg")


@dataclass(frozen=True, eq=False)  # eq on arrays is ambiguous; compare .q with numpy
class IKResult:
    """Outcome of one inverse kinematics solve.

    Attributes
    ----------
    q : np.ndarray, shape (4,)
        Joint angles q1..q4 (rad), read-only.
    iterations : int
        Steps of eq. 3.35 taken (rejected trial steps included).
    residual : float
        Final |x_desired - fk(q)| (m and rad mixed, as in eq. 3.33).
    converged : bool
        Whether ``residual`` is within the tolerance.
    """

    q: np.ndarray
    iterations: int
    residual: float
    converged: bool


# --------------------------------------------------------------------------- forward kinematics

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


def _as_shape4(values: Any, what: str) -> np.ndarray:
    """`values` as a float vector of shape (4,), not yet checked for NaN."""
    try:
        v = np.asarray(values, dtype=float)
    except (TypeError, ValueError, OverflowError):  # text, None, an integer beyond floats
        shown = repr(values) if len(repr(values)) <= 60 else repr(values)[:60] + "..."
        raise IKError(f"{what} must be 4 numbers, got {shown}") from None
    if v.shape != (4,):
        raise IKError(f"{what} must have 4 values, got shape {v.shape}")
    return v


def _as_vector(values: Any, what: str) -> np.ndarray:
    """`values` as a finite float vector of shape (4,)."""
    v = _as_shape4(values, what)
    if not np.isfinite(v).all():
        raise NonFiniteTargetError(what, v)
    return v


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


# --------------------------------------------------------------------------- closed form (test oracle)

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
    x, y, z, phi = _as_vector(target, "target")
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


# --------------------------------------------------------------------------- damped least squares

@numba.njit(cache=True)
def _solve_spd4(A: np.ndarray, b: np.ndarray, out: np.ndarray) -> bool:
    """Solve ``A out = b`` for a symmetric positive definite 4x4 `A` (Cholesky).

    `A` is overwritten by its factor.  Returns False when a pivot is not
    positive (round-off at an exact singularity), leaving `out` undefined.
    """
    n = 4
    for j in range(n):  # A = L L^T, L stored in the lower triangle of A
        d = A[j, j]
        for k in range(j):
            d -= A[j, k] * A[j, k]
        if not d > 0.0:
            return False
        d = math.sqrt(d)
        A[j, j] = d
        for i in range(j + 1, n):
            s = A[i, j]
            for k in range(j):
                s -= A[i, k] * A[j, k]
            A[i, j] = s / d
    for i in range(n):  # L w = b
        s = b[i]
        for k in range(i):
            s -= A[i, k] * out[k]
        out[i] = s / A[i, i]
    for i in range(n - 1, -1, -1):  # L^T out = w
        s = out[i]
        for k in range(i + 1, n):
            s -= A[k, i] * out[k]
        out[i] = s / A[i, i]
    return True


@numba.njit(cache=True)
def _dls_kernel(target: np.ndarray, q0: np.ndarray, geom: np.ndarray, damping: float,
                tolerance: float, max_iterations: int, adaptive: bool
                ) -> tuple[np.ndarray, int, float]:
    """Levenberg-Marquardt damped least squares, eq. 3.35.

    Repeats ``dq = J^T (J J^T + lambda^2 I)^-1 e`` with ``e = target - fk(q)``
    (eqs. 3.31-3.33) until ``|e| <= tolerance`` or `max_iterations` steps.

    With ``adaptive`` False this is the thesis' loop: lambda fixed, every step
    taken.  With ``adaptive`` True, lambda starts at `damping` and follows the
    gain ratio rho = (actual drop of |e|^2) / (drop the linearised model
    promised), as in Nielsen's Levenberg-Marquardt: a step that lowers |e| is
    kept and lambda^2 shrinks (by up to 3x); one that does not is undone and
    lambda^2 grows (2x, 4x, 8x, ...).  No joint moves more than
    ``_MAX_STEP_RAD`` in one step.  Why: next to a singular pose the fixed
    step ``sigma e / (sigma^2 + lambda^2)`` is either huge (sigma ~ lambda:
    about e / (2 lambda), hundreds of radians) or tiny (sigma << lambda: the
    error then falls only like 1/k); docs/kinematics.md has the numbers.

    Returns ``(q, iterations, residual)``; ``residual = |e|`` at `q`, NaN
    when `target` or `q0` is not finite.
    """
    L1, L2, L3, L4, l_f = geom[0], geom[1], geom[2], geom[3], geom[4]
    q = q0.copy()
    for i in range(4):
        if not (math.isfinite(target[i]) and math.isfinite(q0[i])):
            return q, 0, math.nan  # the caller names what was not finite
    e = np.empty(4)
    pose = _fk_floats(q[0], q[1], q[2], q[3], L1, L2, L3, L4, l_f)
    for i in range(4):
        e[i] = target[i] - pose[i]
    err_sq = e[0] ** 2 + e[1] ** 2 + e[2] ** 2 + e[3] ** 2

    J = np.empty((4, 4))
    A = np.empty((4, 4))
    w = np.empty(4)
    dq = np.empty(4)
    q_new = np.empty(4)
    e_new = np.empty(4)
    mu = damping * damping  # lambda^2
    nu = 2.0  # growth factor of mu after a rejected step
    iterations = 0
    need_jacobian = True
    while err_sq > tolerance * tolerance and iterations < max_iterations:
        iterations += 1
        if need_jacobian:
            _jacobian_into(J, q[0], q[1], q[2], q[3], L2, L3, L4, l_f)
        # A = J J^T + lambda^2 I, then dq = J^T A^-1 e   (eq. 3.35)
        for i in range(4):
            for j in range(4):
                A[i, j] = J[i, 0] * J[j, 0] + J[i, 1] * J[j, 1] + J[i, 2] * J[j, 2] + J[i, 3] * J[j, 3]
            A[i, i] += mu
        if not _solve_spd4(A, e, w):  # round-off made A indefinite: damp harder
            if not adaptive:
                break
            mu *= nu
            nu *= 2.0
            need_jacobian = False
            continue
        largest = 0.0
        for k in range(4):
            dq[k] = J[0, k] * w[0] + J[1, k] * w[1] + J[2, k] * w[2] + J[3, k] * w[3]
            largest = max(largest, abs(dq[k]))
        if adaptive and largest > _MAX_STEP_RAD:
            for k in range(4):
                dq[k] *= _MAX_STEP_RAD / largest
        for k in range(4):
            q_new[k] = q[k] + dq[k]
        pose = _fk_floats(q_new[0], q_new[1], q_new[2], q_new[3], L1, L2, L3, L4, l_f)
        for i in range(4):
            e_new[i] = target[i] - pose[i]
        err_new_sq = e_new[0] ** 2 + e_new[1] ** 2 + e_new[2] ** 2 + e_new[3] ** 2

        if adaptive:
            # What the linear model e - J dq promised: |e|^2 - |e - J dq|^2.
            promised = 0.0
            for i in range(4):
                model = e[i] - (J[i, 0] * dq[0] + J[i, 1] * dq[1] + J[i, 2] * dq[2] + J[i, 3] * dq[3])
                promised += e[i] * e[i] - model * model
            rho = (err_sq - err_new_sq) / promised if promised > 0.0 else -1.0
            if rho <= 0.0:  # worse: undo the step, damp harder, same J
                mu *= nu
                nu *= 2.0
                need_jacobian = False
                if mu > _MU_MAX:
                    break
                continue
            mu = max(_MU_MIN, mu * max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3))
            nu = 2.0
        for k in range(4):
            q[k] = q_new[k]
            e[k] = e_new[k]
        err_sq = err_new_sq
        need_jacobian = True
    return q, iterations, math.sqrt(err_sq)


@numba.njit(cache=True)
def _unwind(q: np.ndarray, q_min: np.ndarray, q_max: np.ndarray) -> int:
    """Unwind `q` in place; return the first joint (1..4) outside its limits, or 0.

    q1, q2 and q3 are taken into [-pi, pi]; a whole turn taken off q2 or q3 is
    given to q4, so that phi = q2 + q3 + q4 stays what was asked for.
    """
    for j in range(3):
        turns = round(q[j] / (2.0 * math.pi))
        q[j] -= turns * 2.0 * math.pi
        if j > 0:
            q[3] += turns * 2.0 * math.pi
    for j in range(4):
        if not q_min[j] - _LIMIT_SLACK <= q[j] <= q_max[j] + _LIMIT_SLACK:
            return j + 1
    return 0


def _geometry_vector(geometry: Geometry) -> np.ndarray:
    g = geometry
    return np.array([g.L1, g.L2, g.L3, g.L4, g.l_f])


def damped_least_squares(target: Any, q0: Any, geometry: Geometry, ik: IKParams, *,
                         adaptive: bool = True) -> IKResult:
    """Iterate eq. 3.35 from `q0` towards `target`; never raises on failure.

    Parameters
    ----------
    target : array_like, shape (4,)
        ``[x, y, z, phi]``, m and rad.
    q0 : array_like, shape (4,)
        Start joint angles, rad.
    geometry : Geometry
        Link lengths, m.
    ik : IKParams
        ``damping`` (lambda, the start value when adaptive), ``tolerance`` on
        |e| and ``max_iterations``.
    adaptive : bool
        False runs the thesis' fixed-lambda loop; True adapts lambda by the
        gain ratio (see docs/kinematics.md, "Singularities").

    Returns
    -------
    IKResult
        ``converged`` tells whether the tolerance was met; joint limits are
        not checked (that is :class:`IKSolver`'s job).

    Raises
    ------
    NonFiniteTargetError
        `target` or `q0` holds NaN or infinity.
    """
    t = _as_vector(target, "target")
    start = _as_vector(q0, "start pose q0")
    q, iterations, residual = _dls_kernel(t, start, _geometry_vector(geometry), ik.damping,
                                          ik.tolerance, ik.max_iterations, adaptive)
    q.flags.writeable = False
    converged = bool(residual <= ik.tolerance) and bool(np.isfinite(q).all())
    return IKResult(q, int(iterations), float(residual), converged)


@numba.njit(cache=True)
def _solve_pose_kernel(x: float, y: float, z: float, phi: float, s1: float, s2: float, s3: float, s4: float,
                       consts: np.ndarray, damping: float, tolerance: float, max_iterations: int,
                       adaptive: bool) -> tuple[float, float, float, float, int, float, int]:
    """:func:`_dls_kernel` then :func:`_unwind` in one call, on plain numbers: the control loop's solve.

    `consts` is the geometry vector, then the joint minima, then the maxima.
    Returns ``(q1, q2, q3, q4, iterations, residual, violation)``: numbers
    only, because a returned array costs more to hand back than the solve.
    """
    target = np.empty(4)
    target[0], target[1], target[2], target[3] = x, y, z, phi
    start = np.empty(4)
    start[0], start[1], start[2], start[3] = s1, s2, s3, s4
    q, iterations, residual = _dls_kernel(target, start, consts[:5], damping, tolerance, max_iterations,
                                          adaptive)
    violation = _unwind(q, consts[5:9], consts[9:13])
    return q[0], q[1], q[2], q[3], iterations, residual, violation


# --------------------------------------------------------------------------- solver for the control loop

class IKSolver:
    """Inverse kinematics for a control loop: eq. 3.35, warm-started.

    Each :meth:`solve` starts from the previous solution (the pose one tick
    ago is a few tenths of a millimetre away, so one or two steps suffice),
    or from :data:`HOME_Q` after :meth:`reset`.  If that start fails (no
    convergence, or a solution outside the joint limits) it tries once more
    from :data:`HOME_Q`; then it raises rather than return a wrong answer.

    Parameters
    ----------
    params : ArmParams
        Geometry, joint limits and the ``[ik]`` settings.
    adaptive : bool
        Adaptive damping (default); False runs the thesis' fixed lambda.
    """

    def __init__(self, params: ArmParams, *, adaptive: bool = True) -> None:
        self.params = params
        self.adaptive = adaptive
        self._geom = _geometry_vector(params.geometry)
        self._home = np.array(HOME_Q)
        self._q_min = np.array(params.joint_min)
        self._q_max = np.array(params.joint_max)
        self._last_q: np.ndarray | None = None
        # the last solution as numbers (solve_pose keeps only these; last_q is made on demand)
        self._last_floats: tuple[float, float, float, float] | None = None
        self._consts = np.concatenate([self._geom, self._q_min, self._q_max])
        ik = params.ik
        self._settings = (ik.damping, ik.tolerance, ik.max_iterations, adaptive)
        # Load the control loop's compiled solve now, not in the first chart step; the answer
        # is not kept (the first solve still starts from HOME_Q).
        _solve_pose_kernel(*_fk_floats(*HOME_Q, *self._geom.tolist()), *HOME_Q, self._consts, *self._settings)

    @property
    def last_q(self) -> np.ndarray | None:
        """The last solution (rad, shape (4,), read-only), None after :meth:`reset`."""
        if self._last_q is None and self._last_floats is not None:
            q = np.array(self._last_floats)
            q.flags.writeable = False
            self._last_q = q
        return self._last_q

    def reset(self) -> None:
        """Forget the last solution: the next solve starts from :data:`HOME_Q`."""
        self._last_q = None
        self._last_floats = None

    def solve(self, target: Any, q0: Any = None) -> IKResult:
        """Joint angles that put the tool at `target`.

        Parameters
        ----------
        target : array_like, shape (4,)
            ``[x, y, z, phi]``, m and rad.
        q0 : array_like, shape (4,), optional
            Start joint angles (rad); None warm-starts from :attr:`last_q`.

        Returns
        -------
        IKResult
            Converged, finite and within the joint limits; q1, q2, q3 in [-pi, pi].

        Raises
        ------
        NonFiniteTargetError
            `target` or `q0` holds NaN or infinity.
        UnreachableTargetError
            No start converged within ``max_iterations``; names the best residual.
        JointLimitError
            The solution found violates a joint limit; names joint and angle.
        """
        t = _as_shape4(target, "target")
        if q0 is not None:
            start = _as_shape4(q0, "start pose q0")
        else:
            last = self.last_q
            start = last if last is not None else self._home
        ik = self.params.ik
        q, iterations, residual = _dls_kernel(t, start, self._geom, ik.damping, ik.tolerance,
                                              ik.max_iterations, self.adaptive)
        if not math.isfinite(residual):  # checked here, off the fast path
            _as_vector(t, "target")
            _as_vector(start, "start pose q0")
        violation = _unwind(q, self._q_min, self._q_max)
        if (not residual <= ik.tolerance or violation) and start is not self._home:
            q_h, it_h, res_h = _dls_kernel(t, self._home, self._geom, ik.damping, ik.tolerance,
                                           ik.max_iterations, self.adaptive)
            iterations += it_h
            if res_h <= ik.tolerance or not residual <= ik.tolerance:
                q, residual, violation = q_h, res_h, _unwind(q_h, self._q_min, self._q_max)
        # A finite residual implies finite q: fk of NaN or inf is NaN.
        if not residual <= ik.tolerance:
            raise UnreachableTargetError(t, residual, f"eq. 3.35 did not converge within "
                                         f"{ik.max_iterations} iterations")
        if violation:
            joint = violation - 1
            raise JointLimitError(t, violation, q[joint], self._q_min[joint], self._q_max[joint])
        q.flags.writeable = False
        self._last_q = q
        self._last_floats = tuple(q.tolist())  # type: ignore[assignment]
        return IKResult(q, iterations, residual, True)

    def solve_pose(self, x: float, y: float, z: float, phi: float
                   ) -> tuple[tuple[float, float, float, float], int]:
        """:meth:`solve` warm-started, for the control loop: the pose as four numbers, the answer
        as ``((q1, q2, q3, q4), iterations)``.

        Same angles and the same errors as :meth:`solve`; the common case (the
        warm start converges within the limits) is one compiled call on plain
        numbers, with no array made.
        """
        start = self._last_floats if self._last_floats is not None else HOME_Q
        damping, tolerance, max_iterations, adaptive = self._settings
        q1, q2, q3, q4, iterations, residual, violation = _solve_pose_kernel(
            x, y, z, phi, start[0], start[1], start[2], start[3], self._consts, damping, tolerance,
            max_iterations, adaptive)
        if violation or not residual <= tolerance:
            # a retry from HOME_Q, or an error that names the problem: the full path
            result = self.solve([x, y, z, phi])
            assert self._last_floats is not None
            return self._last_floats, result.iterations
        q = (q1, q2, q3, q4)
        self._last_floats = q
        self._last_q = None
        return q, iterations
