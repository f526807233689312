"""The camera's line protocol: 25 cell percentages per frame, with a sequence number and a CRC-16.

The thesis' smart camera (section 3.6.3) measures, in each of the 25 fields,
the percentage of dark pixels and "sends the obtained percentages through
serial port to the Pc", where Simulink's *Stream input* block reads them.
The thesis does not give the byte format; this one is ours, NMEA-like so a
terminal shows it readably::

    $TTT,<seq>,<p1>,...,<p25>*<CRC>\\r\\n      a frame
    $TTS,<level>,<text>*<CRC>\\r\\n           a status line (INFO, WARN, ERROR)

``seq`` is 0..65535 (wrapping), each ``p`` is 0.0..100.0 with exactly one
decimal, ``CRC`` is CRC-16/CCITT-FALSE (:func:`ttt_sm.ptylink.crc16`, the arm's
link's too) of the bytes between ``$`` and ``*`` as 4 upper-case hex digits.
The full grammar is in docs/smartcam.md.  A CRC rather than NMEA's XOR,
because XOR cannot see a dropped pair of equal bytes (``100.0`` losing ``00``
reads as a valid ``1.0``); a CRC-16 catches every error burst up to 16 bits
and all but 1 in 65536 of the rest.

:func:`decode_line` is strict: it checks framing, then the checksum, then the
content, and raises :class:`FrameError` naming the first thing wrong.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from enum import StrEnum

from ..ptylink.crc import crc16
from .errors import EncodeError, FrameError, Reason

CELLS = 25
"""Percentages per frame: the 5 x 5 playing field (thesis fig. 3.33)."""
SEQ_MODULUS = 65536
"""Sequence numbers count 0..65535 and wrap to 0."""
FRAME_TAG = b"TTT"
STATUS_TAG = b"TTS"
MAX_STATUS_TEXT = 80
"""Longest status text, characters."""
MAX_SENTENCE_BYTES = len(b"$TTT,65535") + CELLS * len(b",100.0") + len(b"*FFFF\r\n")
"""Longest valid sentence (a frame with seq 65535 and every cell at 100.0): 167 bytes."""

_SEQ = re.compile(rb"0|[1-9][0-9]{0,4}")
_PCT = re.compile(rb"100\.0|[1-9]?[0-9]\.[0-9]")
_HEX4 = re.compile(rb"[0-9A-F]{4}")
_TEXT_BYTES = frozenset(range(0x20, 0x7F)) - {ord("$"), ord("*")}


class Level(StrEnum):
    """Severity of a status line."""

    INFO = "INFO"
    WARN = "WARN"
    ERROR = "ERROR"


@dataclass(frozen=True)
class Frame:
    """One camera frame: its sequence number and the 25 percentages, row-major in image order.

    ``percentages[5 * (row - 1) + (column - 1)]`` is the share of dark pixels,
    in percent (0..100), in the field at ``row``, ``column`` (1..5) *as the
    camera's image shows it* (row 1 at the top): the order of the vision
    detector's ``Detection.percentages``, which is what the camera sends.
    ``ttt_sm.vision.board_values(frame.percentages, view)`` turns it into
    board order for percent-process.
    """

    seq: int
    percentages: tuple[float, ...]

    def cell(self, row: int, column: int) -> float:
        """Percentage of the image's field at ``row``, ``column`` (1..5 each, row 1 at the top), percent."""
        if not (1 <= row <= 5 and 1 <= column <= 5):
            raise IndexError(f"row and column are 1..5, got {row}, {column}")
        return self.percentages[5 * (row - 1) + (column - 1)]


@dataclass(frozen=True)
class Status:
    """A status line from the camera: a level and a short text."""

    level: Level
    text: str


def wrap_sentence(body: bytes) -> bytes:
    """The wire line of a sentence's ``body`` (the bytes between ``$`` and ``*``): ``$<body>*<CRC>\\r\\n``."""
    return b"$" + body + b"*" + f"{crc16(body):04X}".encode("ascii") + b"\r\n"


def format_percentage(value: float) -> str:
    """``value`` (percent) as it goes on the wire: one decimal, 0.0..100.0; raises EncodeError otherwise."""
    v = float(value)
    if not math.isfinite(v):
        raise EncodeError(f"percentage {value!r} is not finite")
    r = round(v, 1) + 0.0  # + 0.0 turns -0.0 into 0.0
    if not 0.0 <= r <= 100.0:
        raise EncodeError(f"percentage {value!r} is outside 0..100")
    return f"{r:.1f}"


def encode_frame(seq: int, percentages: Sequence[float]) -> bytes:
    """The wire line of one frame: ``$TTT,<seq>,<p1>,...,<p25>*<CRC>\\r\\n``.

    ``seq`` is 0..65535; ``percentages`` are 25 numbers in percent, row-major,
    rounded to one decimal.  Raises :class:`EncodeError` for a wrong count, a
    NaN, or a value outside 0..100.
    """
    if isinstance(seq, bool) or not isinstance(seq, int) or not 0 <= seq < SEQ_MODULUS:
        raise EncodeError(f"sequence number must be an int 0..{SEQ_MODULUS - 1}, got {seq!r}")
    values = list(percentages)
    if len(values) != CELLS:
        raise EncodeError(f"a frame has {CELLS} percentages, got {len(values)}")
    fields = []
    for i, p in enumerate(values):
        try:
            fields.append(format_percentage(p))
        except (EncodeError, TypeError, ValueError) as exc:
            raise EncodeError(f"cell {i + 1}: {exc}") from None
    return wrap_sentence(b"TTT," + str(seq).encode("ascii") + b"," + ",".join(fields).encode("ascii"))


def encode_status(level: Level | str, text: str) -> bytes:
    """The wire line of a status: ``$TTS,<level>,<text>*<CRC>\\r\\n``.

    ``text`` is printable ASCII without ``$`` and ``*``, at most 80 characters.
    """
    try:
        lvl = Level(level)
    except ValueError:
        raise EncodeError(f"status level must be one of {', '.join(Level)}, got {level!r}") from None
    raw = text.encode("ascii", errors="replace")
    if len(raw) > MAX_STATUS_TEXT or not set(raw) <= _TEXT_BYTES or not text.isascii():
        raise EncodeError(f"status text must be <= {MAX_STATUS_TEXT} printable ASCII characters"
                          f" without '$' or '*', got {text!r}")
    return wrap_sentence(b"TTS," + lvl.value.encode("ascii") + b"," + raw)


def decode_line(line: bytes) -> Frame | Status:
    """The :class:`Frame` or :class:`Status` in one wire line (``$`` to ``\\r\\n`` inclusive).

    Strict: raises :class:`FrameError` with the first problem found, checked
    in this order: framing (``$`` start, CR LF end, length), checksum
    (present, 4 upper-case hex digits, equal to the CRC-16 of the body), then
    content (printable ASCII, sentence tag, field count, sequence number, and
    each percentage: numeric, finite, 0..100, exactly one decimal).
    """
    line = bytes(line)
    if not line.startswith(b"$"):
        raise FrameError(Reason.BAD_FRAMING, "a sentence starts with '$'", line)
    if not line.endswith(b"\r\n"):
        raise FrameError(Reason.BAD_FRAMING, "a sentence ends with CR LF", line)
    if len(line) > MAX_SENTENCE_BYTES:
        raise FrameError(Reason.OVERLONG, f"{len(line)} bytes, the longest valid sentence has"
                         f" {MAX_SENTENCE_BYTES}", line)
    star = line.rfind(b"*")
    if star < 0:
        raise FrameError(Reason.NO_CHECKSUM, "no '*' before the checksum", line)
    body, sent = line[1:star], line[star + 1:-2]
    if not _HEX4.fullmatch(sent):
        raise FrameError(Reason.BAD_CHECKSUM_FORMAT, f"checksum {sent!r} is not 4 upper-case hex digits", line)
    computed = crc16(body)
    if computed != int(sent, 16):
        raise FrameError(Reason.CHECKSUM_MISMATCH, f"line says {sent.decode()}, body gives {computed:04X}", line)
    bad = next((i for i, b in enumerate(body) if b not in _TEXT_BYTES), None)
    if bad is not None:
        raise FrameError(Reason.BAD_FRAMING, f"byte 0x{body[bad]:02X} at column {bad + 2} is not printable"
                         " ASCII (or is a second '$' or '*')", line)
    tag = body[:4]
    if tag == b"TTT,":
        return _decode_frame(body, line)
    if tag == b"TTS,":
        return _decode_status(body, line)
    raise FrameError(Reason.UNKNOWN_SENTENCE, f"tag {body.split(b',')[0]!r}, expected b'TTT' or b'TTS'", line)


def _decode_frame(body: bytes, line: bytes) -> Frame:
    fields = body.split(b",")[1:]
    if len(fields) != 1 + CELLS:
        raise FrameError(Reason.FIELD_COUNT, f"{len(fields) - 1} percentages, expected {CELLS}", line)
    seq_text = fields[0]
    if not _SEQ.fullmatch(seq_text) or int(seq_text) >= SEQ_MODULUS:
        raise FrameError(Reason.BAD_SEQUENCE, f"sequence number {seq_text!r} is not a decimal"
                         f" 0..{SEQ_MODULUS - 1} without leading zeros", line)
    values = []
    for i, text in enumerate(fields[1:]):
        if not _PCT.fullmatch(text):
            raise FrameError(*_classify_bad_percentage(text, i + 1), line)
        values.append(float(text))
    return Frame(int(seq_text), tuple(values))


def _classify_bad_percentage(text: bytes, cell: int) -> tuple[Reason, str]:
    where = f"cell {cell} (row {(cell - 1) // 5 + 1}, column {(cell - 1) % 5 + 1})"
    try:
        value = float(text)
    except ValueError:
        return Reason.NON_NUMERIC, f"{where}: {text!r} is not a number"
    if math.isnan(value):
        return Reason.NOT_FINITE, f"{where}: {text!r} is NaN"
    if math.isinf(value):
        return Reason.NOT_FINITE, f"{where}: {text!r} is infinite"
    if not 0.0 <= value <= 100.0:
        return Reason.OUT_OF_RANGE, f"{where}: {text!r} is outside 0..100"
    return Reason.BAD_NUMBER_FORMAT, f"{where}: {text!r} is not written with one decimal like 42.5"


def _decode_status(body: bytes, line: bytes) -> Status:
    fields = body.split(b",", 2)
    if len(fields) != 3:
        raise FrameError(Reason.FIELD_COUNT, "a status has a level and a text", line)
    level, text = fields[1], fields[2]
    try:
        lvl = Level(level.decode("ascii"))
    except ValueError:
        raise FrameError(Reason.BAD_STATUS, f"status level {level!r}, expected one of"
                         f" {', '.join(Level)}", line) from None
    if len(text) > MAX_STATUS_TEXT:
        raise FrameError(Reason.BAD_STATUS, f"status text of {len(text)} characters, at most"
                         f" {MAX_STATUS_TEXT}", line)
    return Status(lvl, text.decode("ascii"))
