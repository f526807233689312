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
from typing import Protocol

import numpy as np

from ..params import ArmParams
from . import layout
from .kinematics import fk
from .plant import Plant

# the servo's true angle in the plant's shared state (read every chart step)
_SV_Q = layout.PGS_SV_Q


class GroundTruth(Protocol):
    """What the simulation-only parts (the whiteboard's ink, precision figures) read of ground truth.

    :class:`ArmTruth` offers it for the in-process twin; an emulated arm
    behind a serial link offers it from the emulator's plant
    (``ttt_sm.hardware.serial_arm.LinkTruth``).
    """

    @property
    def q(self) -> np.ndarray:
        """True joint angles q1..q4 (rad)."""

    def angles(self) -> tuple[float, float, float, float]:
        """:attr:`q` as plain floats."""

    def tool_pose(self) -> np.ndarray:
        """The true tool pose x, y, z (m), phi (rad)."""

    @property
    def offsets(self) -> np.ndarray:
        """The true encoder offsets (rad)."""


class ArmTruth:
    """The true state of the simulated arm: a view of the plant's memory, not a copy.

    Angles are load side, radians; drives 1..3 first, q4 the servo's output.

    Parameters
    ----------
    params : ArmParams
        The arm (geometry for the tool pose, encoder resolution for the offsets).
    plant : Plant
        The simulated plant.
    act : ndarray
        The actuator commands the plant receives (``layout.ACT_*``), for :attr:`stalled`.
    """

    def __init__(self, params: ArmParams, plant: Plant, act: np.ndarray) -> None:
        self.params = params
        self._plant = plant
        self._act = act
        self._rpc = np.array([d.rad_per_count for d in params.drives])
        self._psv, self._pgsv = plant.psv, plant.pgsv
        n = layout.PLANT_WIDTH  # the true angles' flat indices, drives 1-3
        self._i_q = (layout.PS_Q, n + layout.PS_Q, 2 * n + layout.PS_Q)

    @property
    def q(self) -> np.ndarray:
        """True joint angles q1..q4 (rad), a copy."""
        # built from a list: np.append costs several microseconds, and this runs every chart step
        p = self._plant
        return np.array([*p.ps[:, layout.PS_Q].tolist(), float(p.pgs[layout.PGS_SV_Q])])

    def angles(self) -> tuple[float, float, float, float]:
        """:attr:`q` as plain floats, for code that runs every chart step (the whiteboard)."""
        ps, (i1, i2, i3) = self._psv, self._i_q
        return ps[i1], ps[i2], ps[i3], self._pgsv[_SV_Q]

    def tool_pose(self) -> np.ndarray:
        """The true tool pose x, y, z (m), phi (rad): forward kinematics of :attr:`q` (eqs. 3.17-3.25)."""
        return fk(self.q, self.params.true_geometry)

    @property
    def offsets(self) -> np.ndarray:
        """The encoder offsets that make an encoder angle the motor-side joint angle within half a count (rad)."""
        return (self._plant.ints[:, layout.PI_C0] + 0.5) * self._rpc

    @property
    def q_motor(self) -> np.ndarray:
        """True motor angles divided by the gear ratios (rad): what an ideal encoder would see."""
        p = self._plant
        return p.ps[:, layout.PS_TH] / p.pp[:, layout.PP_N]

    @property
    def current_a(self) -> np.ndarray:
        """True armature currents (A), without the measurement noise."""
        return self._plant.ps[:, layout.PS_I].copy()

    @property
    def speed_motor(self) -> np.ndarray:
        """True motor shaft speeds (rad/s)."""
        return self._plant.ps[:, layout.PS_WM].copy()

    @property
    def speed_load(self) -> np.ndarray:
        """True load (joint) speeds of drives 1..3 (rad/s)."""
        return self._plant.ps[:, layout.PS_WQ].copy()

    @property
    def at_limit(self) -> np.ndarray:
        """True per drive while its load rests on a hard stop."""
        return self._plant.ints[:, layout.PI_AT_LIMIT] != 0

    @property
    def stalled(self) -> np.ndarray:
        """True per drive while the bridge drives it (|duty| > 0.1) but the motor stands still."""
        duty = self._act[layout.ACT_DUTY:layout.ACT_DUTY + 3]
        return (np.abs(duty) > 0.1) & (self._plant.ps[:, layout.PS_WM] == 0.0)

    def mechanical_energy(self) -> float:
        """Kinetic energy of rotors and loads + gravity and gear-spring potential of drives 1..3, J.

        Gravity's zero is the arm hanging straight down.  With the drives
        off, friction can only take energy out: a check of the integrator.
        """
        ps, pp, pg = self._plant.ps, self._plant.pp, self._plant.pg
        kinetic = 0.5 * float(np.sum(pp[:, layout.PP_JM] * ps[:, layout.PS_WM] ** 2
                                     + pp[:, layout.PP_JL] * ps[:, layout.PS_WQ] ** 2))
        g2, g23 = float(pg[layout.PG_GRAV2]), float(pg[layout.PG_GRAV23])
        q2, q3 = float(ps[1, layout.PS_Q]), float(ps[2, layout.PS_Q])
        gravity = g2 * (1.0 - math.cos(q2)) + g23 * (1.0 - math.cos(q2 + q3))
        delta = ps[:, layout.PS_TH] / pp[:, layout.PP_N] - ps[:, layout.PS_Q]
        squeeze = np.maximum(np.abs(delta) - 0.5 * pp[:, layout.PP_CLEAR], 0.0)
        spring = 0.5 * float(np.sum(pp[:, layout.PP_K] * squeeze**2))
        return kinetic + gravity + spring


__all__ = ["ArmTruth", "GroundTruth"]
