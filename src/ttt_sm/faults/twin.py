"""Faults injected into the twin, for the Safety chart's fault matrix (docs/safety.md, "Fault matrix").

:class:`FaultyArm` is the simulated arm behind the :class:`~ttt_sm.arm.Arm`
protocol with a fault switched on or off.  Each fault changes what a real
fault would change, in the plant or in the readings, never in the charts:

- ``encoder_frozen``: a drive's counter stops (a broken encoder wire): the
  controller and the PC read the same count from then on, while the motor
  turns on;
- ``encoder_jump``: a drive's counter gains counts at once (noise on the
  encoder lines): ``ENCODER_JUMP_RAD`` of joint angle, for good;
- ``motor_blocked``: a drive's load is stopped where it stands (something in
  the way): its hard stops close in on it;
- ``current_spike``: a drive's current sensor reads ``SPIKE_A`` more for
  ``SPIKE_S`` (a short in the motor's wiring);
- ``servo_stuck``: the pen servo stops turning (its slew rate 0); its
  feedback wire reads where it stopped;
- ``power_cut``: the H-bridges' supply falls to 0 V (the motors are
  shorted through the bridges, which brakes them) and the servo stops;
- ``camera_lost`` is no fault of the arm: the robot's ``Camera`` block says
  the camera no longer answers (:class:`~ttt_sm.app.safety_wiring.CameraStatus`).

Simulation only: it writes the twin's plant, which a real arm has none of.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..arm import Sensors
from ..twin import _plant as P
from ..twin.sim import ArmSim

#: The faults of the twin, in the order the matrix lists them.
TWIN_FAULTS = ("encoder_frozen", "encoder_jump", "motor_blocked", "current_spike", "servo_stuck", "power_cut",
               "camera_lost")
#: Faults of one drive (the others act on the whole arm).
DRIVE_FAULTS = ("encoder_frozen", "encoder_jump", "motor_blocked", "current_spike")

ENCODER_JUMP_RAD = 0.2
"""How far a jumping encoder's count moves at once, in joint angle (rad)."""
SPIKE_A = 10.0
"""How much a current spike adds to the reading, A."""
SPIKE_S = 0.005
"""How long a current spike lasts, s."""


class FaultError(ValueError):
    """A fault the twin does not know, or one asked for a drive that is not there."""


class FaultyArm:
    """The simulated arm, with one fault at a time switched on (:meth:`inject`) or off (:meth:`clear`).

    It is an :class:`~ttt_sm.arm.Arm`: the robot drives it as it drives the
    simulated arm, and while no fault needs a hand in every control step, a
    step costs what the simulated arm's costs.
    """

    def __init__(self, sim: ArmSim) -> None:
        self.sim = sim
        self.dt = sim.dt
        self.fault: str | None = None
        self.drive = 0  # 1..3 for a fault of one drive
        self._frozen_counts = 0
        self._spike_until = -1.0
        self._saved: list[tuple[object, int, int, float]] = []  # (array, row, column, value) to restore

    # -- the Arm protocol ------------------------------------------------------------

    @property
    def t(self) -> float:
        return self.sim.t

    def step(self, n: int = 1) -> None:
        if self.fault != "encoder_frozen":
            self.sim.step(n)
            return
        ints, d, counts = self.sim.plant.ints, self.drive - 1, self._frozen_counts
        for _ in range(n):  # the counter is rewritten after every control step: the controller reads it next
            self.sim.step(1)
            ints[d, P.PI_COUNTS] = counts

    def set_setpoints(self, q_des: Sequence[float], fr_sw: bool = False) -> None:
        self.sim.set_setpoints(q_des, fr_sw)

    @property
    def servo_setpoint(self) -> float:
        return self.sim.servo_setpoint

    def sensors(self) -> Sensors:
        s = self.sim.sensors()
        if self.fault == "current_spike" and s.t < self._spike_until:
            current = list(s.current_a)
            current[self.drive - 1] += SPIKE_A
            return Sensors(s.counts, s.index, s.index_count, s.index_edges, tuple(current), s.t,  # type: ignore
                           s.servo_rad)
        return s

    def encoder_angles(self) -> tuple[float, float, float]:
        return self.sim.encoder_angles()

    def offset_estimates(self) -> tuple[float, float, float]:
        return self.sim.offset_estimates()

    def set_offset_estimate(self, drive: int, offset_rad: float) -> None:
        self.sim.set_offset_estimate(drive, offset_rad)

    def enabled(self) -> tuple[bool, bool, bool]:
        return self.sim.enabled()

    def set_enabled(self, drive: int, enabled: bool) -> None:
        self.sim.set_enabled(drive, enabled)

    # -- faults ------------------------------------------------------------------------

    def inject(self, fault: str, drive: int = 1) -> None:
        """Switch `fault` on now, on `drive` (1-3) for a fault of one drive."""
        if fault not in TWIN_FAULTS or fault == "camera_lost":
            raise FaultError(f"the twin has no fault {fault!r}; faults: {', '.join(TWIN_FAULTS[:-1])}")
        if fault in DRIVE_FAULTS and drive not in (1, 2, 3):
            raise FaultError(f"drive must be 1, 2 or 3, got {drive!r}")
        self.clear()
        self.fault, self.drive = fault, drive
        plant, d = self.sim.plant, drive - 1
        if fault == "encoder_frozen":
            self._frozen_counts = int(plant.ints[d, P.PI_COUNTS])
        elif fault == "encoder_jump":
            rpc = self.sim.params.drives[d].rad_per_count
            plant.ints[d, P.PI_C0] -= int(round(ENCODER_JUMP_RAD / rpc))  # counts = floor(angle) - C0
        elif fault == "motor_blocked":
            q = float(plant.ps[d, P.PS_Q])
            self._set(plant.pp, d, P.PP_QMIN, q)
            self._set(plant.pp, d, P.PP_QMAX, q)
        elif fault == "current_spike":
            self._spike_until = self.sim.t + SPIKE_S
        elif fault == "servo_stuck":
            self._set(plant.pg, None, P.PG_SV_RATE, 0.0)
        elif fault == "power_cut":
            for k in range(3):
                self._set(plant.pp, k, P.PP_SUPPLY, 0.0)
            self._set(plant.pg, None, P.PG_SV_RATE, 0.0)

    def clear(self) -> None:
        """Switch the fault off: what it changed in the plant is restored (a jumped count stays jumped)."""
        for array, row, column, value in reversed(self._saved):
            if row < 0:
                array[column] = value  # type: ignore[index]
            else:
                array[row, column] = value  # type: ignore[index]
        self._saved.clear()
        self.fault, self.drive = None, 0
        self._spike_until = -1.0

    def _set(self, array: object, row: int | None, column: int, value: float) -> None:
        if row is None:
            self._saved.append((array, -1, column, float(array[column])))  # type: ignore[index]
            array[column] = value  # type: ignore[index]
        else:
            self._saved.append((array, row, column, float(array[row, column])))  # type: ignore[index]
            array[row, column] = value  # type: ignore[index]


__all__ = ["DRIVE_FAULTS", "ENCODER_JUMP_RAD", "FaultError", "FaultyArm", "SPIKE_A", "SPIKE_S", "TWIN_FAULTS"]
