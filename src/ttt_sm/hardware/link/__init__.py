"""The serial link to the firmware, the PC's side: frames, messages, and what is rejected.

The same specification as the firmware's ``firmware/src/link.c`` and
``fw.c`` (docs/hardware.md, "The link protocol"): a frame is

    type (u8) | seq (u16 LE) | body | CRC-16/CCITT-FALSE of the above (u16, MSB first)

COBS-encoded and closed by a 0x00 byte.  Bodies are little-endian.  One
module an idea, as the camera's link (:mod:`ttt_sm.smartcam`) is cut:

- :mod:`.protocol` -- the protocol's numbers and body layouts, written
  once: :class:`Msg`, :class:`Reason`, :class:`State`, :class:`Op`, the
  framing's sizes and every body's fields, from which the messages' formats
  and the firmware's ``protocol.h`` are made;
- :mod:`.rejections` -- :class:`Reason` (the firmware's ``TTT_REJ_*``) and
  :class:`Rejection`;
- :mod:`.messages` -- :class:`Msg`, the :class:`Message` types and their
  bodies, the length each type's body must have;
- :mod:`.framing` -- COBS, the CRC (:func:`ttt_sm.ptylink.crc16`), and
  :class:`FrameDecoder`, which cuts a byte stream, however it is chunked,
  into :class:`Frame` s and rejections;
- :mod:`.endpoint` -- one end: :class:`Sender` numbers the frames,
  :class:`SeqTracker` refuses duplicated and out-of-order ones,
  :class:`Receiver` does every check, decodes the messages, counts every
  rejection by reason and logs a line naming it.

Nothing here does I/O or reads a clock.
"""

from .endpoint import Receiver, Sender, SeqTracker
from .framing import (
    CRC_BYTES,
    HEADER,
    MAX_BODY,
    MAX_ENCODED,
    MAX_FRAME,
    Frame,
    FrameDecoder,
    cobs_decode,
    cobs_encode,
    crc16,
    encode_frame,
)
from .messages import (
    DRIVES,
    EMU_TRUTH_FLAG_GATED,
    GAINS_BLOCKS,
    MESSAGES,
    N_CG,
    N_CP,
    PROTOCOL_VERSION,
    STATE_NAMES,
    TO_FIRMWARE,
    TO_PC,
    Drive,
    EmuTruth,
    Gains,
    GainsRead,
    GainsReadback,
    Handshake,
    Heartbeat,
    HeartbeatReply,
    Hello,
    Message,
    Msg,
    Op,
    Setpoints,
    Start,
    State,
    Status,
    body_length,
    kind_name,
)
from .rejections import N_REASONS, Reason, Rejection

__all__ = [
    "CRC_BYTES", "DRIVES", "EMU_TRUTH_FLAG_GATED", "GAINS_BLOCKS", "HEADER", "MAX_BODY", "MAX_ENCODED", "MAX_FRAME",
    "MESSAGES", "N_CG", "N_CP", "N_REASONS", "PROTOCOL_VERSION", "STATE_NAMES", "TO_FIRMWARE", "TO_PC", "Drive",
    "EmuTruth", "Frame", "FrameDecoder", "Gains", "GainsRead", "GainsReadback", "Handshake", "Heartbeat",
    "HeartbeatReply", "Hello", "Message", "Msg", "Op", "Reason", "Receiver", "Rejection", "SeqTracker", "Sender",
    "Setpoints", "Start", "State", "Status", "body_length", "cobs_decode", "cobs_encode", "crc16", "encode_frame",
    "kind_name",
]
