"""Ground truth of the simulated arm: what only a simulation can tell.

A real arm reports encoder counts, index switches and currents (the
:class:`ttt_sm.arm.Arm` protocol); it cannot report its true joint angles,
the true encoder offsets or where the pen tip really is.  The simulated arm
keeps those here, behind ``ArmSim.truth``, for what exists in simulation
alone: the whiteboard, the simulated camera, precision figures, tests and
the debugger's ``q_true`` signal.  Code typed on ``Arm`` never reads it.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..params import ArmParams
from . import _kernel as K
from .kinematics import fk


def flat_view(a: np.ndarray) -> Any:
    """A flat memoryview of `a`'s memory: its items read and written as plain Python numbers."""
    return memoryview(a.reshape(-1))  # type: ignore[arg-type]  # numpy's stubs lack __buffer__


class ArmTruth:
    """The true state of the simulated arm (reads the twin's state arrays; a view, not a copy).

    Angles are load side, radians; drives 1..3 first, q4 the servo's output.
    """

    def __init__(self, params: ArmParams, dp: np.ndarray, gp: np.ndarray, ds: np.ndarray,
                 di: np.ndarray, gs: np.ndarray) -> None:
        self.params = params
        self._dp, self._gp, self._ds, self._di, self._gs = dp, gp, ds, di, gs
        self._dsv = flat_view(ds)
        self._gsv = flat_view(gs)

    @property
    def q(self) -> np.ndarray:
        """True joint angles q1..q4 (rad), a copy."""
        # built from a list: np.append costs several microseconds, and this runs every chart step
        return np.array([*self._ds[:, K.S_Q].tolist(), float(self._gs[K.GS_SV_Q])])

    def angles(self) -> tuple[float, float, float, float]:
        """:attr:`q` as plain floats, for code that runs every chart step (the whiteboard)."""
        ds, n = self._dsv, K.N_DS
        return ds[K.S_Q], ds[n + K.S_Q], ds[2 * n + K.S_Q], self._gsv[K.GS_SV_Q]

    def tool_pose(self) -> np.ndarray:
        """The true tool pose x, y, z (m), phi (rad): forward kinematics of :attr:`q` (eqs. 3.17-3.25)."""
        return fk(self.q, self.params.geometry)

    @property
    def offsets(self) -> np.ndarray:
        """The encoder offsets that make an encoder angle the motor-side joint angle within half a count (rad)."""
        return (self._di[:, K.I_C0] + 0.5) * self._dp[:, K.P_RPC]

    @property
    def q_motor(self) -> np.ndarray:
        """True motor angles divided by the gear ratios (rad): what an ideal encoder would see."""
        return self._ds[:, K.S_TH] / self._dp[:, K.P_N]

    @property
    def current_a(self) -> np.ndarray:
        """True armature currents (A), without the measurement noise."""
        return self._ds[:, K.S_I].copy()

    @property
    def speed_motor(self) -> np.ndarray:
        """True motor shaft speeds (rad/s)."""
        return self._ds[:, K.S_WM].copy()

    @property
    def speed_load(self) -> np.ndarray:
        """True load (joint) speeds of drives 1..3 (rad/s)."""
        return self._ds[:, K.S_WQ].copy()

    @property
    def at_limit(self) -> np.ndarray:
        """True per drive while its load rests on a hard stop."""
        return self._di[:, K.I_AT_LIMIT] != 0

    @property
    def stalled(self) -> np.ndarray:
        """True per drive while the bridge drives it (|duty| > 0.1) but the motor stands still."""
        return (np.abs(self._ds[:, K.S_DUTY]) > 0.1) & (self._ds[:, K.S_WM] == 0.0)

    def mechanical_energy(self) -> float:
        """Kinetic energy of rotors and loads + gravity and gear-spring potential of drives 1..3, J.

        Gravity's zero is the arm hanging straight down.  With the drives
        off, friction can only take energy out: a check of the integrator.
        """
        ds, dp = self._ds, self._dp
        kinetic = 0.5 * float(np.sum(dp[:, K.P_JM] * ds[:, K.S_WM] ** 2 + dp[:, K.P_JL] * ds[:, K.S_WQ] ** 2))
        g2, g23 = float(self._gp[K.G_GRAV2]), float(self._gp[K.G_GRAV23])
        q2, q3 = float(ds[1, K.S_Q]), float(ds[2, K.S_Q])
        gravity = g2 * (1.0 - math.cos(q2)) + g23 * (1.0 - math.cos(q2 + q3))
        delta = ds[:, K.S_TH] / dp[:, K.P_N] - ds[:, K.S_Q]
        squeeze = np.maximum(np.abs(delta) - 0.5 * dp[:, K.P_CLEAR], 0.0)
        spring = 0.5 * float(np.sum(dp[:, K.P_K] * squeeze**2))
        return kinetic + gravity + spring


__all__ = ["ArmTruth", "flat_view"]
