"""Cutting a byte stream into sentences, and finding the next one after garbage.

Bytes arrive from the serial port in arbitrary chunks.  :class:`LineFramer`
keeps the unfinished part and hands out whole candidate sentences (``$`` to
``\\n``) for :func:`~.protocol.decode_line` to judge, plus a
:class:`Rejection` for whatever cannot be a sentence.  Resynchronisation is
NMEA's: a sentence always starts at a ``$``, so

- bytes before a ``$`` are garbage (reported once per run);
- a ``$`` inside a sentence means the sentence was cut short (truncated), and a
  new one starts there;
- a sentence longer than the longest valid one is overlong, and everything up
  to the next ``$`` or ``\\n`` is dropped with it.

The framer is pure (no I/O, no clock): the same bytes give the same output
however they are chunked.
"""

from __future__ import annotations

from dataclasses import dataclass

from .errors import Reason, snippet
from .protocol import MAX_SENTENCE_BYTES

_KEEP = 64
"""Bytes of a rejected run kept for the log message."""


@dataclass(frozen=True)
class Rejection:
    """Something on the wire that was not a valid sentence: why, in words, and its first bytes."""

    reason: Reason
    detail: str
    snippet: bytes
    size: int
    """Bytes the rejection covers (all of them, not only the snippet)."""

    def __str__(self) -> str:
        return f"{self.reason.value}: {self.detail}; line {snippet(self.snippet)}"


class LineFramer:
    """Turns chunks of bytes into candidate sentences and rejections, in wire order."""

    def __init__(self, max_sentence: int = MAX_SENTENCE_BYTES) -> None:
        self._max = max_sentence
        self._sentence = bytearray()   # from a '$', while in a sentence
        self._in_sentence = False
        self._garbage = bytearray()    # the first bytes of the current garbage run
        self._garbage_size = 0
        self._discarding = 0           # bytes dropped after an overlong sentence, 0 when not discarding
        self._sync_left = 0            # after resync(): bytes that may still be skipped as a line's tail
        self.skipped = 0
        """Bytes dropped as the tail of a line that began before the last :meth:`resync`."""

    def feed(self, data: bytes) -> list[bytes | Rejection]:
        """Consume ``data``; return the sentences (bytes, ``$`` .. ``\\r\\n``) and rejections it completes."""
        out: list[bytes | Rejection] = []
        i, n = 0, len(data)
        while i < n:
            if self._sync_left:
                k = _find_end(data, i)
                stop = n if k < 0 else k + (data[k] == 0x0A)
                take = min(stop - i, self._sync_left)
                self.skipped += take
                self._sync_left = 0 if (k >= 0 and i + take == stop) else self._sync_left - take
                i += take
            elif self._discarding:
                j = _find_end(data, i)
                if j < 0:
                    self._discarding += n - i
                    return out
                self._discarding += j - i + (data[j] == 0x0A)
                self._end_overlong(out)
                i = j + (data[j] == 0x0A)
            elif self._in_sentence:
                j = _find_end(data, i)
                end = n if j < 0 else j
                room = self._max - 1 - len(self._sentence)  # 1: the final \n
                if end - i > room:
                    self._sentence += data[i:i + room]
                    self._discarding = len(self._sentence) + 1  # +1: the byte that overflowed
                    self._in_sentence = False
                    i += room + 1
                    continue
                self._sentence += data[i:end]
                if j < 0:
                    return out
                if data[j] == 0x0A:
                    self._sentence += b"\n"
                    out.append(bytes(self._sentence))
                    self._sentence.clear()
                    self._in_sentence = False
                    i = j + 1
                else:  # a new '$' before this sentence ended
                    out.append(Rejection(Reason.TRUNCATED, "a new '$' came before the end of the line",
                                         bytes(self._sentence), len(self._sentence)))
                    self._sentence = bytearray(b"$")
                    i = j + 1
            else:
                j = data.find(b"$", i)
                end = n if j < 0 else j
                self._hunt(data[i:end], out)
                if j < 0:
                    return out
                self._end_garbage(out)
                self._in_sentence = True
                self._sentence = bytearray(b"$")
                i = j + 1
        return out

    def flush(self, why: str = "the link closed") -> list[Rejection]:
        """End of stream (disconnect, close): whatever was unfinished is reported as rejected."""
        out: list[bytes | Rejection] = []
        if self._in_sentence:
            out.append(Rejection(Reason.TRUNCATED, f"{why} before the end of the line",
                                 bytes(self._sentence), len(self._sentence)))
        if self._discarding:
            self._end_overlong(out)
        self._end_garbage(out)
        self._sentence.clear()
        self._in_sentence = False
        return [r for r in out if isinstance(r, Rejection)]

    def resync(self) -> None:
        """Start mid-stream (a port just opened): the tail of a line before the first '$' is skipped.

        Call after :meth:`flush`.  A port opened while the camera is sending
        may start with the end of a line; that is no fault of the line.  Up
        to the first line end or '$' (at most one sentence's length) is
        skipped and counted in :attr:`skipped`; garbage after it is garbage.
        """
        self._sync_left = self._max

    @property
    def pending(self) -> int:
        """Bytes held back waiting for the rest of a sentence."""
        return len(self._sentence) if self._in_sentence else 0

    def _hunt(self, chunk: bytes, out: list[bytes | Rejection]) -> None:
        # Outside a sentence: bare line ends between sentences are harmless and
        # not garbage; anything else is, and a line end closes the run.
        start = 0
        while start < len(chunk):
            nl = chunk.find(b"\n", start)
            piece = chunk[start:] if nl < 0 else chunk[start:nl + 1]
            if piece.strip(b"\r\n") or self._garbage_size:
                self._add_garbage(piece)
            if nl < 0:
                break
            self._end_garbage(out)
            start = nl + 1

    def _add_garbage(self, piece: bytes) -> None:
        room = _KEEP - len(self._garbage)
        if room > 0:
            self._garbage += piece[:room]
        self._garbage_size += len(piece)

    def _end_garbage(self, out: list[bytes | Rejection]) -> None:
        if self._garbage_size:
            out.append(Rejection(Reason.GARBAGE, f"{self._garbage_size} bytes outside any sentence",
                                 bytes(self._garbage), self._garbage_size))
        self._garbage.clear()
        self._garbage_size = 0

    def _end_overlong(self, out: list[bytes | Rejection]) -> None:
        out.append(Rejection(Reason.OVERLONG, f"{self._discarding} bytes without an end of line, the longest"
                             f" valid sentence has {self._max}", bytes(self._sentence[:_KEEP]), self._discarding))
        self._sentence.clear()
        self._discarding = 0


def _find_end(data: bytes, start: int) -> int:
    """Index of the first '$' or '\\n' in ``data[start:]``, -1 if none."""
    dollar, newline = data.find(b"$", start), data.find(b"\n", start)
    if dollar < 0 or newline < 0:
        return max(dollar, newline)
    return min(dollar, newline)
