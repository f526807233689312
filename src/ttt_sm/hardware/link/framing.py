"""The arm's frames on the wire: COBS, the CRC, and cutting a byte stream into frames (``link.c``'s half).

A frame is

    type (u8) | seq (u16 LE) | body | CRC-16/CCITT-FALSE of the above (u16, MSB first)

COBS-encoded and closed by a 0x00 byte.  :class:`FrameDecoder` cuts a byte
stream, however it is chunked, into :class:`Frame` s and
:class:`~.rejections.Rejection` s, with the verdicts of the firmware's
``ttt_rx``: a body's length is checked against its type's
(:func:`.messages.body_length`), as ``ttt_rx`` asks ``ttt_body_length``.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

from ...ptylink.crc import crc16
from .messages import body_length, kind_name
from .protocol import CRC_BYTES, HEAD_FORMAT, HEADER, MAX_BODY, MAX_ENCODED, MAX_FRAME
from .rejections import Reason, Rejection


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


def encode_frame(kind: int, seq: int, body: bytes) -> bytes:
    """A whole wire frame: COBS of type, seq, body and CRC, then 0x00."""
    if len(body) > MAX_BODY:
        raise ValueError(f"a body of {len(body)} bytes is longer than {MAX_BODY}")
    frame = struct.pack(HEAD_FORMAT, kind, seq & 0xFFFF) + body
    return cobs_encode(frame + crc16(frame).to_bytes(CRC_BYTES, "big")) + b"\x00"


@dataclass(frozen=True)
class Frame:
    """A frame that passed COBS, CRC, type and length: its type, sequence number and body."""

    kind: int
    seq: int
    body: bytes


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
        got, want = int.from_bytes(frame[-CRC_BYTES:], "big"), crc16(frame[:-CRC_BYTES])
        if got != want:
            return Rejection(Reason.CRC, f"CRC {got:04x}, computed {want:04x}, type 0x{frame[0]:02x}", size)
        kind, seq = struct.unpack_from(HEAD_FORMAT, frame)
        body = frame[HEADER:-CRC_BYTES]
        expected = body_length(kind, body)
        if expected is None:
            return Rejection(Reason.UNKNOWN_TYPE, f"type 0x{kind:02x}, seq {seq}", size)
        if len(body) != expected:
            reason = Reason.PARTIAL if len(body) < expected else Reason.LENGTH
            return Rejection(reason, f"{kind_name(kind)} seq {seq} with a {len(body)}-byte body, not {expected}",
                             size)
        return Frame(kind, seq, body)


__all__ = ["CRC_BYTES", "Frame", "FrameDecoder", "HEADER", "MAX_BODY", "MAX_ENCODED", "MAX_FRAME", "cobs_decode",
           "cobs_encode", "crc16", "encode_frame"]
