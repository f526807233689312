"""The inverse-kinematics race: one target, four methods, their iterates and why each stopped.

The methods (docs/kinematics.md, "Lab"):

* ``lm_fixed``: the thesis' Levenberg-Marquardt damped least squares (eq. 3.35)
  with fixed lambda 0.001 and tolerance 1e-5, run by the project's kernel
  (:func:`~ttt_sm.twin.kinematics.dls.damped_least_squares`, ``adaptive=False``);
* ``dls_adaptive``: today's adaptive-lambda DLS, the same kernel;
* ``analytic_up`` / ``analytic_down``: the closed form
  (:func:`~ttt_sm.twin.kinematics.closed_form.ik_closed_form`), elbow up / down,
  as in the WPI RBE 3001 final project's analytic inverse kinematics;
* ``twist``: Newton steps on the error twist -- the position error and the
  matrix logarithm of the orientation error about the pitch axis -- through the
  inverse Jacobian, the step of the Ghent robot-arm report.

The iterative methods' iterates are the kernel's result after 1, 2, ... steps
(the kernel is rerun with a growing step budget; it is deterministic), so the
solver is reused, not copied.  Each result says whether it converged and, if
not, why: ``out of reach`` (the closed form finds no pose with the arm in
front of the base axis), ``singular``
(|det J| fell below :data:`SINGULAR_DET` on the way) or ``iteration limit``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ttt_sm.params import ArmParams, IKParams
from ttt_sm.twin.kinematics.chain import fk, jacobian
from ttt_sm.twin.kinematics.closed_form import ik_closed_form
from ttt_sm.twin.kinematics.dls import damped_least_squares
from ttt_sm.twin.kinematics.errors import UnreachableTargetError
from ttt_sm.twin.kinematics.solver import HOME_Q

#: The thesis' fixed damping and tolerance (section 3.4, eq. 3.35).
THESIS_LAMBDA = 0.001
THESIS_TOLERANCE = 1e-5
#: Below this |det J| (m^3/rad^3) a pose counts as singular.
SINGULAR_DET = 1e-7
#: The race's methods, in order.
METHODS = ("lm_fixed", "dls_adaptive", "analytic_up", "analytic_down", "twist")


@dataclass(frozen=True)
class RaceResult:
    """One method's run.

    Attributes
    ----------
    method : str
        One of :data:`METHODS`.
    iterates : list of np.ndarray
        Joint vectors (rad) from the start pose to the last.
    errors : list of float
        Tip position error |p_target - p(q)| (m) per iterate.
    converged : bool
        Whether the final pose is within the tolerance (1e-5 in position, m, and tilt, rad).
    reason : str
        ``converged``, ``out of reach``, ``singular`` or ``iteration limit``.
    seconds : float
        Wall time of one plain solve (output only).
    """

    method: str
    iterates: list[np.ndarray]
    errors: list[float]
    converged: bool
    reason: str
    seconds: float

    @property
    def q(self) -> np.ndarray:
        """The final joint vector, rad."""
        return self.iterates[-1]


def _errors(target: np.ndarray, q: np.ndarray, params: ArmParams) -> tuple[float, float]:
    pose = fk(q, params.geometry)
    return float(np.linalg.norm(pose[:3] - target[:3])), abs(math.remainder(pose[3] - target[3], 2 * math.pi))


def _finish(method: str, target: np.ndarray, iterates: list[np.ndarray], params: ArmParams,
            seconds: float, reachable: bool, min_det: float) -> RaceResult:
    errs = [_errors(target, q, params) for q in iterates]
    e_pos, e_phi = errs[-1]
    ok = bool(np.isfinite(iterates[-1]).all()) and e_pos <= THESIS_TOLERANCE and e_phi <= THESIS_TOLERANCE
    if ok:
        reason = "converged"
    elif not reachable:
        reason = "out of reach"
    elif min_det < SINGULAR_DET:
        reason = "singular"
    else:
        reason = "iteration limit"
    return RaceResult(method, iterates, [e for e, _ in errs], ok, reason, seconds)


def _det(q: np.ndarray, params: ArmParams) -> float:
    return abs(float(np.linalg.det(jacobian(q, params.geometry)))) if np.isfinite(q).all() else 0.0


def _dls_run(method: str, target: np.ndarray, q0: np.ndarray, params: ArmParams, ik: IKParams,
             adaptive: bool, reachable: bool) -> RaceResult:
    t0 = time.perf_counter()
    full = damped_least_squares(target, q0, params.geometry, ik, adaptive=adaptive)
    seconds = time.perf_counter() - t0
    iterates = [q0.copy()]
    for k in range(1, full.iterations + 1):
        step = damped_least_squares(target, q0, params.geometry, replace(ik, max_iterations=k),
                                    adaptive=adaptive)
        iterates.append(np.array(step.q))
    if full.iterations == 0:
        iterates.append(np.array(full.q))
    min_det = min(_det(q, params) for q in iterates)
    return _finish(method, target, iterates, params, seconds, reachable, min_det)


def _twist_run(target: np.ndarray, q0: np.ndarray, params: ArmParams, max_iterations: int,
               reachable: bool) -> RaceResult:
    t0 = time.perf_counter()
    q = q0.copy()
    iterates = [q.copy()]
    min_det = math.inf
    g = params.geometry
    for _ in range(max_iterations):
        pose = fk(q, g)
        # the orientation error's matrix log: R = Rz(q1) Rx(phi), so R_target R^T is a rotation
        # about the pitch axis by the wrapped tilt difference
        err = np.concatenate([target[:3] - pose[:3], [math.remainder(target[3] - pose[3], 2 * math.pi)]])
        if np.linalg.norm(err) <= THESIS_TOLERANCE:
            break
        J = jacobian(q, g)
        det = abs(float(np.linalg.det(J)))
        min_det = min(min_det, det)
        if det < SINGULAR_DET:
            break
        q = q + np.linalg.solve(J, err)
        iterates.append(q.copy())
    seconds = time.perf_counter() - t0
    return _finish("twist", target, iterates, params, seconds, reachable, min_det)


def race(target: Any, params: ArmParams, q0: Any = None, max_iterations: int = 100) -> list[RaceResult]:
    """Run the four methods (five results: the analytic one twice) on `target` = ``[x, y, z, phi]``.

    Parameters
    ----------
    target : array_like, shape (3,) or (4,)
        m and rad; ``phi`` defaults to 0 (the pen vertical).
    params : ArmParams
        Geometry and limits.
    q0 : array_like, optional
        Start pose of the iterative methods, rad; the documented home pose by default.
    max_iterations : int
        Step budget of the iterative methods.

    Returns
    -------
    list of RaceResult
        In :data:`METHODS` order; never raises on a failed solve.
    """
    t = np.asarray([float(v) for v in target] + ([0.0] if len(target) == 3 else []))
    if t.shape != (4,) or not np.isfinite(t).all():
        raise ValueError(f"target must be 3 or 4 finite numbers (x y z [phi]), got {list(target)!r}")
    start = np.array(HOME_Q if q0 is None else q0, dtype=float)
    results = []
    analytic = []
    reachable = True
    for up in (True, False):
        t0 = time.perf_counter()
        try:
            q = ik_closed_form(t, params.geometry, elbow_up=up)
        except UnreachableTargetError:
            q = np.full(4, np.nan)
            reachable = False
        analytic.append((up, q, time.perf_counter() - t0))
    thesis = IKParams(THESIS_LAMBDA, THESIS_TOLERANCE, max_iterations)
    adaptive = replace(params.ik, max_iterations=max_iterations)
    results.append(_dls_run("lm_fixed", t, start, params, thesis, False, reachable))
    results.append(_dls_run("dls_adaptive", t, start, params, adaptive, True, reachable))
    for up, q, sec in analytic:
        its = [start, q]
        results.append(_finish("analytic_up" if up else "analytic_down", t, its, params, sec, reachable,
                               _det(q, params)))
    results.append(_twist_run(t, start, params, max_iterations, reachable))
    return results
