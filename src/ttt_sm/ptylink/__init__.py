"""The serial-line plumbing both emulated devices share: the camera's link and the arm's.

- :mod:`.port`: :class:`PtyLink`, a pseudo-terminal behind a stable symlink,
  the port of every emulated serial device;
- :mod:`.crc`: :func:`crc16`, the CRC-16/CCITT-FALSE both links' frames carry
  (the camera's in hex after ``*``, the arm's as two bytes before the COBS
  end), the same as the firmware's ``ttt_crc16``.
"""

from .crc import crc16
from .port import PtyLink, PtyLinkError, realtime_priority

__all__ = ["PtyLink", "PtyLinkError", "crc16", "realtime_priority"]
