"""The link protocol's numbers and body layouts, written once: the PC's link and the firmware's C take them from here.

The message types (:class:`Msg`), the rejection reasons (:class:`Reason`),
the firmware's states (:class:`State`), the ``DRIVE`` operations
(:class:`Op`), the gains blocks, the framing's sizes, and every message's
body as a table of fields (:data:`BODIES`): each field a name, a
``struct`` code and a count, the fields a body repeats per drive
interleaved in a :class:`Group`.  From the tables:

* each message class's ``FORMAT`` and its packing (:mod:`.messages`), and
  the length each body must have (:func:`.messages.body_length`);
* the firmware's header ``firmware/include/ttt_fw/protocol.h``
  (``python -m ttt_sm.hardware.generate``): the same numbers as
  ``TTT_MSG_*``, ``TTT_REJ_*``, ``TTT_STATE_*``, ``TTT_OP_*``, each body's
  length ``TTT_BODY_<MSG>`` and each field's offset ``TTT_<MSG>_<FIELD>``,
  which ``link.c`` and ``fw.c`` read and write the bodies at.

A field added to a table moves the offsets after it and the body's length
on both sides (docs/hardware.md, "The link protocol").
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from enum import IntEnum
from typing import Self

from ...twin.layout import DRIVES, N_CG, N_CP

PROTOCOL_VERSION = 2
"""Told in ``HELLO`` and ``HANDSHAKE``; a PC and a firmware of different versions do not talk."""


class Numbered(IntEnum):
    """An enumeration whose members carry a one-line doc (``NAME = number, "doc"``): the C header's comment."""

    doc: str

    def __new__(cls, value: int, doc: str = "") -> Self:  # doc's default: a type checker takes `Msg(kind)`, a lookup
        member = int.__new__(cls, value)
        member._value_ = value
        member.doc = doc
        return member


#: The first message type that goes firmware -> PC: the types below it go PC -> firmware.
FIRST_TO_PC = 0x80


class Msg(Numbered):
    """Message types: PC -> firmware below 0x80, firmware -> PC from 0x80 (FIRST_TO_PC)."""

    HELLO = 0x01, "start a session: the firmware answers HANDSHAKE"
    GAINS = 0x02, "one block of the controller's parameters (idle or safe_stop only)"
    GAINS_READ = 0x03, "ask for one block of gains back"
    SETPOINTS = 0x04, "the setpoints of one control step (running only)"
    HEARTBEAT = 0x05, "the idle link's sign of life: the firmware answers HEARTBEAT_REPLY"
    DRIVE = 0x06, "one drive's operation (Op, TTT_OP_*)"
    START = 0x07, "run the cascade, once all gains blocks are loaded"
    HANDSHAKE = 0x81, "what the firmware is: versions, drives, number type, control period, limits"
    GAINS_READBACK = 0x82, "a gains block as the firmware holds it"
    STATUS = 0x85, "the sensors and the state after a control step"
    HEARTBEAT_REPLY = 0x86, "the heartbeat's token, the step and the link's counters"
    EMU_TRUTH = 0xE0, "the emulator's, never a board's: the plant's true angles (simulation only)"


#: Messages the firmware never sees nor sends: left out of its header.
EMULATOR_ONLY = frozenset({Msg.EMU_TRUTH})


class Reason(Numbered):
    """Why bytes or a frame were rejected (the same numbers on both sides of the link)."""

    COBS = 0, "not valid COBS"
    CRC = 1, "CRC mismatch"
    SHORT = 2, "fewer bytes than a header and a CRC"
    OVERLONG = 3, "no 0x00 within the longest frame"
    UNKNOWN_TYPE = 4, "no such message type (or not one this side takes)"
    PARTIAL = 5, "body shorter than its type's: a frame cut short"
    LENGTH = 6, "body longer than its type's"
    DUPLICATE = 7, "sequence number of the last frame again"
    OUT_OF_ORDER = 8, "sequence number behind the last one"
    LATE = 9, "setpoints for a step already past"
    REFUSED = 10, "valid, but not in this state (setpoints before START, gains while running)"
    VALUE = 11, ("a field out of range (drive, block, op, non-finite, a setpoint, gain or period beyond its"
                 " range)")


class State(Numbered):
    """The firmware's states, as STATUS reports them (docs/hardware.md, "The firmware's core")."""

    IDLE = 0, "after power-on: bridges off, no servo pulse; gains may be downloaded"
    RUNNING = 1, "after START: the cascade follows the setpoints"
    SAFE_STOP = 2, "setpoints stopped coming: powered drives hold, the pen lifts, until the next START"


class Op(Numbered):
    """What a DRIVE message does to its drive."""

    OFF = 0, "bridge off"
    CLOSED = 1, "cascade on, holding where the drive is"
    OPEN = 2, "open loop at duty = value"
    OFFSET = 3, "encoder offset estimate = value (rad)"


GAINS_GLOBAL_BLOCK = DRIVES
"""The gains block of the global row (``cg``, N_CG values); the blocks below it are drive d's row (``cp``, N_CP)."""
GAINS_BLOCKS = GAINS_GLOBAL_BLOCK + 1


@dataclass(frozen=True)
class Field:
    """One field of a body: `count` values of ``struct`` code `code`; the message's attribute ``name.lower()``."""

    name: str
    code: str
    count: int = 1
    doc: str = ""

    @property
    def format(self) -> str:
        return self.code if self.count == 1 else f"{self.count}{self.code}"

    @property
    def size(self) -> int:
        return struct.calcsize("<" + self.format)


@dataclass(frozen=True)
class Group:
    """Fields a body repeats `count` times interleaved (repeat i of a field at its offset + i * stride).

    The message holds each field as a tuple of its `count` values.
    """

    name: str
    fields: tuple[Field, ...]
    count: int

    def __post_init__(self) -> None:
        if any(f.count != 1 for f in self.fields):
            raise ValueError(f"group {self.name}: a repeated field holds one value a repeat")

    @property
    def format(self) -> str:
        return "".join(f.format for f in self.fields) * self.count

    @property
    def stride(self) -> int:
        return sum(f.size for f in self.fields)


@dataclass(frozen=True)
class Body:
    """A message's body: its fields in wire order, little-endian, no padding."""

    items: tuple[Field | Group, ...]

    @property
    def format(self) -> str:
        """The ``struct`` format of the whole body."""
        return "<" + "".join(item.format for item in self.items)

    @property
    def size(self) -> int:
        return struct.calcsize(self.format)

    def offsets(self) -> list[tuple[str, int, str]]:
        """``(NAME, offset, doc)`` of every field in wire order; a group's fields at their first repeat,
        then ``<GROUP>_STRIDE``, the bytes from one repeat to the next."""
        rows, at = [], 0
        for item in self.items:
            if isinstance(item, Group):
                inner = at
                for f in item.fields:
                    rows.append((f.name, inner, f.doc))
                    inner += f.size
                rows.append((f"{item.name}_STRIDE", item.stride, f"bytes from one {item.name.lower()} to the next"))
                at += item.stride * item.count
            else:
                rows.append((item.name, at, item.doc))
                at += item.size
        return rows


def body(*items: Field | Group) -> Body:
    """A :class:`Body` of these fields, in wire order."""
    return Body(items)


#: Bits within a field, ``(NAME, value, doc)``: the C's ``TTT_<NAME>``.
FIELD_BITS = (
    ("SETPOINTS_FLAG_FR_SW", 0x01, "the bit of SETPOINTS' FLAGS that selects the slow setpoint filters (fr_sw)"),
    ("STATUS_MODE_BITS", 2, "the bits of STATUS' MODES each drive's mode (TTT_MODE_*) takes, drive 1's lowest"),
)
SETPOINTS_FLAG_FR_SW, STATUS_MODE_BITS = (value for _, value, _ in FIELD_BITS)

#: A frame's head before its body.
HEAD = body(Field("TYPE", "B", doc="the message type (TTT_MSG_*)"),
            Field("SEQ", "H", doc="the sequence number, +1 per frame sent (wraps)"))
HEAD_FORMAT = HEAD.format
HEADER = HEAD.size
CRC_BYTES = 2
"""The CRC-16/CCITT-FALSE after the body, most significant byte first."""
MAX_BODY = 160
"""The longest body a frame may carry (the longest message's is shorter: room to grow)."""
MAX_FRAME = HEADER + MAX_BODY + CRC_BYTES
SEQ_BEHIND = 0x8000
"""A sequence number this many (modulo 2^16) or more after the last is behind it: out of order."""
MAX_ENCODED = MAX_FRAME + MAX_FRAME // 254 + 1
"""The longest COBS-encoded frame, without its closing 0x00 (COBS adds at most one byte per 254)."""


def gains_body(values: int) -> Body:
    """A ``GAINS`` or ``GAINS_READBACK`` body of `values` parameters."""
    return body(Field("BLOCK", "B", doc=f"0..{GAINS_BLOCKS - 1}"),
                Field("VALUES", "d", values, doc="the block's row, in its layout's order"))


#: The two lengths a gains body may have: a drive's row, the global row (by the block byte).
GAINS_DRIVE = gains_body(N_CP)
GAINS_GLOBAL = gains_body(N_CG)

#: Every fixed-length body, by message type (docs/hardware.md lists them).
BODIES: dict[Msg, Body] = {
    Msg.HELLO: body(Field("PROTOCOL", "B", doc="the PC's protocol version")),
    Msg.GAINS_READ: body(Field("BLOCK", "B", doc=f"0..{GAINS_BLOCKS - 1}")),
    Msg.SETPOINTS: body(
        Field("STEP", "I", doc="the control step they are meant for"),
        Field("Q", "f", DRIVES + 1, doc="drives 1-3 (encoder coordinates), then the servo, rad"),
        Field("FLAGS", "B", doc="TTT_SETPOINTS_FLAG_*")),
    Msg.HEARTBEAT: body(Field("TOKEN", "I", doc="echoed in the reply")),
    Msg.DRIVE: body(
        Field("DRIVE", "B", doc=f"0..{DRIVES - 1}"),
        Field("OP", "B", doc="the operation (Op, TTT_OP_*)"),
        Field("VALUE", "d", doc="OPEN: the duty; OFFSET: the encoder offset (rad)")),
    Msg.START: body(),
    Msg.HANDSHAKE: body(
        Field("PROTOCOL", "B", doc="protocol version"),
        Field("FIRMWARE", "B", 3, doc="firmware version: major, minor, patch"),
        Field("DRIVES", "B", doc="drive count"),
        Field("REAL_SIZE", "B", doc="sizeof(ttt_real): 4 float32, 8 float64"),
        Field("CONTROL_PERIOD_US", "I", doc="control period (us)"),
        Group("DRIVE", (Field("RAD_PER_COUNT", "d", doc="joint rad per encoder count"),
                        Field("LIMIT_MIN_RAD", "f", doc="lower joint limit (rad)"),
                        Field("LIMIT_MAX_RAD", "f", doc="upper joint limit (rad)")), DRIVES),
        Field("SERVO_MIN_RAD", "f", doc="the servo's range (rad) ..."),
        Field("SERVO_MAX_RAD", "f"),
        Field("SERVO_SAFE_RAD", "f", doc="... and its safe (pen lifted) angle")),
    Msg.STATUS: body(
        Field("STEP", "I", doc="control steps since power-on"),
        Field("STATE", "B", doc="the state (State, TTT_STATE_*)"),
        Field("INDEX", "B", doc="bit d: drive d's index switch level"),
        Field("MODES", "B", doc="each drive's TTT_MODE_* in TTT_STATUS_MODE_BITS bits, drive 1 lowest"),
        Field("COUNTS", "i", DRIVES, doc="encoder counts"),
        Field("INDEX_COUNT", "i", DRIVES, doc="counts latched at the last index edge"),
        Field("INDEX_EDGES", "H", DRIVES, doc="index edges seen"),
        Field("CURRENT_MA", "h", DRIVES, doc="motor currents (mA)"),
        Field("SERVO_ADC", "H", doc="the pen servo's feedback (ADC counts; the PC calibrates it)")),
    Msg.HEARTBEAT_REPLY: body(
        Field("TOKEN", "I", doc="the heartbeat's, echoed"),
        Field("STEP", "I", doc="control steps since power-on"),
        Field("FRAMES_OK", "I", doc="frames accepted"),
        Field("LOST", "I", doc="frames lost (sequence gaps)"),
        Field("REJECTIONS", "I", len(Reason), doc="frames rejected, by reason (Reason, TTT_REJ_*)")),
    Msg.EMU_TRUTH: body(
        Field("STEP", "I", doc="the firmware step after which the plant was so"),
        Field("FLAGS", "B", doc="bit 0: the emulator is gated"),
        Field("Q", "d", DRIVES + 1, doc="true joint angles q1..q4 (rad)"),
        Field("OFFSETS", "d", DRIVES, doc="true encoder offsets (rad)")),
}


def body_of(kind: Msg, block: int = 0) -> Body:
    """The body of a message of type `kind`; a gains body by its block number."""
    if kind in (Msg.GAINS, Msg.GAINS_READBACK):
        return GAINS_GLOBAL if block == GAINS_GLOBAL_BLOCK else GAINS_DRIVE
    return BODIES[kind]


__all__ = ["BODIES", "CRC_BYTES", "EMULATOR_ONLY", "FIELD_BITS", "FIRST_TO_PC", "GAINS_BLOCKS", "GAINS_DRIVE",
           "GAINS_GLOBAL", "GAINS_GLOBAL_BLOCK", "HEAD", "HEADER", "HEAD_FORMAT", "MAX_BODY", "MAX_ENCODED",
           "MAX_FRAME", "PROTOCOL_VERSION", "SEQ_BEHIND", "SETPOINTS_FLAG_FR_SW", "STATUS_MODE_BITS", "Body", "Field",
           "Group", "Msg", "Numbered", "Op", "Reason", "State", "body", "body_of", "gains_body"]
