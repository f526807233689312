"""The thesis' iterative inverse kinematics: damped least squares (eq. 3.35), compiled.

:func:`damped_least_squares` runs one solve from a start pose and never
raises on failure; :class:`~ttt_sm.twin.kinematics.IKSolver` wraps it for the
control loop.  The kernels work on plain numbers and small arrays under
numba; with ``NUMBA_DISABLE_JIT=1`` the same code runs as Python.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numba
import numpy as np

from ttt_sm.params import Geometry, IKParams

from .chain import _jacobian_into, arm_chain
from .errors import _as_vector

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
    pose = arm_chain(q[0], q[1], q[2], q[3], L1, L2, L3, L4, l_f)  # x, y, z, phi first
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
        pose = arm_chain(q_new[0], q_new[1], q_new[2], q_new[3], L1, L2, L3, L4, l_f)
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
