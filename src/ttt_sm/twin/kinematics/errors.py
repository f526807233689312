"""The kinematics' errors, and the checks of input that raise them.

Every failure of the inverse kinematics is an :class:`IKError` that names the
target (a pose ``x, y, z, phi``) and what was wrong with it: not finite, out
of reach, or reachable only beyond a joint limit.  The solvers raise these
rather than return a wrong answer.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np


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
