"""The ``serial`` arm backend: the :class:`~ttt_sm.arm.Arm` protocol over the link to the firmware.

:class:`SerialArm` opens the link (:class:`~.firmware_link.FirmwareLink`:
the port, the wire, the keeper that watches it idle, a loss and its
reason), says ``HELLO`` and checks the ``HANDSHAKE`` (protocol version,
three drives, the encoder resolutions of the parameter file), downloads
the cascade's gains (designed with python-control on the PC,
``twin.tuning.design_gains``) and checks their read-back, and sends
``START``.  Then the scheduler drives it like the twin: ``set_setpoints``
once per chart step, ``step(n)`` sends them (one ``SETPOINTS`` frame per
chart step) and waits for the firmware's ``STATUS`` of the step it asked
for; the sensors are that status's.

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

import math
import time
from collections.abc import Sequence

import numpy as np

from ..arm import Sensors
from ..params import ArmParams
from ..twin import layout
from ..twin.cascade import CascadeController
from ..twin.gains import Gains, check_drive
from ..twin.gains_cache import kept_gains
from . import link as L
from .firmware_link import (
    BAUD,
    HANDSHAKE_TIMEOUT_S,
    HEARTBEAT_PERIOD_S,
    LINK_TIMEOUT_S,
    FirmwareLink,
    LinkLoss,
    LinkLost,
    SerialArmError,
)
from .link.protocol import STATUS_MODE_BITS
from .link_truth import LinkTruth

REARM_SETTLE_S = 0.2
"""After a re-arm, the drives hold where they stand this long before the charts command them again, s."""


class SerialArm(FirmwareLink):
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
        self.divider = params.control.chart_divider
        self.gains = kept_gains(params) if gains is None else gains
        self._rpc = tuple(float(d.rad_per_count) for d in params.drives)
        self._servo = params.servo  # its feedback's calibration turns the STATUS's ADC counts into an angle
        self._offsets = [0.0, 0.0, 0.0]
        self._q: list[float] = [0.0, 0.0, 0.0, float(servo_angle)]
        self._fr_sw = False
        self._steps = 0  # control steps run (the arm's time)
        self._sent_for = -1  # the control step the last setpoints were sent for
        self.rearms = 0
        super().__init__(port, params, link_timeout_s, baudrate)
        try:
            with self._io:
                self.handshake = self._open()
        except BaseException:
            self._ser.close()
            raise
        self._start_keeper(port)

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

    # ---- re-arming -------------------------------------------------------------------
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
                while not (self._status is not None and self._status.state == L.State.RUNNING
                           and self.status_seen_at >= sent):
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
        bits, mask = STATUS_MODE_BITS, (1 << STATUS_MODE_BITS) - 1
        return tuple(((m >> (bits * d)) & mask) == layout.MODE_CLOSED for d in range(3))  # type: ignore[return-value]

    def set_enabled(self, drive: int, enabled: bool) -> None:
        d = check_drive(drive) - 1
        with self._io:
            self._try(L.Drive(d, L.Op.CLOSED if enabled else L.Op.OFF, 0.0))


__all__ = ["SerialArm", "SerialArmError", "LinkLost", "LinkLoss", "LinkTruth", "LINK_TIMEOUT_S", "HEARTBEAT_PERIOD_S"]
