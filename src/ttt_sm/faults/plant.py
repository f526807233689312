"""What each fault of the arm does to the twin's plant and to the readings taken of it (docs/safety.md).

One place says it, for both arms the fault matrix runs on: the in-process
twin (:class:`~.twin.FaultyArm`) and the C firmware on the emulator's plant
(:meth:`ttt_sm.hardware.emulator.ArmEmulator.inject_fault`).  A
:class:`PlantFault` is made on a :class:`~ttt_sm.twin.plant.Plant` at the
fault's onset and acts in three places, as a real fault would:

- on the plant, at once (:class:`PlantFault` changes its parameters and
  :meth:`~PlantFault.clear` puts them back): ``encoder_jump``,
  ``motor_blocked``, ``servo_stuck``, ``power_cut``;
- after each control step (:meth:`~PlantFault.after_step`), before the
  controller's next read: ``encoder_frozen`` writes the count it froze at
  back into the plant's counter;
- in the current the controller reads (:meth:`~PlantFault.current_a`):
  ``current_spike``.

The faults:

- ``encoder_frozen``: a drive's counter stops (a broken encoder wire): the
  controller and the PC read the same count from then on, while the motor
  turns on;
- ``encoder_jump``: a drive's counter gains counts at once (noise on the
  encoder lines): :data:`ENCODER_JUMP_RAD` of joint angle, for good;
- ``motor_blocked``: a drive's load is stopped where it stands (something in
  the way): its hard stops close in on it;
- ``current_spike``: a drive's current sensor reads :data:`SPIKE_A` more for
  :data:`SPIKE_S` (a short in the motor's wiring);
- ``servo_stuck``: the pen servo stops turning (its slew rate 0); its
  feedback wire reads where it stopped;
- ``power_cut``: the H-bridges' supply falls to 0 V (the motors are
  shorted through the bridges, which brakes them) and the servo stops.

Simulation only: it writes the twin's plant, which a real arm has none of.
"""

from __future__ import annotations

import numpy as np

from ..twin import layout
from ..twin.plant import Plant

#: The faults of the arm, in the order the matrix lists them.
ARM_FAULTS = ("encoder_frozen", "encoder_jump", "motor_blocked", "current_spike", "servo_stuck", "power_cut")
#: Faults of one drive (the others act on the whole arm).
DRIVE_FAULTS = ("encoder_frozen", "encoder_jump", "motor_blocked", "current_spike")

ENCODER_JUMP_RAD = 0.2
"""How far a jumping encoder's count moves at once, in joint angle (rad)."""
SPIKE_A = 10.0
"""How much a current spike adds to the reading, A."""
SPIKE_S = 0.005
"""How long a current spike lasts, s."""


class FaultError(ValueError):
    """A fault the arm does not know, or one asked for a drive that is not there."""


class PlantFault:
    """One fault of the arm, switched on at `plant`'s time now on `drive` (1-3, for a fault of one drive).

    Attributes
    ----------
    every_step : bool
        The fault needs :meth:`after_step` after every control step.
    spike_until : float
        The plant's time (s) until which :meth:`current_a` adds the spike; -1 for no spike.
    """

    def __init__(self, plant: Plant, fault: str, drive: int = 1) -> None:
        if fault not in ARM_FAULTS:
            raise FaultError(f"the arm has no fault {fault!r}; faults: {', '.join(ARM_FAULTS)}")
        if fault in DRIVE_FAULTS and drive not in (1, 2, 3):
            raise FaultError(f"drive must be 1, 2 or 3, got {drive!r}")
        self.plant = plant
        self.fault = fault
        self.drive = drive
        self.every_step = fault == "encoder_frozen"
        self.spike_until = -1.0
        self._saved: list[tuple[np.ndarray, int | None, int, float]] = []  # (array, row, column, value)
        d = drive - 1
        self._frozen_counts = int(plant.ints[d, layout.PI_COUNTS])
        if fault == "encoder_jump":
            rpc = plant.params.drives[d].rad_per_count
            plant.ints[d, layout.PI_C0] -= int(round(ENCODER_JUMP_RAD / rpc))  # counts = floor(angle) - C0
        elif fault == "motor_blocked":
            q = float(plant.ps[d, layout.PS_Q])
            self._set(plant.pp, d, layout.PP_QMIN, q)
            self._set(plant.pp, d, layout.PP_QMAX, q)
        elif fault == "current_spike":
            self.spike_until = plant.t + SPIKE_S
        elif fault == "servo_stuck":
            self._set(plant.pg, None, layout.PG_SV_RATE, 0.0)
        elif fault == "power_cut":
            for k in range(3):
                self._set(plant.pp, k, layout.PP_SUPPLY, 0.0)
            self._set(plant.pg, None, layout.PG_SV_RATE, 0.0)

    def after_step(self) -> None:
        """After a control step of the plant, before the controller reads it: a frozen counter stays put."""
        if self.every_step:
            self.plant.ints[self.drive - 1, layout.PI_COUNTS] = self._frozen_counts

    def current_a(self, drive: int, reading: float, t: float) -> float:
        """The current drive `drive` (1-3) reads at time `t` (s), its sensor's `reading` (A) with the fault."""
        if drive == self.drive and t < self.spike_until:
            return reading + SPIKE_A
        return reading

    def clear(self) -> None:
        """Switch the fault off: what it changed in the plant is restored (a jumped count stays jumped)."""
        for array, row, column, value in reversed(self._saved):
            if row is None:
                array[column] = value
            else:
                array[row, column] = value
        self._saved.clear()
        self.every_step = False
        self.spike_until = -1.0

    def _set(self, array: np.ndarray, row: int | None, column: int, value: float) -> None:
        if row is None:
            self._saved.append((array, None, column, float(array[column])))
            array[column] = value
        else:
            self._saved.append((array, row, column, float(array[row, column])))
            array[row, column] = value


__all__ = ["ARM_FAULTS", "DRIVE_FAULTS", "ENCODER_JUMP_RAD", "FaultError", "PlantFault", "SPIKE_A", "SPIKE_S"]
