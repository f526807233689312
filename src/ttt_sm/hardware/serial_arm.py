"""The ``serial`` arm backend: the :class:`~ttt_sm.arm.Arm` protocol over the link to the firmware.

:class:`SerialArm` opens a serial port with pyserial (a board's
``/dev/ttyACM0``, or ``ttt-sm arm serve``'s pseudo-terminal), says
``HELLO`` and checks the ``HANDSHAKE`` (protocol version, three drives, the
encoder resolutions of the parameter file), downloads the cascade's gains
(designed with python-control on the PC, ``twin.tuning.design_gains``) and
checks their read-back, and sends ``START``.  Then the scheduler drives it
like the twin: ``set_setpoints`` once per chart step, ``step(n)`` sends them
(one ``SETPOINTS`` frame per chart step) and waits for the firmware's
``STATUS`` of the step it asked for; the sensors are that status's.

The link is declared lost when no valid status arrives within
:data:`LINK_TIMEOUT_S` of wall-clock time while waiting for one, or the
port fails.  While the PC has nothing to send (the charts paused, a
debugger at a breakpoint), a background thread keeps the link watched:
every :data:`HEARTBEAT_PERIOD_S` it sends a ``HEARTBEAT`` (the firmware
answers with a ``HEARTBEAT_REPLY``; on its own clock it also goes on
sending its ``STATUS``), and when no valid frame has come for the link's
timeout it declares the loss.  A loss is a :class:`LinkLoss`
(:attr:`SerialArm.lost`, and the ``on_link_lost`` callback); it stays
until :meth:`SerialArm.rearm`.  Rejected frames are counted and logged by
its :class:`~ttt_sm.hardware.link.Receiver`.

A lost link does not raise out of ``step``: :attr:`SerialArm.link_ok`
turns false (the ``Link`` block the Safety chart reads, docs/safety.md),
the PC stops streaming setpoints, so that the firmware's watchdog stops the
drives 50 ms later whichever way the link broke, and ``step`` returns at
the wall clock's pace (``n`` control periods) with the last sensors; the
arm's time (:attr:`SerialArm.t`, the firmware's steps) stands until the
link is re-armed, then goes on from the firmware's step.  A firmware that
stopped the drives itself (``safe_stop``) makes :attr:`~SerialArm.link_ok`
false too.  :meth:`SerialArm.rearm` (the Safety
chart's ``reset``: ``Robot.reinitialise``) sends ``START`` again once the
firmware answers.
"""

from __future__ import annotations

import itertools
import math
import os
import select
import threading
import time
from collections.abc import Callable, Sequence
from contextlib import AbstractContextManager
from dataclasses import dataclass
from typing import TypeVar

import numpy as np
import serial

from ..arm import Sensors
from ..params import ArmParams
from ..twin import layout
from ..twin.cascade import CascadeController
from ..twin.gains import Gains, check_drive
from ..twin.gains_cache import kept_gains
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
REARM_SETTLE_S = 0.2
"""After a re-arm, the drives hold where they stand this long before the charts command them again, s."""
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


class SerialArm(AbstractContextManager["SerialArm"]):
    """An :class:`~ttt_sm.arm.Arm` whose cascade runs in the firmware at the other end of `port`.

    Parameters
    ----------
    port
        A pyserial URL or device path (``ttt-sm arm serve``'s link, ``/dev/ttyACM0``).
    params
        The parameter file: the encoder resolutions the handshake must match,
        the control rate, the chart divider.
    gains
        The cascade's gains; None designs them (``kept_gains(params)``).
    servo_angle
        The servo's setpoint until the first ``set_setpoints`` (rad).
    link_timeout_s
        Wall-clock seconds without a valid status before :class:`LinkLost`.
    """

    def __init__(self, port: str, params: ArmParams, gains: Gains | None = None, servo_angle: float = 0.0,
                 link_timeout_s: float = LINK_TIMEOUT_S, baudrate: int = BAUD) -> None:
        self.params = params
        self.dt = params.control.dt
        self.divider = params.control.chart_divider
        self.gains = kept_gains(params) if gains is None else gains
        self.link_timeout_s = link_timeout_s
        self._rpc = tuple(float(d.rad_per_count) for d in params.drives)
        self._servo = params.servo  # its feedback's calibration turns the STATUS's ADC counts into an angle
        self._offsets = [0.0, 0.0, 0.0]
        self._q: list[float] = [0.0, 0.0, 0.0, float(servo_angle)]
        self._fr_sw = False
        self.rx = L.Receiver(name="pc")
        self.tx = L.Sender()
        self.bytes_sent = 0
        self.bytes_received = 0
        self._status: L.Status | None = None
        self._steps = 0  # control steps run (the arm's time)
        self._sent_for = -1  # the control step the last setpoints were sent for
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
        self.rearms = 0
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
        try:
            with self._io:
                self.handshake = self._open()
        except BaseException:
            self._ser.close()
            raise
        self._keeper = threading.Thread(target=self._keep, name=f"serial-arm keeper {port}", daemon=True)
        self._keeper.start()

    # ---- opening the link ---------------------------------------------------------

    def _open(self) -> L.Handshake:
        self._send(L.Hello())
        hs = self._wait_for(L.Handshake, HANDSHAKE_TIMEOUT_S)
        if hs.protocol != L.PROTOCOL_VERSION:
            raise SerialArmError(f"the firmware speaks protocol {hs.protocol}, this PC {L.PROTOCOL_VERSION}")
        if hs.drives != 3:
            raise SerialArmError(f"the firmware drives {hs.drives} motors, the arm has 3")
        for d, (theirs, ours) in enumerate(zip(hs.rad_per_count, self._rpc, strict=True)):
            if not math.isclose(theirs, ours, rel_tol=1e-9):
                raise SerialArmError(f"drive {d + 1}: the firmware's encoder gives {theirs:.6g} rad per count, "
                                     f"the parameter file {ours:.6g}")
        if abs(hs.control_period_us - self.dt * 1e6) > 0.5:
            raise SerialArmError(f"the firmware steps every {hs.control_period_us} us, the parameter file every "
                                 f"{self.dt * 1e6:g} us")
        pc = CascadeController(self.params, self.gains, servo_angle=self._q[3])
        rows = [pc.cp[d, :layout.N_CP] for d in range(3)] + [pc.cg[:layout.N_CG]]
        real = np.float32 if hs.real_size == 4 else np.float64
        for block, row in enumerate(rows):
            self._send(L.Gains(block, tuple(float(v) for v in row)))
            back = self._wait_for(L.GainsReadback, HANDSHAKE_TIMEOUT_S)
            want = row.astype(real).astype(np.float64)
            if back.block != block or not np.array_equal(np.array(back.values_), want):
                raise SerialArmError(f"gains block {block}: read back {back.values_}, sent {tuple(want)}")
        self._send(L.Start())
        self._status = self._wait_for(L.Status, HANDSHAKE_TIMEOUT_S, after_start=True)
        self._steps = self._status.step
        return hs

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
                        if m.state != 1 and self.stop_seen_at is None and self._status is not None \
                                and self._status.state == 1:
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
            if kind is L.Status and status is not None and (not after_start or status.state == 1):
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

    def _wait_step(self, target: int) -> None:
        """Wait for the status of step `target`; declare the link lost (no exception) when none comes in time."""
        timeout = self._timeout()
        checked = time.monotonic()
        give_up = checked + timeout
        while True:
            status = self._status
            if status is not None and (status.state != 1 or status.step >= target):
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
        return self.lost is None and (s is None or s.state == 1)

    @property
    def link_fault(self) -> str | None:
        """Why :attr:`link_ok` is false, in one line; None while it is true."""
        if self.lost is not None:
            return self.lost.reason
        s = self._status
        if s is not None and s.state != 1:
            return (f"the firmware stopped the drives ({s.state_name} at step {s.step}: no setpoints reached"
                    " it for 50 ms)")
        return None

    def rearm(self, timeout_s: float = 0.5) -> bool:
        """After a loss or the firmware's safe stop, ``START`` again: whether the firmware runs the drives now.

        Tried only when a valid frame came after the loss (the link answers
        again); the firmware takes ``START`` with its gains kept and holds every
        drive where it stands (docs/hardware.md); the PC sends its encoder
        offsets again (any sent while the link was down were lost) and holds them there
        for :data:`REARM_SETTLE_S` so that the arm is at rest when the charts
        take over again.  The loss is then forgotten
        and the PC streams setpoints again, from the firmware's step (on its
        own clock it ran on; a gated emulator's stood still too).  Nothing is
        sent, and False returned, while the link is silent.
        """
        with self._io:
            if self.link_ok:
                return True
            if self.lost is not None and self.last_frame_at <= self.lost.declared_at:
                try:
                    self._poll()
                except LinkLost:
                    return False
                if self.last_frame_at <= self.lost.declared_at:
                    return False
            sent = time.monotonic()
            try:
                self._send(L.Start())
                for d in range(3):  # the PC's offsets are the ones: any sent while the link was down were lost
                    self._send(L.Drive(d, L.Op.OFFSET, self._offsets[d]))
                give_up = sent + timeout_s
                while not (self._status is not None and self._status.state == 1 and self.status_seen_at >= sent):
                    if time.monotonic() > give_up:
                        return False
                    self._poll(0.005)
            except LinkLost:
                return False
            self.lost = None
            self.stop_seen_at = None
            self.rearms += 1
            self._steps = max(self._steps, self._status.step)
            self._sent_for = -1
            # hold where the drives stand while they come to rest (a gated emulator froze the plant moving)
            self._q[:3] = list(self.encoder_angles())
            self._step(max(1, round(REARM_SETTLE_S / self.dt)))
            return self.link_ok

    # ---- the Arm protocol ---------------------------------------------------------------

    @property
    def t(self) -> float:
        return self._steps * self.dt

    @property
    def steps(self) -> int:
        """Control steps run: the firmware's, as of its last status, and those stepped since within a chart step."""
        return self._steps

    def step(self, n: int = 1) -> None:
        """Stream the setpoints and wait until the firmware has run `n` more control steps.

        The setpoints go out at each chart step's first control step; the
        firmware reports at each chart step's end, so that is where this waits.
        Stepping one control step at a time (the debugger, a paced clock),
        the steps within a chart step return at once: the firmware runs them
        on the setpoints it has.
        """
        with self._io:
            self._step(n)

    def _step(self, n: int) -> None:
        target = self._steps + n
        d = self.divider
        while self._steps < target:
            if not self.link_ok:  # nothing goes out: the firmware's watchdog stops the drives; the arm's
                self._idle(target - self._steps)  # time (the firmware's) stands until the link is re-armed
                return
            if self._steps % d == 0 and self._sent_for != self._steps:
                self._sent_for = self._steps
                if not self._try(L.Setpoints(self._steps, (self._q[0], self._q[1], self._q[2], self._q[3]),
                                             self._fr_sw)):
                    continue
            nxt = min(target, (self._steps // d + 1) * d)
            if nxt % d == 0:
                try:
                    self._wait_step(nxt)
                except LinkLost as exc:  # the port failed
                    self._declare_lost(str(exc), time.monotonic(), self.last_frame_at)
                if not self.link_ok:
                    continue
                assert self._status is not None  # _wait_step returns with one
                nxt = max(nxt, self._status.step)  # on its own clock, the firmware may be further on
            self._steps = nxt

    def _try(self, message: L.Message) -> bool:
        """Send `message`; a port that fails declares the link lost (False) instead of raising."""
        try:
            self._send(message)
        except LinkLost as exc:
            self._declare_lost(str(exc), time.monotonic(), self.last_frame_at)
            return False
        return True

    def set_setpoints(self, q_des: Sequence[float], fr_sw: bool = False) -> None:
        q = [float(v) for v in q_des[:4]]
        if len(q) != 4 or not all(math.isfinite(v) for v in q):
            raise SerialArmError(f"setpoints must be 4 finite angles (rad), got {list(q_des)!r}")
        self._q = q
        self._fr_sw = bool(fr_sw)

    @property
    def servo_setpoint(self) -> float:
        return self._q[3]

    def sensors(self) -> Sensors:
        s = self._status
        assert s is not None  # the handshake waited for one
        return Sensors(counts=s.counts, index=tuple(bool(s.index >> d & 1) for d in range(3)),  # type: ignore[arg-type]
                       index_count=s.index_count, index_edges=s.index_edges,
                       current_a=tuple(i / 1000.0 for i in s.current_ma), t=self.t,  # type: ignore[arg-type]
                       servo_rad=self._servo.feedback_angle(s.servo_adc))

    def encoder_angles(self) -> tuple[float, float, float]:
        c = (0, 0, 0) if self._status is None else self._status.counts
        o, r = self._offsets, self._rpc
        return c[0] * r[0] + o[0], c[1] * r[1] + o[1], c[2] * r[2] + o[2]

    def offset_estimates(self) -> tuple[float, float, float]:
        return self._offsets[0], self._offsets[1], self._offsets[2]

    def set_offset_estimate(self, drive: int, offset_rad: float) -> None:
        d = check_drive(drive) - 1
        shift = float(offset_rad) - self._offsets[d]
        self._offsets[d] = float(offset_rad)
        self._q[d] += shift  # the firmware moves its setpoint with the offset: keep ours with it
        with self._io:
            self._try(L.Drive(d, L.Op.OFFSET, float(offset_rad)))

    def enabled(self) -> tuple[bool, bool, bool]:
        m = 0 if self._status is None else self._status.modes
        return tuple(((m >> (2 * d)) & 3) == layout.MODE_CLOSED for d in range(3))  # type: ignore[return-value]

    def set_enabled(self, drive: int, enabled: bool) -> None:
        d = check_drive(drive) - 1
        with self._io:
            self._try(L.Drive(d, L.Op.CLOSED if enabled else L.Op.OFF, 0.0))

    @property
    def link_stats(self) -> dict[str, int]:
        """Bytes each way, frames taken, rejected and lost (sequence gaps) on the PC's side."""
        return {"bytes_sent": self.bytes_sent, "bytes_received": self.bytes_received,
                "frames_ok": self.rx.frames_ok, "rejected": self.rx.rejected, "lost": self.rx.seq.lost}


__all__ = ["SerialArm", "SerialArmError", "LinkLost", "LinkLoss", "LinkTruth", "LINK_TIMEOUT_S", "HEARTBEAT_PERIOD_S"]
