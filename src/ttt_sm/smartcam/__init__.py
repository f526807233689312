"""The smart camera's serial link (thesis section 3.6.3): protocol, reader, emulator.

The camera sends, per frame, the share of dark pixels in each of the 25
fields over a serial port; the PC reads them.  Layers, one way:

- :mod:`.protocol` -- the line format, a strict decoder, CRC-16;
- :mod:`.framing` -- bytes to sentences, resynchronising after garbage;
- :mod:`.burst_log` -- warnings rate-limited per kind and summed up per burst;
- :mod:`.reader` -- :class:`SerialCameraReader` on a pyserial port, with
  rejection counts, sequence gaps and bounded reconnects;
- :mod:`.emulator` -- :class:`CameraEmulator` on a real pseudo-terminal,
  with fault injection;
- :mod:`.sources` -- frame sources for the emulator (the vision detector,
  a text board).

Nothing here imports the game or the vision package.  See docs/smartcam.md.
"""

from .emulator import CameraEmulator, EmulatorError, EmulatorStats, Fault, FaultKind, FrameSource, apply_fault
from .errors import (
    CameraSilent,
    EncodeError,
    FrameError,
    LinkLost,
    PortUnavailable,
    Reason,
    SerialLinkError,
)
from .framing import LineFramer, Rejection
from .link import LinkStats, ReconnectPolicy
from .protocol import CELLS, MAX_SENTENCE_BYTES, Frame, Level, Status, crc16, decode_line, encode_frame, encode_status
from .reader import SerialCameraReader
from .sources import board_source, detection_source, parse_board

__all__ = [
    "CELLS", "MAX_SENTENCE_BYTES", "CameraEmulator", "CameraSilent", "EmulatorError", "EmulatorStats",
    "EncodeError", "Fault", "FaultKind", "Frame", "FrameError", "FrameSource", "Level", "LineFramer", "LinkLost",
    "LinkStats", "PortUnavailable", "Reason", "ReconnectPolicy", "Rejection", "SerialCameraReader",
    "SerialLinkError", "Status", "apply_fault", "board_source", "crc16", "decode_line", "detection_source",
    "encode_frame", "encode_status", "parse_board",
]
