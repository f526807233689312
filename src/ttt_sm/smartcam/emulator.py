"""The camera's end of the link, emulated: frames on a real pseudo-terminal, with faults on demand.

The thesis' NI 1742 runs its Vision Builder program on its own processor and
writes the 25 percentages to its serial port (section 3.6.3).
:class:`CameraEmulator` does the same from a ``frame_source`` callable (the
game plugs the simulated camera and the vision detector into it), at a set
rate, in a background thread, on the master side of a pseudo-terminal.  The
PC side opens the slave (``/dev/pts/N``) with pyserial like any serial port.

Replugging works as it does with a USB serial adapter and udev: the kernel
device comes and goes (a new pty gets a new ``/dev/pts/N``), a *stable
symlink* follows it (udev's ``/dev/serial/by-id/...``; here :attr:`port`).
:meth:`unplug` removes the link and closes the pty, so the reader's next read
fails as on a yanked cable; :meth:`plug` makes a new pty and points the link
at it, so the reader's reopen by name finds it.

Faults for tests (:class:`Fault`) are queued with :meth:`inject` and applied
to the next frame(s) the thread sends, or given to :meth:`send_frame`.
"""

from __future__ import annotations

import logging
import os
import select
import threading
import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from enum import StrEnum

from ..ptylink import DeviceThread, PtyLink, PtyLinkError
from .errors import EncodeError, SerialLinkError
from .protocol import CELLS, MAX_STATUS_TEXT, SEQ_MODULUS, Level, encode_frame, encode_status, wrap_sentence

FrameSource = Callable[[], Sequence[float]]
"""Returns the 25 percentages of the field as the camera sees it now (row-major, image order, percent)."""

_LOG = logging.getLogger(__name__)


class EmulatorError(SerialLinkError):
    """The emulator cannot do what was asked (a link path that is not ours, a stopped emulator)."""


class FaultKind(StrEnum):
    """What can go wrong on the camera's side or on the wire."""

    CORRUPT_CHECKSUM = "corrupt_checksum"  # a wrong CRC, as after a bit flip on the wire
    TRUNCATE = "truncate"                  # the line stops part way (a dropped buffer, a reset)
    OUT_OF_RANGE = "out_of_range"          # a percentage > 100 with a right CRC (a camera bug)
    NOT_FINITE = "not_finite"              # NaN with a right CRC
    NON_NUMERIC = "non_numeric"            # text in a number field, right CRC
    FIELD_COUNT = "field_count"            # a percentage missing, right CRC
    GARBAGE = "garbage"                    # line noise before the frame
    OVERLONG = "overlong"                  # a runaway line with no end
    SKIP = "skip"                          # frames lost: the sequence number jumps
    DUPLICATE = "duplicate"                # the same frame twice
    PAUSE = "pause"                        # the camera stops sending for a while (port stays)
    DISCONNECT = "disconnect"              # the port goes away for a while, then comes back


@dataclass(frozen=True)
class Fault:
    """One fault to apply to the next frame; make them with the class methods."""

    kind: FaultKind
    cell: int = 1
    """For the value faults: which cell (1..25) gets the bad value."""
    value: str = ""
    """For the value faults: the text put on the wire."""
    count: int = 1
    """For SKIP: frames skipped."""
    seconds: float = 0.0
    """For PAUSE and DISCONNECT: how long."""
    data: bytes = b""
    """For GARBAGE: the noise."""
    keep: float = 0.5
    """For TRUNCATE: the share of the line that is sent."""

    @classmethod
    def corrupt_checksum(cls) -> Fault:
        return cls(FaultKind.CORRUPT_CHECKSUM)

    @classmethod
    def truncate(cls, keep: float = 0.5) -> Fault:
        return cls(FaultKind.TRUNCATE, keep=keep)

    @classmethod
    def out_of_range(cls, cell: int = 1, value: float = 150.0) -> Fault:
        return cls(FaultKind.OUT_OF_RANGE, cell=cell, value=f"{value:.1f}")

    @classmethod
    def not_finite(cls, cell: int = 1, value: str = "nan") -> Fault:
        return cls(FaultKind.NOT_FINITE, cell=cell, value=value)

    @classmethod
    def non_numeric(cls, cell: int = 1, value: str = "abc") -> Fault:
        return cls(FaultKind.NON_NUMERIC, cell=cell, value=value)

    @classmethod
    def field_count(cls) -> Fault:
        return cls(FaultKind.FIELD_COUNT)

    @classmethod
    def garbage(cls, data: bytes = b"\x00\xff\xfe line noise \x13\x11\r\n") -> Fault:
        return cls(FaultKind.GARBAGE, data=data)

    @classmethod
    def overlong(cls, size: int = 400) -> Fault:
        return cls(FaultKind.OVERLONG, count=size)

    @classmethod
    def skip(cls, frames: int = 3) -> Fault:
        return cls(FaultKind.SKIP, count=frames)

    @classmethod
    def duplicate(cls) -> Fault:
        return cls(FaultKind.DUPLICATE)

    @classmethod
    def pause(cls, seconds: float) -> Fault:
        return cls(FaultKind.PAUSE, seconds=seconds)

    @classmethod
    def disconnect(cls, seconds: float) -> Fault:
        return cls(FaultKind.DISCONNECT, seconds=seconds)


def apply_fault(line: bytes, fault: Fault | None) -> bytes:
    """The bytes to send instead of the good frame ``line`` under ``fault`` (line-level faults only).

    SKIP, DUPLICATE, PAUSE and DISCONNECT act on the stream, not on the line,
    and return it unchanged.
    """
    if fault is None:
        return line
    kind = fault.kind
    if kind is FaultKind.CORRUPT_CHECKSUM:
        star = line.rindex(b"*")
        wrong = int(line[star + 1:star + 5], 16) ^ 0x0001
        return line[:star + 1] + f"{wrong:04X}".encode("ascii") + b"\r\n"
    if kind is FaultKind.TRUNCATE:
        return line[:max(1, min(len(line) - 3, int(len(line) * fault.keep)))]
    if kind in (FaultKind.OUT_OF_RANGE, FaultKind.NOT_FINITE, FaultKind.NON_NUMERIC):
        if not 1 <= fault.cell <= CELLS:
            raise ValueError(f"fault cell must be 1..{CELLS}, got {fault.cell}")
        fields = _body(line).split(b",")
        fields[1 + fault.cell] = fault.value.encode("ascii")
        return wrap_sentence(b",".join(fields))
    if kind is FaultKind.FIELD_COUNT:
        return wrap_sentence(_body(line).rsplit(b",", 1)[0])
    if kind is FaultKind.GARBAGE:
        return fault.data + line
    if kind is FaultKind.OVERLONG:
        return b"$TTT," + b"1" * fault.count + b"\r\n" + line
    return line


def _status_text(text: str) -> str:
    """``text`` made fit for a status line: printable ASCII without '$' and '*', at most 80 characters."""
    clean = "".join(ch if " " <= ch <= "~" and ch not in "$*" else "?" for ch in text)
    return clean if len(clean) <= MAX_STATUS_TEXT else clean[:MAX_STATUS_TEXT - 3] + "..."


def _body(line: bytes) -> bytes:
    return line[1:line.rindex(b"*")]


@dataclass(frozen=True)
class EmulatorStats:
    """What the emulator has done (a snapshot)."""

    frames_sent: int
    frames_dropped: int
    """Frames produced while unplugged or not written in time (a full buffer: nobody reading)."""
    bytes_written: int
    bytes_dropped: int
    faults_applied: int
    source_errors: int
    plugs: int
    unplugs: int


class CameraEmulator:
    """A smart camera on a pseudo-terminal: sends ``frame_source()`` as frames at ``rate_hz``.

    Parameters
    ----------
    frame_source
        Called once per frame, returns 25 percentages (row-major, percent).
        Needed by :meth:`start` and by :meth:`send_frame` without values.
    rate_hz
        Frames per second of the background thread.
    link
        Path of the stable symlink the reader opens (like udev's
        ``/dev/serial/by-id/...``).  Default: ``camera`` in a fresh temporary
        folder, removed by :meth:`stop`.  An existing path must be a symlink.
    first_seq
        Sequence number of the first frame.

    Use as a context manager (``with CameraEmulator(src) as cam:``), which
    plugs and starts it, or call :meth:`plug` and :meth:`send_frame` yourself
    for an exact sequence of lines.
    """

    def __init__(self, frame_source: FrameSource | None = None, *, rate_hz: float = 10.0,
                 link: str | os.PathLike[str] | None = None, first_seq: int = 0,
                 logger: logging.Logger | None = None) -> None:
        if not rate_hz > 0:
            raise ValueError(f"rate_hz must be > 0 frames per second, got {rate_hz}")
        if not 0 <= first_seq < SEQ_MODULUS:
            raise ValueError(f"first_seq must be 0..{SEQ_MODULUS - 1}, got {first_seq}")
        self._source = frame_source
        self.rate_hz = float(rate_hz)
        try:
            self._pty = PtyLink(link, "camera")
        except PtyLinkError as exc:
            raise EmulatorError(str(exc)) from None
        self._seq = first_seq
        self._log = logger or _LOG
        self._lock = threading.RLock()
        self._faults: deque[Fault] = deque()
        self._replug_at: float | None = None
        self._loop = DeviceThread(self._run, f"camera-emulator {self._pty.link}")
        self._n = {k: 0 for k in EmulatorStats.__dataclass_fields__}

    # -- the port -----------------------------------------------------------

    @property
    def port(self) -> str:
        """The stable path the reader opens (a symlink to the current pty)."""
        return self._pty.port

    @property
    def device(self) -> str | None:
        """The current pseudo-terminal slave, ``/dev/pts/N``; None while unplugged."""
        return self._pty.device

    @property
    def plugged(self) -> bool:
        return self._pty.is_open

    def plug(self) -> str:
        """Make a new pseudo-terminal and point :attr:`port` at it; returns its ``/dev/pts/N``."""
        with self._lock:
            if self._pty.is_open:
                assert self._pty.device is not None
                return self._pty.device
            device = self._pty.open()
            self._n["plugs"] += 1
            self._log.info("camera emulator: %s -> %s", self._pty.link, device)
            return device

    def unplug(self) -> None:
        """Remove :attr:`port` and close the pseudo-terminal: the reader's next read fails, its reopen too."""
        with self._lock:
            if not self._pty.is_open:
                return
            device = self._pty.device
            self._pty.close()
            self._log.info("camera emulator: %s unplugged (%s gone)", self._pty.link, device)
            self._n["unplugs"] += 1

    # -- the thread ---------------------------------------------------------

    def start(self) -> CameraEmulator:
        """Plug (if needed) and send frames from ``frame_source`` at ``rate_hz`` in a background thread."""
        if self._source is None:
            raise EmulatorError("start() needs a frame_source: the callable that returns the 25 percentages")
        if self._loop.started:
            return self
        self.plug()
        self._loop.start()
        return self

    def stop(self, timeout_s: float = 5.0) -> None:
        """Stop the thread (waiting at most ``timeout_s``), unplug, and remove the link's folder if it made it."""
        if not self._loop.stop(timeout_s):
            self._log.error("camera emulator: thread still busy after %g s (a frame_source that hangs?);"
                            " leaving it as a daemon", timeout_s)
        with self._lock:
            self.unplug()
            self._pty.remove()

    def __enter__(self) -> CameraEmulator:
        """Start streaming when there is a frame_source; only plug otherwise (send frames yourself)."""
        if self._source is not None:
            return self.start()
        self.plug()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    @property
    def running(self) -> bool:
        return self._loop.running

    def inject(self, *faults: Fault) -> None:
        """Queue faults; the thread applies one per frame, in order."""
        with self._lock:
            self._faults.extend(faults)

    @property
    def faults_pending(self) -> int:
        """Injected faults not yet applied."""
        return len(self._faults)

    def _run(self) -> None:
        period = 1.0 / self.rate_hz
        next_t = time.monotonic()
        stopping = self._loop.stopping
        while not stopping.is_set():
            try:
                self._tick()
            except Exception:  # keep the camera alive; the reader will see the gap
                self._log.exception("camera emulator: frame failed")
            next_t += period
            now = time.monotonic()
            if next_t < now - period:  # fell behind (a loaded machine): skip, do not burst
                next_t = now
            stopping.wait(max(0.0, next_t - now))

    def _tick(self) -> None:
        with self._lock:
            fault = self._faults.popleft() if self._faults else None
        if self._replug_at is not None and time.monotonic() >= self._replug_at:
            self._replug_at = None
            self.plug()
        if fault is not None and fault.kind is FaultKind.PAUSE:
            self._n["faults_applied"] += 1
            self._loop.stopping.wait(fault.seconds)  # the camera is busy: no frames, no sequence numbers used
            return
        if fault is not None and fault.kind is FaultKind.DISCONNECT:
            self._n["faults_applied"] += 1
            self.unplug()
            self._replug_at = time.monotonic() + fault.seconds
            fault = None  # this frame is still made, and lost, like every one until the replug
        self.send_frame(fault=fault, wait_s=0.5 / self.rate_hz)

    # -- sending ------------------------------------------------------------

    def send_frame(self, percentages: Sequence[float] | None = None, *, fault: Fault | None = None,
                   wait_s: float = 2.0) -> bytes:
        """Send one frame (``percentages``, or ``frame_source()``) with the next sequence number.

        Returns the bytes put on the wire (after ``fault``).  Waits up to
        ``wait_s`` for room in the pty; what does not fit is dropped, as a UART
        would.  Unplugged, the frame is made and counted as dropped.
        """
        if percentages is None:
            if self._source is None:
                raise EmulatorError("send_frame() without percentages needs a frame_source")
            try:
                percentages = self._source()
            except Exception as exc:  # the camera reports it and carries on
                self._n["source_errors"] += 1
                self._log.warning("camera emulator: frame_source failed: %r", exc)
                self.send_status(Level.ERROR, _status_text(f"no frame: {type(exc).__name__}: {exc}"))
                return b""
        with self._lock:
            seq = self._seq
            if fault is not None and fault.kind is FaultKind.SKIP:
                seq = (seq + fault.count) % SEQ_MODULUS
            try:
                line = encode_frame(seq, percentages)
            except EncodeError as exc:
                self._n["source_errors"] += 1
                self._log.warning("camera emulator: cannot send frame %d: %s", seq, exc)
                self.send_status(Level.ERROR, _status_text(f"bad frame from the detector: {exc}"))
                return b""
            self._seq = (seq + 1) % SEQ_MODULUS
            data = apply_fault(line, fault)
            if fault is not None:
                self._n["faults_applied"] += 1
                if fault.kind is FaultKind.DUPLICATE:
                    data = line + line
            if self._write(data, wait_s):
                self._n["frames_sent"] += 1
            else:
                self._n["frames_dropped"] += 1
            return data

    def send_status(self, level: Level | str, text: str, *, wait_s: float = 2.0) -> bytes:
        """Send a status line (``$TTS,<level>,<text>``)."""
        line = encode_status(level, text)
        self._write(line, wait_s)
        return line

    def send_raw(self, data: bytes, *, wait_s: float = 2.0) -> bool:
        """Put ``data`` on the wire as is (for tests of the reader); True if all of it went."""
        return self._write(bytes(data), wait_s)

    def _write(self, data: bytes, wait_s: float) -> bool:
        with self._lock:
            fd = self._pty.master
            if fd is None:
                self._n["bytes_dropped"] += len(data)
                return False
            self._drain(fd)
            view = memoryview(data)
            deadline = time.monotonic() + wait_s
            while view:
                try:
                    view = view[os.write(fd, view):]
                except BlockingIOError:
                    pass
                if not view:
                    break
                left = deadline - time.monotonic()
                if left <= 0:
                    break
                select.select([], [fd], [], min(left, 0.05))
            sent = len(data) - len(view)
            self._n["bytes_written"] += sent
            self._n["bytes_dropped"] += len(view)
            return not view

    @staticmethod
    def _drain(fd: int) -> None:
        # Whatever the PC writes to the camera is read and ignored, so the PC's
        # writes never block on a full buffer.
        try:
            while os.read(fd, 4096):
                pass
        except (BlockingIOError, OSError):
            pass

    @property
    def seq(self) -> int:
        """The sequence number the next frame gets."""
        return self._seq

    @property
    def stats(self) -> EmulatorStats:
        return EmulatorStats(**self._n)


__all__ = ["CameraEmulator", "EmulatorError", "EmulatorStats", "Fault", "FaultKind", "FrameSource",
           "apply_fault"]
