"""The serial link to the firmware, the PC's side: frames, messages, and what is rejected.

The same specification as the firmware's ``firmware/src/link.c`` and
``fw.c`` (docs/hardware.md, "The link protocol"): a frame is

    type (u8) | seq (u16 LE) | body | CRC-16/CCITT-FALSE of the above (u16, MSB first)

COBS-encoded and closed by a 0x00 byte.  Bodies are little-endian.
:class:`FrameDecoder` cuts a byte stream, however it is chunked, into
:class:`Frame` s and :class:`Rejection` s; :class:`SeqTracker` refuses
duplicated and out-of-order frames; :class:`Receiver` does both, decodes
the messages, counts every rejection by :class:`Reason` and logs a line
naming it.  Nothing here does I/O or reads a clock.
"""

from __future__ import annotations

import logging
import math
import struct
from collections import Counter
from dataclasses import dataclass, field
from enum import IntEnum
from typing import ClassVar

from ..ptylink import crc16

PROTOCOL_VERSION = 2
HEADER = 3
CRC_BYTES = 2
MAX_BODY = 160
MAX_FRAME = HEADER + MAX_BODY + CRC_BYTES
MAX_ENCODED = MAX_FRAME + MAX_FRAME // 254 + 1
"""The longest COBS-encoded frame, without its closing 0x00."""

DRIVES = 3
N_CP = 10
N_CG = 18
GAINS_BLOCKS = 4  # 0..2: a drive's parameter row (N_CP values); 3: the global row (N_CG values)

log = logging.getLogger("ttt_sm.link")


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


class Reason(IntEnum):
    """Why bytes or a frame were rejected (the same numbers as the firmware's ``TTT_REJ_*``)."""

    COBS = 0  # not valid COBS
    CRC = 1  # CRC mismatch
    SHORT = 2  # fewer bytes than a header and a CRC
    OVERLONG = 3  # no 0x00 within the longest frame
    UNKNOWN_TYPE = 4  # no such message type (or not one this side takes)
    PARTIAL = 5  # body shorter than its type's: a frame cut short
    LENGTH = 6  # body longer than its type's
    DUPLICATE = 7  # sequence number seen last
    OUT_OF_ORDER = 8  # sequence number behind the last one
    LATE = 9  # setpoints for a step already past
    REFUSED = 10  # valid, but not in this state
    VALUE = 11  # a field out of range


N_REASONS = len(Reason)

# ---- COBS (the CRC is ttt_sm.ptylink.crc16, the camera link's too) ----------------


def cobs_encode(data: bytes) -> bytes:
    """Consistent Overhead Byte Stuffing: no 0x00 in the result (the frame's closing 0x00 not added)."""
    out = bytearray([0])
    code_at, code = 0, 1
    for byte in data:
        if byte == 0:
            out[code_at] = code
            code_at, code = len(out), 1
            out.append(0)
        else:
            out.append(byte)
            code += 1
            if code == 0xFF:
                out[code_at] = code
                code_at, code = len(out), 1
                out.append(0)
    out[code_at] = code
    return bytes(out)


def cobs_decode(data: bytes) -> bytes:
    """Undo :func:`cobs_encode`; ValueError if `data` is not valid COBS."""
    out = bytearray()
    i, n = 0, len(data)
    while i < n:
        code = data[i]
        i += 1
        if code == 0 or i + code - 1 > n:
            raise ValueError(f"COBS block of {code} at byte {i - 1} runs past the frame's {n} bytes"
                             if code else f"0x00 at byte {i - 1}")
        block = data[i:i + code - 1]
        if 0 in block:
            raise ValueError(f"0x00 inside a COBS block at byte {i + block.index(0)}")
        out += block
        i += code - 1
        if code != 0xFF and i != n:
            out.append(0)
    return bytes(out)


# ---- frames ----------------------------------------------------------------------------


def body_length(kind: int, body: bytes) -> int | None:
    """The body length a frame of type `kind` must have (GAINS: by its block byte), None if no such type."""
    if kind in (Msg.GAINS, Msg.GAINS_READBACK):
        return 1 + 8 * (N_CG if body[:1] == b"\x03" else N_CP)
    return _FIXED_LENGTH.get(kind)


def encode_frame(kind: int, seq: int, body: bytes) -> bytes:
    """A whole wire frame: COBS of type, seq, body and CRC, then 0x00."""
    if len(body) > MAX_BODY:
        raise ValueError(f"a body of {len(body)} bytes is longer than {MAX_BODY}")
    frame = struct.pack("<BH", kind, seq & 0xFFFF) + body
    return cobs_encode(frame + crc16(frame).to_bytes(2, "big")) + b"\x00"


@dataclass(frozen=True)
class Frame:
    """A frame that passed COBS, CRC, type and length: its type, sequence number and body."""

    kind: int
    seq: int
    body: bytes


@dataclass(frozen=True)
class Rejection:
    """Bytes that were not a valid frame, or a valid frame refused: why, and what it was."""

    reason: Reason
    detail: str
    size: int
    """Wire bytes it covers (0 for a frame refused after decoding)."""

    def __str__(self) -> str:
        return f"{self.reason.name.lower()}: {self.detail}"


class FrameDecoder:
    """Cuts a byte stream into frames and rejections at each 0x00 (the same verdicts as ``ttt_rx``)."""

    def __init__(self) -> None:
        self._buf = bytearray()
        self._overflow = 0  # bytes dropped past MAX_ENCODED

    def feed(self, data: bytes) -> list[Frame | Rejection]:
        out: list[Frame | Rejection] = []
        start = 0
        while True:
            end = data.find(b"\x00", start)
            chunk = data[start:] if end < 0 else data[start:end]
            room = MAX_ENCODED - len(self._buf)
            self._buf += chunk[:room]
            self._overflow += max(0, len(chunk) - room)
            if end < 0:
                return out
            if self._buf or self._overflow:
                out.append(self._judge(bytes(self._buf)))
            self._buf.clear()
            self._overflow = 0
            start = end + 1

    def _judge(self, encoded: bytes) -> Frame | Rejection:
        size = len(encoded) + self._overflow + 1
        if self._overflow:
            return Rejection(Reason.OVERLONG, f"{size} bytes without a 0x00 (longest frame {MAX_ENCODED + 1})", size)
        try:
            frame = cobs_decode(encoded)
        except ValueError as e:
            return Rejection(Reason.COBS, f"{e} ({encoded[:16].hex(' ')})", size)
        if len(frame) < HEADER + CRC_BYTES:
            return Rejection(Reason.SHORT, f"{len(frame)} bytes, a frame has at least {HEADER + CRC_BYTES}", size)
        got, want = int.from_bytes(frame[-2:], "big"), crc16(frame[:-2])
        if got != want:
            return Rejection(Reason.CRC, f"CRC {got:04x}, computed {want:04x}, type 0x{frame[0]:02x}", size)
        kind, seq = struct.unpack_from("<BH", frame)
        body = frame[HEADER:-CRC_BYTES]
        expected = body_length(kind, body)
        if expected is None:
            return Rejection(Reason.UNKNOWN_TYPE, f"type 0x{kind:02x}, seq {seq}", size)
        if len(body) != expected:
            reason = Reason.PARTIAL if len(body) < expected else Reason.LENGTH
            return Rejection(reason, f"{_name(kind)} seq {seq} with a {len(body)}-byte body, not {expected}", size)
        return Frame(kind, seq, body)


class SeqTracker:
    """One direction's sequence numbers: a repeat is a duplicate, a number behind the last is out of order."""

    def __init__(self) -> None:
        self.last: int | None = None
        self.lost = 0
        """Frames skipped over (gaps in the numbers)."""

    def reset(self) -> None:
        self.last = None

    def accept(self, seq: int) -> Reason | None:
        """None if `seq` is new (then it is the last); else why it is refused."""
        if self.last is not None:
            delta = (seq - self.last) & 0xFFFF
            if delta == 0:
                return Reason.DUPLICATE
            if delta >= 0x8000:
                return Reason.OUT_OF_ORDER
            self.lost += delta - 1
        self.last = seq
        return None


# ---- messages -------------------------------------------------------------------------------


def _name(kind: int) -> str:
    try:
        return Msg(kind).name
    except ValueError:
        return f"0x{kind:02x}"


class Message:
    """A message's fields; :meth:`pack` gives its body, :meth:`unpack` reads one (bodies are little-endian)."""

    KIND: ClassVar[Msg]
    FORMAT: ClassVar[str]

    def values(self) -> tuple[float | int, ...]:
        raise NotImplementedError

    def pack(self) -> bytes:
        return struct.pack(self.FORMAT, *self.values())

    @classmethod
    def unpack(cls, body: bytes) -> Message:
        raise NotImplementedError

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

    def values(self) -> tuple[int, ...]:
        return (self.protocol,)

    @classmethod
    def unpack(cls, body: bytes) -> Hello:
        return cls(*struct.unpack(cls.FORMAT, body))


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

    def values(self) -> tuple[int, ...]:
        return (self.block,)

    @classmethod
    def unpack(cls, body: bytes) -> GainsRead:
        return cls(*struct.unpack(cls.FORMAT, body))

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

    def values(self) -> tuple[int, ...]:
        return (self.token,)

    @classmethod
    def unpack(cls, body: bytes) -> Heartbeat:
        return cls(*struct.unpack(cls.FORMAT, body))


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

    def values(self) -> tuple[float | int, ...]:
        return (self.drive, self.op, self.value)

    @classmethod
    def unpack(cls, body: bytes) -> Drive:
        return cls(*struct.unpack(cls.FORMAT, body))

    def check(self) -> str | None:
        if not 0 <= self.drive < DRIVES or self.op > max(Op) or not math.isfinite(self.value):
            return f"drive {self.drive} op {self.op} value {self.value}"
        return None


@dataclass(frozen=True)
class Start(Message):
    KIND: ClassVar[Msg] = Msg.START
    FORMAT: ClassVar[str] = "<"

    def values(self) -> tuple[int, ...]:
        return ()

    @classmethod
    def unpack(cls, body: bytes) -> Start:
        return cls()


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


# ---- one end of the link -----------------------------------------------------------------------


@dataclass
class Receiver:
    """The receiving half of one end: frames, sequence numbers, messages; every rejection counted and logged.

    `accepts` are the message types this end takes (the PC: :data:`TO_PC`);
    any other type is rejected as ``unknown_type``.  A ``HELLO`` (on the
    firmware's side) or a ``HANDSHAKE`` (on the PC's) starts a new session
    of sequence numbers.
    """

    accepts: frozenset[int] = TO_PC
    name: str = "pc"
    decoder: FrameDecoder = field(default_factory=FrameDecoder)
    seq: SeqTracker = field(default_factory=SeqTracker)
    rejections: Counter[Reason] = field(default_factory=Counter)
    frames_ok: int = 0
    emu_seq: SeqTracker = field(default_factory=SeqTracker)
    """The emulator's own frames (``EMU_TRUTH``) are numbered apart from the firmware's."""

    def feed(self, data: bytes) -> list[Message]:
        """The messages in `data` that pass every check, in order."""
        out: list[Message] = []
        for item in self.decoder.feed(data):
            if isinstance(item, Rejection):
                self.reject(item)
                continue
            if item.kind not in self.accepts:
                self.reject(Rejection(Reason.UNKNOWN_TYPE, f"{_name(item.kind)} seq {item.seq} is not for "
                                      f"the {self.name}", 0))
                continue
            if item.kind in (Msg.HELLO, Msg.HANDSHAKE):
                self.seq.reset()
            seq = self.emu_seq if item.kind == Msg.EMU_TRUTH else self.seq
            refused = seq.accept(item.seq)
            if refused is not None:
                self.reject(Rejection(refused, f"{_name(item.kind)} seq {item.seq} after {seq.last}", 0))
                continue
            message = MESSAGES[item.kind].unpack(item.body)
            bad = message.check()
            if bad is not None:
                self.reject(Rejection(Reason.VALUE, f"{_name(item.kind)} seq {item.seq}: {bad}", 0))
                continue
            self.frames_ok += 1
            out.append(message)
        return out

    def reject(self, rejection: Rejection) -> None:
        self.rejections[rejection.reason] += 1
        log.warning("link (%s): rejected %s (%d so far)", self.name, rejection,
                    self.rejections[rejection.reason])

    @property
    def rejected(self) -> int:
        return sum(self.rejections.values())


class Sender:
    """The sending half of one end: numbers the frames."""

    def __init__(self) -> None:
        self.seq = 0

    def frame(self, message: Message) -> bytes:
        wire = encode_frame(message.KIND, self.seq, message.pack())
        self.seq = (self.seq + 1) & 0xFFFF
        return wire


__all__ = ["PROTOCOL_VERSION", "Msg", "Reason", "Op", "crc16", "cobs_encode", "cobs_decode", "encode_frame",
           "Frame", "Rejection", "FrameDecoder", "SeqTracker", "Message", "Hello", "Gains", "GainsRead",
           "GainsReadback", "Setpoints", "Heartbeat", "Drive", "Start", "Handshake", "Status", "HeartbeatReply",
           "EmuTruth",
           "MESSAGES", "TO_FIRMWARE", "TO_PC", "Receiver", "Sender"]
