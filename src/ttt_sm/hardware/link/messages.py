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
from dataclasses import Field, dataclass, fields
from enum import IntEnum
from typing import Any, ClassVar, Self

from .rejections import N_REASONS

PROTOCOL_VERSION = 2
DRIVES = 3
N_CP = 10
N_CG = 18
GAINS_BLOCKS = 4  # 0..2: a drive's parameter row (N_CP values); 3: the global row (N_CG values)


class Msg(IntEnum):
    """Message types: PC -> firmware below 0x80, firmware -> PC from 0x80."""

    HELLO = 0x01
    GAINS = 0x02
    GAINS_READ = 0x03
    SETPOINTS = 0x04
    HEARTBEAT = 0x05
    DRIVE = 0x06
    START = 0x07
    HANDSHAKE = 0x81
    GAINS_READBACK = 0x82
    STATUS = 0x85
    HEARTBEAT_REPLY = 0x86
    EMU_TRUTH = 0xE0  # the emulator's, never a board's: the plant's true angles (simulation only)


def kind_name(kind: int) -> str:
    """A message type's name (``SETPOINTS``), or its number in hex when there is no such type."""
    try:
        return Msg(kind).name
    except ValueError:
        return f"0x{kind:02x}"


class Message:
    """A message's fields; :meth:`pack` gives its body, :meth:`unpack` reads one (bodies are little-endian).

    A message whose fields are its body's values one for one, in order,
    needs no more than its fields and :attr:`FORMAT`; one that groups
    values into tuples says how in :meth:`values` and :meth:`unpack`.
    """

    KIND: ClassVar[Msg]
    FORMAT: ClassVar[str]
    __dataclass_fields__: ClassVar[dict[str, Field[Any]]]  # every message is a dataclass

    def values(self) -> tuple[float | int, ...]:
        """The body's values in :attr:`FORMAT`'s order: by default the fields, as declared."""
        return tuple(getattr(self, f.name) for f in fields(self))

    def pack(self) -> bytes:
        return struct.pack(self.FORMAT, *self.values())

    @classmethod
    def unpack(cls, body: bytes) -> Self:
        """The message in `body` (of :attr:`FORMAT`'s length): by default its values as the fields."""
        return cls(*struct.unpack(cls.FORMAT, body))

    def check(self) -> str | None:
        """What is out of range in the fields (a :data:`Reason.VALUE` rejection), None if nothing."""
        return None


def _finite(values: tuple[float, ...] | list[float]) -> bool:
    return all(math.isfinite(v) for v in values)


@dataclass(frozen=True)
class Hello(Message):
    KIND: ClassVar[Msg] = Msg.HELLO
    FORMAT: ClassVar[str] = "<B"
    protocol: int = PROTOCOL_VERSION


@dataclass(frozen=True)
class Gains(Message):
    """One block of the controller's parameters: 0..2 a drive's row (10 values), 3 the global row (18)."""

    KIND: ClassVar[Msg] = Msg.GAINS
    FORMAT: ClassVar[str] = "<B"
    block: int
    values_: tuple[float, ...]

    def pack(self) -> bytes:
        return struct.pack(f"<B{len(self.values_)}d", self.block, *self.values_)

    @classmethod
    def unpack(cls, body: bytes) -> Gains:
        n = (len(body) - 1) // 8
        block, *vals = struct.unpack(f"<B{n}d", body)
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
    FORMAT: ClassVar[str] = "<B"
    block: int

    def check(self) -> str | None:
        return None if 0 <= self.block < GAINS_BLOCKS else f"gains block {self.block} (0..{GAINS_BLOCKS - 1})"


@dataclass(frozen=True)
class Setpoints(Message):
    """Setpoints meant for firmware control step `step`: drives 1-3 (encoder coordinates) and the servo, rad."""

    KIND: ClassVar[Msg] = Msg.SETPOINTS
    FORMAT: ClassVar[str] = "<I4fB"
    step: int
    q: tuple[float, float, float, float]
    fr_sw: bool = False

    def values(self) -> tuple[float | int, ...]:
        return (self.step, *self.q, 1 if self.fr_sw else 0)

    @classmethod
    def unpack(cls, body: bytes) -> Setpoints:
        step, a, b, c, d, flags = struct.unpack(cls.FORMAT, body)
        return cls(step, (a, b, c, d), bool(flags & 1))

    def check(self) -> str | None:
        return None if _finite(self.q) else f"setpoints {self.q} are not all finite"


@dataclass(frozen=True)
class Heartbeat(Message):
    KIND: ClassVar[Msg] = Msg.HEARTBEAT
    FORMAT: ClassVar[str] = "<I"
    token: int


class Op(IntEnum):
    """What a :class:`Drive` message does to drive `drive`."""

    OFF = 0  # bridge off
    CLOSED = 1  # cascade on, holding where the drive is
    OPEN = 2  # open loop at duty = value
    OFFSET = 3  # encoder offset estimate = value (rad)


@dataclass(frozen=True)
class Drive(Message):
    KIND: ClassVar[Msg] = Msg.DRIVE
    FORMAT: ClassVar[str] = "<BBd"
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
    FORMAT: ClassVar[str] = "<"


@dataclass(frozen=True)
class Handshake(Message):
    """What the firmware is: versions, drives, its number type, control period, encoders and limits."""

    KIND: ClassVar[Msg] = Msg.HANDSHAKE
    FORMAT: ClassVar[str] = "<BBBBBBI" + "dff" * DRIVES + "fff"
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

    def values(self) -> tuple[float | int, ...]:
        per_drive = [v for d in range(DRIVES)
                     for v in (self.rad_per_count[d], self.limit_min_rad[d], self.limit_max_rad[d])]
        return (self.protocol, *self.firmware, self.drives, self.real_size, self.control_period_us, *per_drive,
                self.servo_min_rad, self.servo_max_rad, self.servo_safe_rad)

    @classmethod
    def unpack(cls, body: bytes) -> Handshake:
        v = struct.unpack(cls.FORMAT, body)
        drives = v[7:7 + 3 * DRIVES]
        return cls(v[0], (v[1], v[2], v[3]), v[4], v[5], v[6], tuple(drives[0::3]), tuple(drives[1::3]),
                   tuple(drives[2::3]), *v[7 + 3 * DRIVES:])


STATE_NAMES = ("idle", "running", "safe_stop")


@dataclass(frozen=True)
class Status(Message):
    """The firmware's sensors and state after control step `step` (currents in mA, the servo's feedback in
    ADC counts: the PC converts it with the ``[servo]`` calibration)."""

    KIND: ClassVar[Msg] = Msg.STATUS
    FORMAT: ClassVar[str] = "<IBBB3i3i3H3hH"
    step: int
    state: int
    index: int  # bit d: drive d's index switch level
    modes: int  # 2 bits per drive, drive 1 lowest
    counts: tuple[int, int, int]
    index_count: tuple[int, int, int]
    index_edges: tuple[int, int, int]
    current_ma: tuple[int, int, int]
    servo_adc: int

    def values(self) -> tuple[int, ...]:
        return (self.step, self.state, self.index, self.modes, *self.counts, *self.index_count,
                *self.index_edges, *self.current_ma, self.servo_adc)

    @classmethod
    def unpack(cls, body: bytes) -> Status:
        v = struct.unpack(cls.FORMAT, body)
        return cls(v[0], v[1], v[2], v[3], v[4:7], v[7:10], v[10:13], v[13:16], v[16])

    @property
    def state_name(self) -> str:
        return STATE_NAMES[self.state] if self.state < len(STATE_NAMES) else f"state {self.state}"


@dataclass(frozen=True)
class HeartbeatReply(Message):
    """The firmware's answer to a :class:`Heartbeat`: the token, its step and its link counters."""

    KIND: ClassVar[Msg] = Msg.HEARTBEAT_REPLY
    FORMAT: ClassVar[str] = f"<4I{N_REASONS}I"
    token: int
    step: int
    frames_ok: int
    lost: int
    rejections: tuple[int, ...]

    def values(self) -> tuple[int, ...]:
        return (self.token, self.step, self.frames_ok, self.lost, *self.rejections)

    @classmethod
    def unpack(cls, body: bytes) -> HeartbeatReply:
        v = struct.unpack(cls.FORMAT, body)
        return cls(v[0], v[1], v[2], v[3], tuple(v[4:]))


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
    FORMAT: ClassVar[str] = "<IB4d3d"
    step: int
    flags: int
    q: tuple[float, float, float, float]
    offsets: tuple[float, float, float]

    def values(self) -> tuple[float | int, ...]:
        return (self.step, self.flags, *self.q, *self.offsets)

    @classmethod
    def unpack(cls, body: bytes) -> EmuTruth:
        v = struct.unpack(cls.FORMAT, body)
        return cls(v[0], v[1], (v[2], v[3], v[4], v[5]), (v[6], v[7], v[8]))

    @property
    def gated(self) -> bool:
        return bool(self.flags & 1)

    def check(self) -> str | None:
        return None if _finite(self.q + self.offsets) else f"non-finite angles {self.q} {self.offsets}"


MESSAGES: dict[int, type[Message]] = {m.KIND: m for m in (
    Hello, Gains, GainsRead, Setpoints, Heartbeat, Drive, Start, Handshake, GainsReadback, Status, HeartbeatReply,
    EmuTruth)}
_FIXED_LENGTH = {kind: struct.calcsize(m.FORMAT) for kind, m in MESSAGES.items()
                 if kind not in (Msg.GAINS, Msg.GAINS_READBACK)}
TO_FIRMWARE = frozenset(k for k in MESSAGES if k < 0x80)
TO_PC = frozenset(k for k in MESSAGES if k >= 0x80)


def body_length(kind: int, body: bytes) -> int | None:
    """The body length a frame of type `kind` must have (GAINS: by its block byte), None if no such type."""
    if kind in (Msg.GAINS, Msg.GAINS_READBACK):
        return 1 + 8 * (N_CG if body[:1] == b"\x03" else N_CP)
    return _FIXED_LENGTH.get(kind)


__all__ = ["DRIVES", "GAINS_BLOCKS", "MESSAGES", "N_CG", "N_CP", "PROTOCOL_VERSION", "STATE_NAMES", "TO_FIRMWARE",
           "TO_PC", "Drive", "EmuTruth", "Gains", "GainsRead", "GainsReadback", "Handshake", "Heartbeat",
           "HeartbeatReply", "Hello", "Message", "Msg", "Op", "Setpoints", "Start", "Status", "body_length",
           "kind_name"]
