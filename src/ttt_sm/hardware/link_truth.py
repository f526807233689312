"""The emulator's ground truth as the PC receives it over the link (``EMU_TRUTH`` frames).

Simulation only: the firmware emulator (``ttt-sm arm serve``) sends the
emulated plant's true joint angles beside its ``STATUS``; a board sends none.
:class:`LinkTruth` offers those parts of the application that exist in
simulation alone (the whiteboard inked by the true pen, a drawing's
precision, the fault matrix) what :class:`ttt_sm.twin.truth.ArmTruth` offers
them on the twin.  See docs/hardware.md.
"""

from __future__ import annotations

import numpy as np

from ..params import ArmParams
from ..twin.kinematics import fk


class LinkTruth:
    """Ground truth from an emulator (``EMU_TRUTH`` frames): the emulated plant's true joint angles.

    Simulation only, for what exists in simulation alone (the PC's whiteboard
    inked by the true pen, a drawing's precision); the charts never see it.
    It offers what :class:`ttt_sm.twin.truth.ArmTruth` offers those parts:
    :attr:`q`, :meth:`angles`, :meth:`tool_pose`, :attr:`offsets`, and
    :attr:`speed_load` (from two frames in a row: the fault matrix's
    ``time_to_safe_ms``).
    """

    def __init__(self, params: ArmParams, q: tuple[float, float, float, float], offsets: tuple[float, float, float],
                 step: int) -> None:
        self.params = params
        self._q = q
        self._offsets = offsets
        #: The firmware step these angles are after.
        self.step = step
        self._speed = (0.0, 0.0, 0.0)

    def update(self, q: tuple[float, float, float, float], step: int,
               offsets: tuple[float, float, float] | None = None) -> None:
        if step > self.step:
            h = (step - self.step) * self.params.control.dt
            p = self._q
            self._speed = ((q[0] - p[0]) / h, (q[1] - p[1]) / h, (q[2] - p[2]) / h)
        self._q, self.step = q, step
        if offsets is not None:
            self._offsets = offsets

    @property
    def q(self) -> np.ndarray:
        """True joint angles q1..q4 (rad), a copy."""
        return np.array(self._q)

    def angles(self) -> tuple[float, float, float, float]:
        return self._q

    @property
    def offsets(self) -> np.ndarray:
        """The true encoder offsets (rad): an encoder angle plus these is the joint angle within half a count."""
        return np.array(self._offsets)

    def tool_pose(self) -> np.ndarray:
        """The true tool pose x, y, z (m), phi (rad): forward kinematics of :attr:`q`."""
        return fk(self.q, self.params.true_geometry)

    @property
    def speed_load(self) -> np.ndarray:
        """True joint speeds of drives 1..3 (rad/s): the mean over the firmware steps between the last two frames."""
        return np.array(self._speed)
