"""Faults injected into the twin, for the Safety chart's fault matrix (docs/safety.md, "Fault matrix").

:class:`FaultyArm` is the simulated arm behind the :class:`~ttt_sm.arm.Arm`
protocol with a fault switched on or off.  Each fault changes what a real
fault would change, in the plant or in the readings, never in the charts:
:mod:`.plant` says what each one does (the emulator's faults are the same).
``camera_lost`` is no fault of the arm: the robot's ``Camera`` block says
the camera no longer answers (:class:`~ttt_sm.app.safety_wiring.CameraStatus`).

Simulation only: it writes the twin's plant, which a real arm has none of.
"""

from __future__ import annotations

from collections.abc import Sequence

from ..arm import Sensors
from ..twin.sim import ArmSim
from .plant import ARM_FAULTS, DRIVE_FAULTS, ENCODER_JUMP_RAD, SPIKE_A, SPIKE_S, FaultError, PlantFault

#: The faults of the twin, in the order the matrix lists them.
TWIN_FAULTS = (*ARM_FAULTS, "camera_lost")


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
        self._fault: PlantFault | None = None

    # -- the Arm protocol ------------------------------------------------------------

    @property
    def t(self) -> float:
        return self.sim.t

    def step(self, n: int = 1) -> None:
        fault = self._fault
        if fault is None or not fault.every_step:
            self.sim.step(n)
            return
        for _ in range(n):  # the fault acts after every control step: the controller reads the plant next
            self.sim.step(1)
            fault.after_step()

    def set_setpoints(self, q_des: Sequence[float], fr_sw: bool = False) -> None:
        self.sim.set_setpoints(q_des, fr_sw)

    @property
    def servo_setpoint(self) -> float:
        return self.sim.servo_setpoint

    def sensors(self) -> Sensors:
        s = self.sim.sensors()
        fault = self._fault
        if fault is not None and s.t < fault.spike_until:
            i1, i2, i3 = s.current_a
            return s._replace(current_a=(fault.current_a(1, i1, s.t), fault.current_a(2, i2, s.t),
                                         fault.current_a(3, i3, s.t)))
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
        if fault not in ARM_FAULTS:
            raise FaultError(f"the twin has no fault {fault!r}; faults: {', '.join(ARM_FAULTS)}")
        self.clear()
        self._fault = PlantFault(self.sim.plant, fault, drive)
        self.fault, self.drive = fault, drive

    def clear(self) -> None:
        """Switch the fault off: what it changed in the plant is restored (a jumped count stays jumped)."""
        if self._fault is not None:
            self._fault.clear()
        self._fault = None
        self.fault, self.drive = None, 0


__all__ = ["DRIVE_FAULTS", "ENCODER_JUMP_RAD", "FaultError", "FaultyArm", "SPIKE_A", "SPIKE_S", "TWIN_FAULTS"]
