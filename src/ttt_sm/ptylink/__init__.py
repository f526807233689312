"""What every serial device of ``ttt_sm`` shares, on the PC's side and in its emulators.

The camera's link (:mod:`ttt_sm.smartcam`) and the arm's
(:mod:`ttt_sm.hardware.link`) are two protocols over two serial ports; beneath
both lie the same few pieces, one module each:

- :mod:`.port` -- :class:`PtyLink`, a raw pseudo-terminal behind a stable
  symlink: the port an emulator stands on and the PC opens;
- :mod:`.thread` -- :class:`DeviceThread`, an emulator's loop in a daemon
  thread, started and stopped;
- :mod:`.realtime` -- :func:`realtime_priority`, ``SCHED_FIFO`` for a loop
  that must keep its period;
- :mod:`.crc` -- :func:`crc16`, the CRC-16/CCITT-FALSE both protocols carry.

Nothing here imports another part of ``ttt_sm``.
"""

from .crc import crc16
from .port import PtyLink, PtyLinkError
from .realtime import realtime_priority
from .thread import DeviceThread

__all__ = ["DeviceThread", "PtyLink", "PtyLinkError", "crc16", "realtime_priority"]
