"""One end of the arm's link: it numbers what it sends, and checks what it receives down to the message.

:class:`Sender` numbers the frames of one direction; :class:`SeqTracker`
refuses duplicated and out-of-order numbers (``ttt_seq_accept`` in
``link.c``); :class:`Receiver` cuts frames (:mod:`.framing`), checks their
numbers, decodes the messages (:mod:`.messages`), counts every rejection
by :class:`~.rejections.Reason` and logs a line naming it.  Nothing here
does I/O or reads a clock.
"""

from __future__ import annotations

import logging
from collections import Counter
from dataclasses import dataclass, field

from .framing import FrameDecoder, encode_frame
from .messages import MESSAGES, TO_PC, Message, Msg, kind_name
from .protocol import SEQ_BEHIND
from .rejections import Reason, Rejection

log = logging.getLogger("ttt_sm.link")


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
            if delta >= SEQ_BEHIND:
                return Reason.OUT_OF_ORDER
            self.lost += delta - 1
        self.last = seq
        return None


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
                self.reject(Rejection(Reason.UNKNOWN_TYPE, f"{kind_name(item.kind)} seq {item.seq} is not for "
                                      f"the {self.name}", 0))
                continue
            if item.kind in (Msg.HELLO, Msg.HANDSHAKE):
                self.seq.reset()
            seq = self.emu_seq if item.kind == Msg.EMU_TRUTH else self.seq
            refused = seq.accept(item.seq)
            if refused is not None:
                self.reject(Rejection(refused, f"{kind_name(item.kind)} seq {item.seq} after {seq.last}", 0))
                continue
            message = MESSAGES[item.kind].unpack(item.body)
            bad = message.check()
            if bad is not None:
                self.reject(Rejection(Reason.VALUE, f"{kind_name(item.kind)} seq {item.seq}: {bad}", 0))
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


__all__ = ["Receiver", "SeqTracker", "Sender", "log"]
