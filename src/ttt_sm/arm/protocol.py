"""The :class:`Arm` protocol and the :class:`Sensors` snapshot it returns.

A real arm tells the PC what its sensors read and takes setpoints; it cannot
tell the true joint angles or the true encoder offsets.  The protocol says
exactly that much, so that the code typed on it (the scheduler, the charts'
wiring, the debugger's signals) runs unchanged on any backend:

* time, and ``step(n)``: the backend advances ``n`` control steps (the
  simulation integrates them; a hardware backend waits for them);
* ``set_setpoints(q, fr_sw)``: the joint setpoints and the setpoint
  filters' switch, once per chart step;
* encoder angles and counts, index switches, motor currents, the pen
  servo's feedback (``sensors()``);
* the encoder offset estimates the init charts set, and enabling or
  disabling a drive's controller.

Where the cascade controller runs is the backend's business: in-process,
fused with the plant, for the simulation (:class:`ttt_sm.twin.sim.ArmSim`);
in the microcontroller for a hardware backend.  Ground truth is not part of
this protocol: the simulated arm keeps it behind its ``truth`` attribute.

An arm behind a link may offer more; the application asks with
``getattr`` and does without when it is absent (the simulated arm has none):

* ``link_ok`` (bool property): the link to the arm is alive and its
  firmware runs the drives; read every chart step as the Safety chart's
  ``Link`` block (docs/safety.md); absent means always true;
* ``link_fault`` (``str | None`` property): why ``link_ok`` is false, in one
  line, for the record of the trip;
* ``rearm() -> bool``: after a lost link, make the arm run its drives again
  if it answers (the Safety chart's ``reset`` calls it before the drives
  initialise again); whether it does;
* ``close()``: release the port.

:class:`ttt_sm.hardware.serial_arm.SerialArm` offers all four (docs/hardware.md).

Every accessor is cheap and returns plain numbers: the scheduler and the
wiring call some of them every chart step.  Drives are numbered 1, 2, 3 as in
the thesis where a method takes a drive number; tuples of three are drive 1
first.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple, Protocol, runtime_checkable


class Sensors(NamedTuple):
    """What the controller hardware reads at one instant (drives 1..3 in order).

    counts: encoder counts since power-on (motor shaft).  index: index switch
    levels (True above the switch angle).  index_count: counts latched at the
    last index edge (0 before any).  index_edges: edges seen since power-on.
    current_a: measured motor currents (with noise), A.  t: the arm's time, s.
    servo_rad: the pen servo's angle as its feedback wire reads it (the ADC's counts through the
    two-point calibration of ``[servo]``, docs/hardware.md), rad: an angle, not counts, so that code typed
    on the protocol needs no calibration; each backend converts what its board measures.

    An immutable record (``_asdict()`` gives its fields by name): a named
    tuple rather than a frozen dataclass, because the simulated arm builds
    one every chart step and a frozen dataclass costs ~1.5 µs more to build.
    Its field ``index`` hides the tuple's ``index()`` method.
    """

    counts: tuple[int, int, int]
    index: tuple[bool, bool, bool]  # type: ignore[assignment]  # hides tuple.index(): a reading is not searched
    index_count: tuple[int, int, int]
    index_edges: tuple[int, int, int]
    current_a: tuple[float, float, float]
    t: float
    servo_rad: float


@runtime_checkable
class Arm(Protocol):
    """An arm the scheduler can drive: three DC drives under cascade control and a pen servo.

    Attributes
    ----------
    dt : float
        The control step, s: ``step(1)`` advances the arm's time by it.
    """

    dt: float

    @property
    def t(self) -> float:
        """The arm's time since power-on, s."""

    def step(self, n: int = 1) -> None:
        """Advance `n` control steps."""

    def set_setpoints(self, q_des: Sequence[float], fr_sw: bool = False) -> None:
        """Joint setpoints: drives 1-3 in encoder coordinates (rad), q4 the servo angle (rad).

        `fr_sw` selects the slow setpoint filters (the thesis' slow moves).
        """

    @property
    def servo_setpoint(self) -> float:
        """The servo angle last commanded (rad); what the servo did is ``sensors().servo_rad``."""

    def sensors(self) -> Sensors:
        """The encoders, index switches, current sensors and the servo's feedback now."""

    def encoder_angles(self) -> tuple[float, float, float]:
        """Drive angles the controllers see, ``counts * rad_per_count + offset estimate`` (rad)."""

    def offset_estimates(self) -> tuple[float, float, float]:
        """The controllers' encoder offsets (rad), 0 until a drive is initialised."""

    def set_offset_estimate(self, drive: int, offset_rad: float) -> None:
        """Set drive `drive`'s (1-3) encoder offset, as its init chart estimates it; the arm does not jump."""

    def enabled(self) -> tuple[bool, bool, bool]:
        """Whether each drive's cascade controller runs."""

    def set_enabled(self, drive: int, enabled: bool) -> None:
        """Switch drive `drive`'s (1-3) controller on (holding where the drive is) or off (bridge off)."""


__all__ = ["Arm", "Sensors"]
