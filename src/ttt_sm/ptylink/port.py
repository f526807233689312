"""A pseudo-terminal behind a stable symlink: the port of every emulated serial device.

The camera's emulator (:mod:`ttt_sm.smartcam.emulator`) and the arm's
(:mod:`ttt_sm.hardware.emulator`) each stand for a device on a serial port.
:class:`PtyLink` is the port they share: a pseudo-terminal in raw mode (bytes
pass as on a UART: no echo, no line discipline) whose master side the
emulator reads and writes without blocking, and whose slave side the PC opens
through a stable symlink, as udev's ``/dev/serial/by-id/...`` follows a USB
adapter from one ``/dev/ttyUSBn`` to the next (docs/smartcam.md).

The link path is checked when the :class:`PtyLink` is made: its folder must
exist, and a path already there must be a symlink (an emulator replaces only
its own links, never a file).  Without a path, the link lives in a fresh
temporary folder that :meth:`PtyLink.remove` deletes.
"""

from __future__ import annotations

import os
import shutil
import tempfile
import tty
from pathlib import Path


class PtyLinkError(ValueError):
    """The link path cannot be used: its folder is missing, or a file that is no symlink is there."""


class PtyLink:
    """A raw pseudo-terminal whose slave is reachable through the symlink :attr:`port`.

    Parameters
    ----------
    link
        Path of the stable symlink; None: ``name`` in a fresh temporary
        folder (prefix ``ttt-<name>-``), removed by :meth:`remove`.
    name
        What the device is (``"camera"``, ``"arm"``): the default link's name.
    """

    def __init__(self, link: str | os.PathLike[str] | None, name: str) -> None:
        #: The master side (non-blocking) while open, else None.
        self.master: int | None = None
        self._slave: int | None = None
        #: The slave, ``/dev/pts/N``, while open, else None.
        self.device: str | None = None
        self._own_dir: Path | None = None
        if link is None:
            self._own_dir = Path(tempfile.mkdtemp(prefix=f"ttt-{name}-"))
            link = self._own_dir / name
        self.link = Path(link)
        if not self.link.parent.is_dir():
            self.remove()
            raise PtyLinkError(f"the folder of the link {self.link} does not exist; create it or choose"
                               " another --link")
        if self.link.exists() and not self.link.is_symlink():
            self.remove()
            raise PtyLinkError(f"{self.link} exists and is not a symlink; the emulator only replaces its own"
                               " link: choose another --link")

    @property
    def port(self) -> str:
        """The stable path the PC opens."""
        return str(self.link)

    @property
    def is_open(self) -> bool:
        return self.master is not None

    def open(self) -> str:
        """Make a new pseudo-terminal and point :attr:`port` at it; returns its ``/dev/pts/N``.

        Already open: the current device.  The slave stays open on this side
        too, so the pty keeps its raw settings while the PC closes and reopens it.
        """
        if self.device is not None:
            return self.device
        master, slave = os.openpty()
        tty.setraw(slave)
        os.set_blocking(master, False)
        self.master, self._slave = master, slave
        self.device = os.ttyname(slave)
        tmp = self.link.with_name(f".{self.link.name}.{os.getpid()}.tmp")
        tmp.unlink(missing_ok=True)
        os.symlink(self.device, tmp)
        os.replace(tmp, self.link)  # atomic: a reader sees the old link or the new one
        return self.device

    def close(self) -> None:
        """Remove :attr:`port` and close the pseudo-terminal: the PC's next read fails, its reopen too."""
        if self.master is None:
            return
        self.link.unlink(missing_ok=True)
        for fd in (self.master, self._slave):
            if fd is not None:
                os.close(fd)
        self.master = self._slave = None
        self.device = None

    def remove(self) -> None:
        """Close, and delete the temporary folder when this link made it."""
        self.close()
        if self._own_dir is not None:
            shutil.rmtree(self._own_dir, ignore_errors=True)
            self._own_dir = None


__all__ = ["PtyLink", "PtyLinkError"]
