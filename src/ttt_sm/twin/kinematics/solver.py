"""Inverse kinematics for the control loop: eq. 3.35 warm-started, with joint limits and errors."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ttt_sm.params import ArmParams

from .chain import fk
from .dls import IKResult, _dls_kernel, _geometry_vector, _solve_pose_kernel, _unwind
from .errors import JointLimitError, UnreachableTargetError, _as_shape4, _as_vector

#: Documented home pose (rad): elbow up, the pen 5 cm above the field centre
#: of the default arm.  Cold solves start here.
HOME_Q: tuple[float, float, float, float] = (0.0, math.radians(100.0), math.radians(-90.0),
                                             math.radians(-10.0))


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
        x, y, z, phi = fk(HOME_Q, params.geometry)
        _solve_pose_kernel(float(x), float(y), float(z), float(phi), *HOME_Q, self._consts, *self._settings)

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
