"""Which arm the robot drives: the in-process twin, or an arm behind a serial link.

``--arm sim`` (the default of ``play``, ``gui``, ``demo``, ``draw``,
``init`` and ``debug``) builds the twin in the process, as always.
``--arm serial:PORT`` opens :class:`~ttt_sm.hardware.serial_arm.SerialArm`
on ``PORT``: a board's ``/dev/ttyACM0``, or ``ttt-sm arm serve``'s
pseudo-terminal (docs/hardware.md).  The charts, the scheduler and the
wiring run unchanged on either: they only see the :class:`~ttt_sm.arm.Arm`.

Ground truth over the link exists only when an emulator sends it
(``EMU_TRUTH``): then the whiteboard is inked where the emulated pen really
is, and drawings are measured as on the twin.  A board sends none.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..arm import Arm
from ..params import ArmParams
from ..twin.truth import GroundTruth

#: The default: the twin, in this process.
SIM = "sim"


class ArmChoiceError(ValueError):
    """An ``--arm`` value that names no arm, or an arm that cannot be reached; the message says which."""


def parse_arm(text: str) -> str | None:
    """The port of ``serial:PORT``, None for ``sim``; :class:`ArmChoiceError` for anything else."""
    if text == SIM:
        return None
    kind, sep, port = text.partition(":")
    if kind == "serial" and sep and port.strip():
        return port
    raise ArmChoiceError(f"expected sim or serial:PORT (a serial device or ttt-sm arm serve's link), got {text[:80]!r}")


@dataclass
class ArmConnection:
    """An arm that is not the in-process twin, with the ground truth it offers (None from a board)."""

    arm: Arm
    truth: GroundTruth | None
    port: str

    def close(self) -> None:
        close = getattr(self.arm, "close", None)
        if close is not None:
            close()

    def __enter__(self) -> ArmConnection:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def connect_arm(choice: str, params: ArmParams, servo_angle: float | None = None) -> ArmConnection | None:
    """Open the arm ``choice`` names (``--arm``): None for ``sim`` (the caller builds the twin).

    `servo_angle` is the pen's angle until the charts command one (default:
    the init charts' servo angle, as the twin starts).  Every way the port or
    the firmware can fail to answer is an :class:`ArmChoiceError` naming the port.
    """
    from ..hardware.firmware import FirmwareError
    from ..hardware.serial_arm import SerialArm, SerialArmError
    from .init_wiring import servo_init_angle

    port = parse_arm(choice)
    if port is None:
        return None
    angle = servo_init_angle(params) if servo_angle is None else servo_angle
    try:
        arm = SerialArm(port, params, servo_angle=angle)
    except (SerialArmError, FirmwareError, OSError, ValueError) as exc:
        raise ArmChoiceError(f"--arm serial:{port}: {exc}") from None
    return ArmConnection(arm, arm.truth, port)


__all__ = ["SIM", "ArmChoiceError", "ArmConnection", "connect_arm", "parse_arm"]
