"""The arm's messages: their types, their fields, their bodies (``fw.c``'s half of the protocol).

Each message type is a frozen dataclass whose :attr:`~Message.FORMAT` is
its body's ``struct`` format (little-endian, as the firmware's
``ttt_put_*``/``ttt_get_*`` write and read); :data:`MESSAGES` finds the
class of a frame's type, :func:`body_length` the length its body must have.
docs/hardware.md ("The link protocol") lists them with their fields.
"""

from __future__ import annotations

import math
import struct
from collections.abc import Iterator
from dataclasses import Field, dataclass
from typing import Any, ClassVar, Self

from ...twin.layout import DRIVES, N_CG, N_CP
from .protocol import (
    BODIES,
    FIRST_TO_PC,
    GAINS_BLOCKS,
    PROTOCOL_VERSION,
    SETPOINTS_FLAG_FR_SW,
    Group,
    Msg,
    Op,
    State,
    body_of,
    gains_body,
)

STATE_NAMES = tuple(s.name.lower() for s in State)
#: The bit of EMU_TRUTH's `flags` that says the emulator is gated (the emulator's own: not in protocol.h).
EMU_TRUTH_FLAG_GATED = 0x01


def kind_name(kind: int) -> str:
    """A message type's name (``SETPOINTS``), or its number in hex when there is no such type."""
    try:
        return Msg(kind).name
    except ValueError:
        return f"0x{kind:02x}"


class Message:
    """A message's fields; :meth:`pack` gives its body, :meth:`unpack` reads one (bodies are little-endian).

    Its body's table (:data:`.protocol.BODIES`) says what it holds: each
    field of the table is the attribute of its name in lower case, in
    order, a tuple where the field counts several values or repeats per
    drive; :attr:`FORMAT` is the table's ``struct`` format, set when the
    class is made.  A message whose attributes are not its body's fields
    says how they map in :meth:`values` and :meth:`unpack`.
    """

    KIND: ClassVar[Msg]
    FORMAT: ClassVar[str]
    __dataclass_fields__: ClassVar[dict[str, Field[Any]]]  # every message is a dataclass

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        cls.FORMAT = body_of(cls.KIND).format

    def values(self) -> tuple[float | int, ...]:
        """The body's values in :attr:`FORMAT`'s order: a group's fields interleaved, repeat by repeat."""
        out: list[float | int] = []
        for item in BODIES[self.KIND].items:
            if isinstance(item, Group):
                columns = [getattr(self, f.name.lower()) for f in item.fields]
                out += [v for i in range(item.count) for v in (c[i] for c in columns)]
            elif item.count == 1:
                out.append(getattr(self, item.name.lower()))
            else:
                out += getattr(self, item.name.lower())
        return tuple(out)

    def pack(self) -> bytes:
        return struct.pack(self.FORMAT, *self.values())

    @classmethod
    def unpack(cls, body: bytes) -> Self:
        """The message in `body` (of :attr:`FORMAT`'s length): its values as the fields, grouped as :meth:`values`."""
        values: Iterator[Any] = iter(struct.unpack(cls.FORMAT, body))
        args: list[Any] = []
        for item in BODIES[cls.KIND].items:
            if isinstance(item, Group):
                rows = [[next(values) for _ in item.fields] for _ in range(item.count)]
                args += [tuple(column) for column in zip(*rows, strict=True)]
            elif item.count == 1:
                args.append(next(values))
            else:
                args.append(tuple(next(values) for _ in range(item.count)))
        return cls(*args)

    def check(self) -> str | None:
        """What is out of range in the fields (a :data:`Reason.VALUE` rejection), None if nothing."""
        return None


def _finite(values: tuple[float, ...] | list[float]) -> bool:
    return all(math.isfinite(v) for v in values)


@dataclass(frozen=True)
class Hello(Message):
    KIND: ClassVar[Msg] = Msg.HELLO
    protocol: int = PROTOCOL_VERSION


@dataclass(frozen=True)
class Gains(Message):
    """One block of the controller's parameters: 0..2 a drive's row (N_CP values), 3 the global row (N_CG).

    Its :attr:`FORMAT` is the drive row's; a body's length is its values', whatever their number (a
    wrong one is the receiver's to judge).
    """

    KIND: ClassVar[Msg] = Msg.GAINS
    block: int
    values_: tuple[float, ...]

    def values(self) -> tuple[float | int, ...]:
        return (self.block, *self.values_)

    def pack(self) -> bytes:
        return struct.pack(gains_body(len(self.values_)).format, *self.values())

    @classmethod
    def unpack(cls, body: bytes) -> Self:
        block, *vals = struct.unpack(gains_body((len(body) - 1) // 8).format, body)
        return cls(block, tuple(vals))

    def check(self) -> str | None:
        if not 0 <= self.block < GAINS_BLOCKS:
            return f"gains block {self.block} (0..{GAINS_BLOCKS - 1})"
        return None if _finite(self.values_) else f"gains block {self.block} has a non-finite value"


@dataclass(frozen=True)
class GainsReadback(Gains):
    KIND: ClassVar[Msg] = Msg.GAINS_READBACK


@dataclass(frozen=True)
class GainsRead(Message):
    KIND: ClassVar[Msg] = Msg.GAINS_READ
    block: int

    def check(self) -> str | None:
        return None if 0 <= self.block < GAINS_BLOCKS else f"gains block {self.block} (0..{GAINS_BLOCKS - 1})"


@dataclass(frozen=True)
class Setpoints(Message):
    """Setpoints meant for firmware control step `step`: drives 1-3 (encoder coordinates) and the servo, rad.

    The body's ``FLAGS`` byte holds `fr_sw` (:data:`.protocol.SETPOINTS_FLAG_FR_SW`).
    """

    KIND: ClassVar[Msg] = Msg.SETPOINTS
    step: int
    q: tuple[float, float, float, float]
    fr_sw: bool = False

    def values(self) -> tuple[float | int, ...]:
        return (self.step, *self.q, SETPOINTS_FLAG_FR_SW if self.fr_sw else 0)

    @classmethod
    def unpack(cls, body: bytes) -> Self:
        step, a, b, c, d, flags = struct.unpack(cls.FORMAT, body)
        return cls(step, (a, b, c, d), bool(flags & SETPOINTS_FLAG_FR_SW))

    def check(self) -> str | None:
        return None if _finite(self.q) else f"setpoints {self.q} are not all finite"


@dataclass(frozen=True)
class Heartbeat(Message):
    KIND: ClassVar[Msg] = Msg.HEARTBEAT
    token: int


@dataclass(frozen=True)
class Drive(Message):
    KIND: ClassVar[Msg] = Msg.DRIVE
    drive: int  # 0..2
    op: int
    value: float = 0.0

    def check(self) -> str | None:
        if not 0 <= self.drive < DRIVES or self.op > max(Op) or not math.isfinite(self.value):
            return f"drive {self.drive} op {self.op} value {self.value}"
        return None


@dataclass(frozen=True)
class Start(Message):
    KIND: ClassVar[Msg] = Msg.START


@dataclass(frozen=True)
class Handshake(Message):
    """What the firmware is: versions, drives, its number type, control period, encoders and limits."""

    KIND: ClassVar[Msg] = Msg.HANDSHAKE
    protocol: int
    firmware: tuple[int, int, int]
    drives: int
    real_size: int
    control_period_us: int
    rad_per_count: tuple[float, ...]
    limit_min_rad: tuple[float, ...]
    limit_max_rad: tuple[float, ...]
    servo_min_rad: float
    servo_max_rad: float
    servo_safe_rad: float


@dataclass(frozen=True)
class Status(Message):
    """The firmware's sensors and state after control step `step` (currents in mA, the servo's feedback in
    ADC counts: the PC converts it with the ``[servo]`` calibration)."""

    KIND: ClassVar[Msg] = Msg.STATUS
    step: int
    state: int
    index: int  # bit d: drive d's index switch level
    modes: int  # STATUS_MODE_BITS bits per drive, drive 1 lowest
    counts: tuple[int, int, int]
    index_count: tuple[int, int, int]
    index_edges: tuple[int, int, int]
    current_ma: tuple[int, int, int]
    servo_adc: int

    @property
    def state_name(self) -> str:
        return STATE_NAMES[self.state] if self.state < len(STATE_NAMES) else f"state {self.state}"


@dataclass(frozen=True)
class HeartbeatReply(Message):
    """The firmware's answer to a :class:`Heartbeat`: the token, its step and its link counters."""

    KIND: ClassVar[Msg] = Msg.HEARTBEAT_REPLY
    token: int
    step: int
    frames_ok: int
    lost: int
    rejections: tuple[int, ...]


@dataclass(frozen=True)
class EmuTruth(Message):
    """The emulator's plant after firmware step `step`: true joint angles q1..q4, true encoder offsets (rad).

    Simulation only: ``ttt-sm arm serve`` sends one before each burst of the
    firmware's frames so that the PC can ink its simulated whiteboard and
    measure a drawing's precision; a board never sends it.  Its sequence
    numbers are its own (the emulator numbers them, not the firmware).
    `flags` bit 0: the emulator is gated (the PC's setpoints set its pace:
    it keeps no deadline, so the PC need not hold it to the link's 50 ms).
    """

    KIND: ClassVar[Msg] = Msg.EMU_TRUTH
    step: int
    flags: int
    q: tuple[float, float, float, float]
    offsets: tuple[float, float, float]

    @property
    def gated(self) -> bool:
        return bool(self.flags & EMU_TRUTH_FLAG_GATED)

    def check(self) -> str | None:
        return None if _finite(self.q + self.offsets) else f"non-finite angles {self.q} {self.offsets}"


MESSAGES: dict[int, type[Message]] = {m.KIND: m for m in (
    Hello, Gains, GainsRead, Setpoints, Heartbeat, Drive, Start, Handshake, GainsReadback, Status, HeartbeatReply,
    EmuTruth)}
TO_FIRMWARE = frozenset(k for k in MESSAGES if k < FIRST_TO_PC)
TO_PC = frozenset(k for k in MESSAGES if k >= FIRST_TO_PC)


def body_length(kind: int, body: bytes) -> int | None:
    """The body length a frame of type `kind` must have (GAINS: by its block byte), None if no such type."""
    if kind not in MESSAGES:
        return None
    return body_of(Msg(kind), body[0] if body else 0).size


__all__ = ["DRIVES", "EMU_TRUTH_FLAG_GATED", "GAINS_BLOCKS", "MESSAGES", "N_CG", "N_CP", "PROTOCOL_VERSION",
           "STATE_NAMES", "TO_FIRMWARE", "TO_PC", "Drive", "EmuTruth", "Gains", "GainsRead", "GainsReadback",
           "Handshake", "Heartbeat", "HeartbeatReply", "Hello", "Message", "Msg", "Op", "Setpoints", "Start", "State",
           "Status", "body_length", "kind_name"]
