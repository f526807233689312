"""The PC's end of the camera link: read frames from a serial port, survive what a real cable does.

:class:`SerialCameraReader` plays the part of Simulink's *Stream input*
block in the thesis (section 3.6.3): it reads the camera's percentages from
the serial port and hands the game the newest ones.  Around that it does
what the thesis' set-up got from the hardware being well behaved:

- every line is checked (:func:`~.protocol.decode_line`); a bad one is
  rejected, counted by reason and logged with a snippet, and the next good
  frame is found after any garbage (:class:`~.framing.LineFramer`);
- sequence numbers show frames lost on the way (gaps), repeated (duplicates,
  dropped) or a camera that restarted (the number went back);
- a port that disappears or fails (``SerialException``, EOF, ``EIO``) is
  closed and reopened by name with bounded exponential backoff; the reader
  gives up with :class:`~.errors.LinkLost` after ``max_attempts`` or
  ``max_duration_s``, whichever comes first;
- an open port with no valid frame for ``silence_s`` is reported once (a
  pulled cable on a built-in COM port looks like that, not like an error),
  but only while frames are expected: a camera that sends only when asked
  (the game's, between two readings) is idle by design, and
  :meth:`SerialCameraReader.expect_frames` says so.

Every call is bounded in time: reads use the port's timeout and a deadline,
reconnect attempts are bounded in number and time.  One thread uses a reader.
"""

from __future__ import annotations

import logging
import os
import time
from collections import deque
from collections.abc import Callable, Iterator
from typing import TypeAlias

import serial

from .burst_log import BurstLog
from .errors import CameraSilent, FrameError, LinkLost, PortUnavailable, Reason, SerialLinkError, snippet
from .framing import LineFramer, Rejection
from .link import LinkCounters, LinkStats, ReconnectPolicy
from .protocol import SEQ_MODULUS, Frame, Level, Status, decode_line

PortSpec: TypeAlias = "str | serial.SerialBase | Callable[[], serial.SerialBase]"
"""What a reader opens: a pyserial URL or device path (``/dev/ttyUSB0``, a stable
symlink, ``socket://host:port``, ``spy:///dev/pts/3``), a ``serial.Serial``
(reopened with ``.open()``), or a callable returning an open port."""

_CHUNK = 4096
_LOG = logging.getLogger(__name__)



class SerialCameraReader:
    """Reads the camera's frames from a serial port; rejects bad lines, notes gaps, reconnects.

    Parameters
    ----------
    port
        A pyserial URL or device path, a ``serial.Serial``, or a callable
        returning an open port (see :data:`PortSpec`).  Give a *stable* name
        (a udev ``/dev/serial/by-id/...`` link, or the emulator's link) so a
        replugged device is found again.
    timeout_s
        Default wait of :meth:`read_frame`, seconds.
    baudrate
        For a real port; a pseudo-terminal ignores it.
    reconnect
        Bounds of (re)opening; see :class:`ReconnectPolicy`.
    silence_s
        An open port without a valid frame for this long is reported (once
        per silence), seconds.
    poll_s
        Longest single blocking read on the port, seconds: how late the
        reader may notice a deadline.
    flush_on_open
        Drop bytes queued in the port before it was (re)opened: they are
        stale camera frames.

    The port is opened by :meth:`open` (or ``with``), or on the first read.
    """

    def __init__(self, port: PortSpec, timeout_s: float = 1.0, *, baudrate: int = 115200,
                 reconnect: ReconnectPolicy | None = None, silence_s: float = 2.0, poll_s: float = 0.05,
                 flush_on_open: bool = True, logger: logging.Logger | None = None) -> None:
        if not timeout_s >= 0 or not poll_s > 0 or not silence_s > 0:
            raise ValueError(f"timeout_s >= 0, poll_s > 0 and silence_s > 0 seconds, got {timeout_s}, {poll_s},"
                             f" {silence_s}")
        self._spec = port
        self.timeout_s = float(timeout_s)
        self.port_name = _describe(port)
        self._baudrate = baudrate
        self._policy = reconnect or ReconnectPolicy()
        self._silence_s = float(silence_s)
        self._poll_s = float(poll_s)
        self._flush_on_open = flush_on_open
        self._log = logger or _LOG

        self._ser: serial.SerialBase | None = None
        self._closed = False
        self._ever_connected = False
        self._down_since: float | None = None   # when the link went down / opening began; None while up
        self._attempts = 0
        self._next_attempt = 0.0
        self._last_error: BaseException | None = None
        self._lost: SerialLinkError | None = None

        self._framer = LineFramer()
        self._pending: deque[Frame] = deque()
        self._latest: Frame | None = None
        self._latest_at: float | None = None
        self._last_frame_at = 0.0
        self._expecting = True
        self._expected_since = 0.0
        self._silent = False
        self._last_seq: int | None = None
        self._n = LinkCounters()
        self._burst = BurstLog(self._log, self.port_name, self._summary)
        self.last_status: Status | None = None
        """The latest status line from the camera, if any."""

    # -- life cycle ---------------------------------------------------------

    def open(self) -> SerialCameraReader:
        """Open the port now, retrying within the reconnect policy; raises PortUnavailable when it cannot."""
        self._check_usable()
        while self._ser is None:
            self._connect_step(deadline=float("inf"))
        return self

    def close(self) -> None:
        """Close the port; the reader cannot be used afterwards."""
        self._closed = True
        self._burst.end()
        self._close_port()

    def __enter__(self) -> SerialCameraReader:
        return self.open()

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def silent(self) -> bool:
        """The silence watchdog fired: no valid frame for ``silence_s`` while frames were expected (until the
        next valid frame)."""
        return self._silent

    def expect_frames(self, expected: bool) -> None:
        """Say whether frames should be arriving now: the silence watchdog only runs while they should.

        A reader expects frames from the start (a camera that streams).  A
        camera that sends a frame only when asked (the game's: one photo per
        reading) is idle by design between two requests: call
        ``expect_frames(False)`` when done with a reading and
        ``expect_frames(True)`` when asking for the next; the silence is then
        measured from the request, not from the last frame before the pause.
        """
        if expected and not self._expecting:
            self._expected_since = time.monotonic()
        self._expecting = expected

    @property
    def connected(self) -> bool:
        """Whether the port is open now."""
        return self._ser is not None

    @property
    def device(self) -> str | None:
        """The device open now (a symlink resolved: ``/dev/pts/3`` for the emulator's link), None while down."""
        return None if self._ser is None else _resolve(self._ser.port)

    # -- reading ------------------------------------------------------------

    def read_frame(self, timeout_s: float | None = None) -> Frame | None:
        """The next valid frame, in wire order, or None when none arrives within ``timeout_s``.

        Waits at most ``timeout_s`` (default: the reader's ``timeout_s``) plus
        one ``poll_s``.  Raises :class:`LinkLost` / :class:`PortUnavailable`
        once the reconnect policy is exhausted.
        """
        self._check_usable()
        wait = self.timeout_s if timeout_s is None else float(timeout_s)
        deadline = time.monotonic() + max(0.0, wait)
        while not self._pending:
            self._step(deadline)
            if not self._pending and time.monotonic() >= deadline:
                return None
        return self._pending.popleft()

    def latest(self) -> Frame | None:
        """The newest valid frame seen so far (None before the first), reading what is waiting without blocking.

        What the game polls each cycle, like the thesis' *Stream input* block:
        frames not yet returned by :meth:`read_frame` are skipped.  Pair it
        with :meth:`age_s` to tell a fresh frame from an old one.
        """
        self._check_usable()
        now = time.monotonic()
        for _ in range(64):  # bounded even if bytes flood in as fast as we read them
            before = self._n.bytes_read
            self._step(now)
            if self._ser is None or self._n.bytes_read == before:
                break
        self._pending.clear()
        return self._latest

    def age_s(self) -> float | None:
        """Seconds since the newest valid frame arrived, None before the first."""
        return None if self._latest_at is None else time.monotonic() - self._latest_at

    def frames(self, count: int | None = None, idle_timeout_s: float | None = None) -> Iterator[Frame]:
        """Yield frames as they come: ``count`` of them, or forever.

        Raises :class:`CameraSilent` when no valid frame comes within
        ``idle_timeout_s`` (default: ``timeout_s``), so a loop over it never
        waits forever.
        """
        wait = self.timeout_s if idle_timeout_s is None else idle_timeout_s
        n = 0
        while count is None or n < count:
            frame = self.read_frame(wait)
            if frame is None:
                raise CameraSilent(f"no valid frame from {self.port_name} within {wait:g} s"
                                   f" ({self._summary()}); is the camera running and sending?")
            yield frame
            n += 1

    def __iter__(self) -> Iterator[Frame]:
        return self.frames()

    @property
    def stats(self) -> LinkStats:
        """Counts so far (a snapshot)."""
        return self._n.snapshot(self._framer.skipped)

    # -- one step: read a chunk, or try to (re)open --------------------------

    def _check_usable(self) -> None:
        if self._closed:
            raise SerialLinkError(f"the reader of {self.port_name} is closed; make a new one")
        if self._lost is not None:
            raise type(self._lost)(str(self._lost))  # a fresh one: the first keeps its own traceback

    def _step(self, deadline: float) -> None:
        if self._ser is None:
            self._connect_step(deadline)
        else:
            self._read_step(deadline)

    def _read_step(self, deadline: float) -> None:
        # The port's timeout stays poll_s: setting it reconfigures the port
        # (tcsetattr), which some USB adapters do not take well many times a
        # second.  Past the deadline, only what is already waiting is read.
        ser = self._ser
        assert ser is not None
        try:
            waiting = ser.in_waiting
            if waiting or time.monotonic() < deadline:
                data = ser.read(min(max(waiting, 1), _CHUNK))
            else:
                data = b""
        except (OSError, serial.SerialException) as exc:  # SerialException, EIO from in_waiting, EOF
            self._went_down(exc)
            return
        if data:
            self._consume(data)
        self._check_silence()

    def _connect_step(self, deadline: float) -> None:
        now = time.monotonic()
        if self._down_since is None:  # first open
            self._down_since, self._attempts, self._next_attempt = now, 0, now
        if now < self._next_attempt:
            time.sleep(max(0.0, min(self._next_attempt, deadline) - now))
            if time.monotonic() < self._next_attempt:
                return
        try:
            ser = self._open_port()
        except ValueError as exc:  # a malformed URL or setting: retrying cannot help
            self._lost = PortUnavailable(f"cannot open {self.port_name}: {exc}")
            raise self._lost from exc
        except (OSError, serial.SerialException) as exc:
            self._open_failed(exc)
            return
        self._up(ser)

    def _open_port(self) -> serial.SerialBase:
        spec = self._spec
        if isinstance(spec, str):
            ser = serial.serial_for_url(spec, baudrate=self._baudrate, timeout=self._poll_s)
        elif isinstance(spec, serial.SerialBase):
            ser = spec
            if not ser.is_open:
                ser.open()
        else:
            ser = spec()
            if not ser.is_open:
                ser.open()
        if ser.timeout != self._poll_s:
            ser.timeout = self._poll_s
        return ser

    def _open_failed(self, exc: BaseException) -> None:
        now = time.monotonic()
        assert self._down_since is not None
        self._attempts += 1
        self._last_error = exc
        elapsed = now - self._down_since
        limit = self._down_since + self._policy.max_duration_s
        self._log.debug("camera %s: open attempt %d failed: %s", self.port_name, self._attempts, exc)
        if self._attempts >= self._policy.max_attempts or now >= limit:
            what = "never came back" if self._ever_connected else "could not be opened"
            msg = (f"camera port {self.port_name} {what}: {self._attempts} attempts in {elapsed:.1f} s,"
                   f" last error: {exc}; check the cable and that the camera (or `ttt-sm camera serve`) runs")
            self._lost = LinkLost(msg) if self._ever_connected else PortUnavailable(msg)
            raise self._lost from exc
        self._next_attempt = min(now + self._policy.delay_s(self._attempts - 1), limit)

    def _up(self, ser: serial.SerialBase) -> None:
        now = time.monotonic()
        if self._flush_on_open:
            try:
                ser.reset_input_buffer()
            except (OSError, serial.SerialException):
                pass  # not every URL handler can; stale bytes are then read and judged like any others
        self._ser = ser
        self._framer.resync()
        if self._ever_connected:
            self._n.reconnects += 1
            assert self._down_since is not None
            self._log.warning("camera %s: link back on %s after %d failed attempts, %.2f s down",
                              self.port_name, _resolve(ser.port), self._attempts, now - self._down_since)
        else:
            self._log.info("camera %s: link open on %s", self.port_name, _resolve(ser.port))
        self._ever_connected = True
        self._down_since = None
        self._attempts = 0
        self._last_frame_at = now
        self._silent = False

    def _went_down(self, exc: BaseException) -> None:
        now = time.monotonic()
        for rejection in self._framer.flush("the link went down"):
            self._reject(rejection.reason, rejection.detail, rejection.snippet, rejection.size)
        self._close_port()
        self._n.disconnects += 1
        self._down_since, self._attempts = now, 0
        self._next_attempt = now + self._policy.delay_s(0)
        self._log.warning("camera %s: link lost (%s); reopening, at most %d attempts in %g s",
                          self.port_name, exc, self._policy.max_attempts, self._policy.max_duration_s)

    def _close_port(self) -> None:
        ser, self._ser = self._ser, None
        if ser is not None:
            try:
                ser.close()
            except (OSError, serial.SerialException):
                pass  # it is already gone; closing is only tidying up

    # -- judging what arrived -----------------------------------------------

    def _consume(self, data: bytes) -> None:
        self._n.bytes_read += len(data)
        for item in self._framer.feed(data):
            if isinstance(item, Rejection):
                self._reject(item.reason, item.detail, item.snippet, item.size)
                continue
            try:
                message = decode_line(item)
            except FrameError as exc:
                self._reject(exc.reason, exc.detail, exc.line, len(exc.line))
                continue
            if isinstance(message, Frame):
                self._accept(message)
            else:
                self._status(message)

    def _accept(self, frame: Frame) -> None:
        self._burst.end()  # a good frame ends every burst of bad lines
        now = time.monotonic()
        if self._last_seq is not None:
            step = (frame.seq - self._last_seq) % SEQ_MODULUS
            if step == 0:
                self._n.duplicates += 1
                self._burst.say("duplicate", "duplicate frame %d dropped", frame.seq)
                return
            if 1 < step < SEQ_MODULUS // 2:
                self._n.gaps += 1
                self._n.frames_missed += step - 1
                self._burst.say("gap", "sequence gap: expected %d, got %d (%d frame(s) missed)",
                          (self._last_seq + 1) % SEQ_MODULUS, frame.seq, step - 1)
            elif step >= SEQ_MODULUS // 2:
                self._n.seq_restarts += 1
                self._burst.say("restart", "sequence went back from %d to %d: the camera restarted?",
                          self._last_seq, frame.seq)
        if self._silent:
            self._log.warning("camera %s: frames again after %.2f s of silence", self.port_name,
                              now - self._last_frame_at)
            self._silent = False
        self._last_seq = frame.seq
        self._last_frame_at = self._latest_at = now
        self._latest = frame
        self._pending.append(frame)
        self._n.frames_ok += 1

    def _status(self, status: Status) -> None:
        self._n.statuses += 1
        self.last_status = status
        level = {Level.INFO: logging.INFO, Level.WARN: logging.WARNING, Level.ERROR: logging.ERROR}[status.level]
        self._log.log(level, "camera %s says %s: %s", self.port_name, status.level.value, status.text)

    def _reject(self, reason: Reason, detail: str, raw: bytes, size: int) -> None:
        counts = self._n.rejected
        counts[reason.value] = counts.get(reason.value, 0) + 1
        if reason is Reason.GARBAGE:
            self._n.garbage_bytes += size
        self._burst.say(reason.value, "rejected %s: %s; line %s", reason.value, detail, snippet(raw))

    def _check_silence(self) -> None:
        if not self._expecting or self._silent:
            return
        if time.monotonic() - max(self._last_frame_at, self._expected_since) > self._silence_s:
            self._silent = True
            self._n.silences += 1
            self._log.warning("camera %s: port open but no valid frame for %.1f s (%s); camera stopped or"
                              " cable pulled?", self.port_name, self._silence_s, self._summary())

    def _summary(self) -> str:
        n = self._n
        rejected = ", ".join(f"{k} {v}" for k, v in sorted(n.rejected.items())) or "none"
        return f"{n.frames_ok} frames so far, {n.bytes_read} bytes read, rejected: {rejected}"


def _resolve(name: str | None) -> str | None:
    """A device path with symlinks resolved (what a stable link points at now); URLs unchanged."""
    if name and name.startswith("/") and os.path.islink(name):
        return os.path.realpath(name)
    return name


def _describe(port: PortSpec) -> str:
    if isinstance(port, str):
        return port
    if isinstance(port, serial.SerialBase):
        return str(port.port)
    return getattr(port, "__name__", repr(port))
