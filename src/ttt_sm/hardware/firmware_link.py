"""The PC's end of the link to the firmware: the port, the wire under one lock, the keeper that watches it idle.

:class:`FirmwareLink` owns the serial port (pyserial: a board's
``/dev/ttyACM0``, or ``ttt-sm arm serve``'s pseudo-terminal) and what comes
over it: the firmware's ``STATUS`` frames (the last one kept), the replies
a command waits for, the emulator's ``EMU_TRUTH``.  One thread at a time
sends, reads and decodes: the chart loop while it waits for a status, or,
while the PC has nothing to send (the charts paused, a debugger at a
breakpoint), the link's keeper, a background thread that sends a
``HEARTBEAT`` every :data:`HEARTBEAT_PERIOD_S` (the firmware answers with a
``HEARTBEAT_REPLY``; on its own clock it also goes on sending its
``STATUS``).

The link is declared lost when no valid status arrives within
:data:`LINK_TIMEOUT_S` of wall-clock time while one is due, or the port
fails.  A loss is a :class:`LinkLoss` (:attr:`FirmwareLink.lost`, and the
``on_link_lost`` callback); it stays until the arm re-arms the firmware
(:meth:`~ttt_sm.hardware.serial_arm.SerialArm.rearm`).  Rejected frames
are counted and logged by its :class:`~ttt_sm.hardware.link.Receiver`.
:class:`~ttt_sm.hardware.serial_arm.SerialArm` is the
:class:`~ttt_sm.arm.Arm` built on it.
"""

from __future__ import annotations

import itertools
import os
import select
import threading
import time
from collections.abc import Callable
from contextlib import AbstractContextManager
from dataclasses import dataclass
from typing import TypeVar

import serial

from ..params import ArmParams
from . import link as L
from .link_truth import LinkTruth

LINK_TIMEOUT_S = 0.050
"""No valid status for this long while one is due: the link is lost."""
GATED_TIMEOUT_S = 5.0
"""The same for a gated emulator (it says so in its ``EMU_TRUTH``): it keeps no deadline, and shares the
PC's processor, so a loaded machine may hold it up; only a link that is really gone is lost."""
HEARTBEAT_PERIOD_S = 0.010
"""With nothing sent for this long, the PC sends a ``HEARTBEAT``: an idle link stays watched both ways."""
KEEPER_TICK_S = 0.002
"""How often the idle link's keeper looks at the clock."""
HANDSHAKE_TIMEOUT_S = 2.0
BAUD = 921_600


M = TypeVar("M", bound=L.Message)


@dataclass(frozen=True)
class LinkLoss:
    """The PC declared the link lost: why, and the clock readings it decided on (``time.monotonic``, s).

    ``last_frame_at``: the last valid frame from the firmware.  ``declared_at``:
    when the silence was found longer than ``timeout_s``.  ``checked_before``:
    the look before that one, when it was not yet (the loss is declared at
    the first look past the limit).
    """

    reason: str
    last_frame_at: float
    declared_at: float
    checked_before: float
    timeout_s: float

    @property
    def silence_s(self) -> float:
        """How long nothing valid had come when the loss was declared."""
        return self.declared_at - self.last_frame_at


class SerialArmError(RuntimeError):
    """The firmware is not the one expected (handshake, gains read-back), or refused a command."""


class LinkLost(SerialArmError):
    """No valid frame from the firmware within the link's timeout (while opening it, or asked for a reply)."""


class FirmwareLink(AbstractContextManager["FirmwareLink"]):
    """The port to the firmware and the frames that come over it; the link's keeper and its loss.

    Parameters
    ----------
    port
        A pyserial URL or device path.
    params
        The parameter file: the control period (the wall clock's steps while the link is down), and the
        emulator's ground truth's geometry.
    link_timeout_s
        Wall-clock seconds without a valid status before the link is lost.
    baudrate
        The port's speed, bit/s.
    """

    def __init__(self, port: str, params: ArmParams, link_timeout_s: float = LINK_TIMEOUT_S,
                 baudrate: int = BAUD) -> None:
        self.params = params
        self.dt = params.control.dt
        self.link_timeout_s = link_timeout_s
        self.rx = L.Receiver(name="pc")
        self.tx = L.Sender()
        self.bytes_sent = 0
        self.bytes_received = 0
        self._status: L.Status | None = None
        #: The emulator's ground truth (simulation only); None from a board, which sends none.
        self.truth: LinkTruth | None = None
        #: Whether the other end is a gated emulator (its ``EMU_TRUTH`` says so): it keeps no deadline.
        self.gated = False
        self._replies: list[L.Message] = []
        #: The wire: one thread at a time sends, reads and decodes (the chart loop, or the idle link's keeper).
        self._io = threading.RLock()
        self._last_tx = time.monotonic()
        #: When the last valid frame came from the firmware (``time.monotonic``).
        self.last_frame_at = time.monotonic()
        #: The link's loss, while it lasts (a valid frame clears it); :attr:`losses` keeps every one.
        self.lost: LinkLoss | None = None
        self.losses: list[LinkLoss] = []
        #: Called (from the keeper's thread) when the PC declares the link lost.
        self.on_link_lost: Callable[[LinkLoss], None] | None = None
        self.heartbeats_sent = 0
        self.heartbeat_replies = 0
        self._tokens = itertools.count(1)
        #: When (``time.monotonic``) the last new STATUS came, and its firmware step.
        self.status_at = 0.0
        self.status_step = 0
        #: When (``time.monotonic``) the PC first saw the firmware out of ``running`` (its watchdog tripped),
        #: None while it runs.
        self.stop_seen_at: float | None = None
        #: When the last STATUS frame came, new or not (``time.monotonic``).
        self.status_seen_at = 0.0
        #: The link's timeout against a gated emulator (:data:`GATED_TIMEOUT_S`).
        self.gated_timeout_s = GATED_TIMEOUT_S
        self._closing = threading.Event()
        self._keeper: threading.Thread | None = None
        # The keeper runs at its maker's scheduling priority: one that ran lower could be held off the
        # processor while holding the interpreter's lock, and hold up a chart loop of higher priority.
        get_policy = getattr(os, "sched_getscheduler", None)
        self._policy = (get_policy(0), os.sched_getparam(0)) if get_policy is not None else None
        try:
            self._ser = serial.serial_for_url(port, baudrate=baudrate, timeout=0)
        except (OSError, serial.SerialException) as e:
            raise SerialArmError(f"cannot open the arm's port {port}: {e}") from e
        fileno = getattr(self._ser, "fileno", None)
        try:
            self._fd: int | None = fileno() if fileno is not None else None
        except (OSError, serial.SerialException, AttributeError):
            self._fd = None

    def _start_keeper(self, port: str) -> None:
        """Start the link's keeper (once the link is open: the handshake is the opener's)."""
        self._keeper = threading.Thread(target=self._keep, name=f"serial-arm keeper {port}", daemon=True)
        self._keeper.start()

    def close(self) -> None:
        self._closing.set()
        keeper, self._keeper = self._keeper, None
        if keeper is not None and keeper is not threading.current_thread():
            keeper.join(1.0)
        with self._io:
            self._ser.close()

    def __exit__(self, *exc: object) -> None:
        self.close()

    # ---- the wire -------------------------------------------------------------------
    def _send(self, message: L.Message) -> None:
        data = self.tx.frame(message)
        try:
            self._ser.write(data)
        except (OSError, serial.SerialException) as e:
            raise LinkLost(f"cannot write to the arm's port: {e}") from e
        self.bytes_sent += len(data)
        self._last_tx = time.monotonic()

    def _poll(self, wait_s: float = 0.0) -> None:
        """Read what has come (waiting up to `wait_s` for a first byte, without spinning) and take its frames."""
        try:
            if wait_s > 0 and not self._ser.in_waiting and self._fd is not None:
                select.select([self._fd], [], [], wait_s)
            data = self._ser.read(self._ser.in_waiting or 1)
        except (OSError, serial.SerialException) as e:
            raise LinkLost(f"cannot read from the arm's port: {e}") from e
        if data:
            self.bytes_received += len(data)
            messages = self.rx.feed(data)
            if messages:
                self.last_frame_at = time.monotonic()
            for m in messages:
                if isinstance(m, L.Status):
                    self.status_seen_at = self.last_frame_at
                    if self._status is None or m.step > self._status.step or m.state != self._status.state:
                        if m.state != L.State.RUNNING and self.stop_seen_at is None and self._status is not None \
                                and self._status.state == L.State.RUNNING:
                            self.stop_seen_at = self.last_frame_at
                        self._status = m
                        self.status_at, self.status_step = self.last_frame_at, m.step
                elif isinstance(m, L.HeartbeatReply):
                    self.heartbeat_replies += 1
                    self._replies.append(m)
                    del self._replies[:-8]  # replies nobody asked for (the keeper's) are not kept
                elif isinstance(m, L.EmuTruth):
                    self.gated = m.gated
                    if self.truth is None:
                        self.truth = LinkTruth(self.params, m.q, m.offsets, m.step)
                    else:
                        self.truth.update(m.q, m.step, m.offsets)
                else:
                    self._replies.append(m)

    def _wait_for(self, kind: type[M], timeout_s: float, after_start: bool = False) -> M:
        give_up = time.monotonic() + timeout_s
        while True:
            for i, m in enumerate(self._replies):
                if isinstance(m, kind):
                    del self._replies[i]
                    return m
            status = self._status
            if kind is L.Status and status is not None and (not after_start or status.state == L.State.RUNNING):
                return status  # type: ignore[return-value]  # kind is Status
            if time.monotonic() > give_up:
                raise LinkLost(f"no {kind.__name__} from the firmware within {timeout_s * 1000:.0f} ms "
                               f"({self.rx.rejected} frames rejected)")
            self._poll(min(0.005, max(0.0, give_up - time.monotonic())))

    def _timeout(self) -> float:
        return max(self.link_timeout_s, self.gated_timeout_s) if self.gated else self.link_timeout_s

    def _keep(self) -> None:
        """The link's keeper: a HEARTBEAT when nothing was sent for a while; a loss declared on silence.

        It looks every :data:`KEEPER_TICK_S` while the wire is free (the chart
        loop, waiting for a status, watches the link itself).
        """
        if self._policy is not None and self._policy[0] != os.SCHED_OTHER:
            try:
                os.sched_setscheduler(0, *self._policy)
            except OSError:
                pass  # the maker's priority is not ours to take: the keeper runs at the normal one
        checked = time.monotonic()
        while not self._closing.wait(KEEPER_TICK_S):
            if not self._io.acquire(blocking=False):
                continue
            try:
                if self._closing.is_set():
                    return
                if time.monotonic() - self._last_tx >= HEARTBEAT_PERIOD_S:
                    self._send(L.Heartbeat(next(self._tokens) & 0xFFFFFFFF))
                    self.heartbeats_sent += 1
                self._poll()
                now = time.monotonic()
                timeout = self._timeout()
                if self.lost is None and now - self.last_frame_at > timeout:
                    self._declare_lost(f"no status from the firmware for {timeout * 1000:.0f} ms (heartbeats"
                                       f" unanswered; {self.rx.rejected} frames rejected)", now, checked)
                checked = now
            except LinkLost as exc:  # the port itself failed
                now = time.monotonic()
                if self.lost is None:
                    self._declare_lost(str(exc), now, checked)
                checked = now
            finally:
                self._io.release()

    def _declare_lost(self, reason: str, now: float, checked_before: float) -> None:
        if self.lost is not None:
            return
        loss = LinkLoss(reason, self.last_frame_at, now, checked_before, self._timeout())
        self.lost = loss
        self.losses.append(loss)
        if self.on_link_lost is not None:
            self.on_link_lost(loss)

    def heartbeat(self, timeout_s: float = HANDSHAKE_TIMEOUT_S) -> L.HeartbeatReply:
        """Send a ``HEARTBEAT`` and return the firmware's reply: its step and its link counters."""
        token = next(self._tokens) & 0xFFFFFFFF
        with self._io:
            self._send(L.Heartbeat(token))
            self.heartbeats_sent += 1
            give_up = time.monotonic() + timeout_s
            while True:
                reply = self._wait_for(L.HeartbeatReply, max(0.0, give_up - time.monotonic()))
                if reply.token == token:
                    return reply

    def _try(self, message: L.Message) -> bool:
        """Send `message`; a port that fails declares the link lost (False) instead of raising."""
        try:
            self._send(message)
        except LinkLost as exc:
            self._declare_lost(str(exc), time.monotonic(), self.last_frame_at)
            return False
        return True

    def _wait_step(self, target: int) -> None:
        """Wait for the status of step `target`; declare the link lost (no exception) when none comes in time."""
        timeout = self._timeout()
        checked = time.monotonic()
        give_up = checked + timeout
        while True:
            status = self._status
            if status is not None and (status.state != L.State.RUNNING or status.step >= target):
                return  # a stopped firmware: link_ok says so
            self._poll(min(0.005, timeout))
            now = time.monotonic()
            if self._status is not status:
                # measured from the frame's arrival, not from this look: a look that ends late
                # (a busy machine) must not stretch the silence allowed past `timeout`
                give_up = self.last_frame_at + timeout
            elif now > give_up:
                self._declare_lost(f"no status from the firmware for {timeout * 1000:.0f} ms (waiting for step"
                                   f" {target}; {self.rx.rejected} frames rejected)", now, checked)
                return
            checked = now

    def _idle(self, steps: int) -> None:
        """`steps` control steps of the wall clock without the firmware, reading what comes meanwhile."""
        until = time.monotonic() + self.dt * steps
        while True:
            left = until - time.monotonic()
            if time.monotonic() - self._last_tx >= HEARTBEAT_PERIOD_S:  # the keeper's work, the wire being ours
                if self._try(L.Heartbeat(next(self._tokens) & 0xFFFFFFFF)):
                    self.heartbeats_sent += 1
            try:
                self._poll(max(0.0, left))
                if self._fd is None:  # no descriptor to wait on (a pyserial URL): do not spin
                    time.sleep(max(0.0, min(left, 0.001)))
            except LinkLost:
                time.sleep(max(0.0, left))  # the port is gone: only the clock goes on
            if left <= 0:
                return

    # ---- the link's state -----------------------------------------------------------
    @property
    def link_ok(self) -> bool:
        """The ``Link`` block (docs/safety.md): the link is not lost and the firmware runs the drives.

        False from the loss (no valid status for the link's timeout, or a port
        that failed) or from the firmware's own safe stop, until :meth:`rearm`.
        """
        s = self._status
        return self.lost is None and (s is None or s.state == L.State.RUNNING)

    @property
    def link_fault(self) -> str | None:
        """Why :attr:`link_ok` is false, in one line; None while it is true."""
        if self.lost is not None:
            return self.lost.reason
        s = self._status
        if s is not None and s.state != L.State.RUNNING:
            return (f"the firmware stopped the drives ({s.state_name} at step {s.step}: no setpoints reached"
                    " it for 50 ms)")
        return None

    @property
    def link_stats(self) -> dict[str, int]:
        """Bytes each way, frames taken, rejected and lost (sequence gaps) on the PC's side."""
        return {"bytes_sent": self.bytes_sent, "bytes_received": self.bytes_received,
                "frames_ok": self.rx.frames_ok, "rejected": self.rx.rejected, "lost": self.rx.seq.lost}


__all__ = ["FirmwareLink", "LinkLoss", "LinkLost", "SerialArmError", "LINK_TIMEOUT_S", "GATED_TIMEOUT_S",
           "HEARTBEAT_PERIOD_S", "KEEPER_TICK_S", "HANDSHAKE_TIMEOUT_S", "BAUD"]
