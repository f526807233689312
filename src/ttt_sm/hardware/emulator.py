"""The arm's firmware, emulated: the C firmware on the twin's plant, behind a real pseudo-terminal.

:class:`ArmEmulator` is what ``ttt-sm arm serve`` runs.  The firmware is the
C that would be flashed (``firmware/``, built with the system compiler,
:mod:`.firmware`), loaded with ctypes (:class:`.native.NativeFirmware`); in
place of a board, each control step reads the twin's plant
(:class:`ttt_sm.twin.plant.Plant`: encoder counts, index switches,
currents) into the firmware's sensors and applies the firmware's commands
(H-bridge duties and flags, the servo's PWM) to the plant.  Bytes go over
the master side of a pseudo-terminal; the PC opens the slave (``port``, a
stable symlink, as the camera emulator does: docs/smartcam.md) with
pyserial like any serial port.

Two clocks (``pace``):

* ``"realtime"``: the control steps follow the wall clock at the control
  rate, as on a board; setpoints that stop arriving trip the watchdog.
* ``"gated"``: the PC's setpoints are the clock: each accepted
  ``SETPOINTS`` frame lets the firmware run one chart step (``status_every``
  control steps) past the step it was meant for, then it waits.  A loaded
  machine cannot make frames late, and a whole game runs as fast as the
  two processes can talk.

Faults of the arm (``ttt-sm faults --arm emulator``, docs/safety.md) go in
by a door a board has none of: :meth:`ArmEmulator.inject_fault` hands the
emulator an :class:`ArmFault` (``ttt_sm.faults.plant.PlantFault``) that
acts on the plant and on the sensors the firmware reads, in the emulator's
own thread, between the plant's step and the firmware's next read.  The
firmware's wire protocol has no fault command: the C sees a frozen
counter, a spiking current or a stalled motor as a board would.
"""

from __future__ import annotations

import logging
import os
import select
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Literal, Protocol

import numpy as np

from ..params import ArmParams
from ..ptylink import DeviceThread, PtyLink, PtyLinkError, realtime_priority
from ..twin import layout
from ..twin.plant import REST_POSE, Plant, check_pose
from . import link as L
from .firmware import Precision, build
from .native import FirmwareLibrary, NativeFirmware, board_for

Pace = Literal["realtime", "gated"]
PACES: tuple[Pace, ...] = ("realtime", "gated")

_LOG = logging.getLogger(__name__)


class WireTap(Protocol):
    """What stands between the pty and the firmware's UART: a fault injector (``ttt_sm.faults.link``).

    Each is called with the bytes that came (maybe none: the emulator calls
    both every turn of its loop, so that frames held back can go on) and the
    ``time.monotonic`` of the call; it returns the bytes to pass on.
    """

    def to_firmware(self, data: bytes, now: float) -> bytes:
        """Bytes from the PC, on their way into the firmware."""

    def to_pc(self, data: bytes, now: float) -> bytes:
        """Bytes from the firmware, on their way to the PC."""


class ArmFault(Protocol):
    """A fault of the arm on the emulator's plant (``ttt_sm.faults.plant.PlantFault``), made on the plant at its onset.

    :meth:`after_step` runs after each control step of the plant, before
    the firmware's next read; :meth:`current_a` gives the current the
    firmware reads of drive `drive` (1-3) at the plant's time `t`;
    :meth:`clear` puts back what it changed in the plant.
    """

    def after_step(self) -> None: ...

    def current_a(self, drive: int, reading: float, t: float) -> float: ...

    def clear(self) -> None: ...


class ArmEmulatorError(RuntimeError):
    """The emulator cannot do what was asked (a link path that is not ours, a bad option)."""


class FirmwareOnPlant:
    """The C firmware coupled to the twin's plant, stepped by hand (no port, no thread)."""

    def __init__(self, params: ArmParams, lib: FirmwareLibrary, *, seed: int = 0,
                 q0: tuple[float, float, float, float] | None = None, servo_safe_rad: float | None = None) -> None:
        q_start = check_pose(params, q0 if q0 is not None else REST_POSE)
        self.params = params
        self.plant = Plant(params, q_start, np.random.default_rng(seed))
        safe = float(q_start[3]) if servo_safe_rad is None else servo_safe_rad
        self.firmware = NativeFirmware(lib, board_for(params, safe))
        self._act = np.zeros(layout.N_ACT)
        self._ints = self.plant.ints
        self._ps = self.plant.ps
        #: A fault of the arm acting on the plant and the readings (None: none); set by the emulator's thread.
        self.fault: ArmFault | None = None

    def read_sensors(self) -> None:
        """The plant's sensors into the firmware's input (no step)."""
        s, ints, fault = self.firmware.sensors, self._ints, self.fault
        for d in range(3):
            s.counts[d] = int(ints[d, layout.PI_COUNTS])
            s.index_count[d] = int(ints[d, layout.PI_INDEX_COUNT])
            s.index_edges[d] = int(ints[d, layout.PI_INDEX_EDGES]) & 0xFFFF
            current = float(self._ps[d, layout.PS_I_MEAS])
            s.current_a[d] = current if fault is None else fault.current_a(d + 1, current, self.plant.t)
        s.servo_adc = self.plant.feedback_counts  # the twin's ADC reading of the servo's feedback wire
        s.index = sum(1 << d for d in range(3) if ints[d, layout.PI_INDEX] == 1)

    def sense(self) -> None:
        """The firmware takes the plant's sensors without a step (a gated clock, before START)."""
        self.read_sensors()
        self.firmware.sense()

    def step(self) -> None:
        """One control step: the plant's sensors into the firmware, its commands onto the plant."""
        self.read_sensors()
        self.firmware.step()
        self._act[:] = self.firmware.act
        self.plant.step(self._act)
        if self.fault is not None:
            self.fault.after_step()


class ArmEmulator:
    """The firmware on the twin's plant, on a pseudo-terminal, in a background thread.

    Parameters
    ----------
    params
        The parameter file (the plant, and the board the handshake tells).
    pace
        ``"realtime"`` or ``"gated"`` (module docstring).
    link
        Path of the stable symlink to the pty; default ``arm`` in a fresh
        temporary folder, removed by :meth:`stop`.  An existing path must be
        a symlink.
    precision
        The firmware's number type: ``"float"`` (the reference board) or ``"double"``.
    seed, q0
        The plant's noise seed and its pose at power-on.
    truth
        Send the plant's true angles (``EMU_TRUTH``, simulation only) before
        each burst of the firmware's frames, so that the PC's simulated
        whiteboard is inked where the emulated pen really is; off, the wire
        carries exactly what a board sends.
    realtime
        Run the firmware's thread at ``SCHED_FIFO`` priority
        (:func:`ttt_sm.ptylink.realtime_priority`), as a board's control
        loop runs before anything else; :attr:`priority_note` says why not
        when the system refuses.
    """

    def __init__(self, params: ArmParams, *, pace: Pace = "gated", link: str | os.PathLike[str] | None = None,
                 precision: Precision = "float", seed: int = 0,
                 q0: tuple[float, float, float, float] | None = None, cache: Path | None = None,
                 logger: logging.Logger | None = None, truth: bool = False, realtime: bool = False) -> None:
        if pace not in PACES:
            raise ArmEmulatorError(f"pace must be one of {', '.join(PACES)}, got {pace!r}")
        self.params = params
        self.pace = pace
        self.dt = params.control.dt
        self._lib = FirmwareLibrary(build(precision, cache), precision)
        self.bench = FirmwareOnPlant(params, self._lib, seed=seed, q0=q0)
        # The plant's compiled step is loaded on its first call (a third of a second): on a scratch plant
        # now, not on the first control step, which a PC would wait for in vain.
        Plant(params, check_pose(params, REST_POSE), np.random.default_rng(0)).step(np.zeros(layout.N_ACT))
        self.firmware = self.bench.firmware
        #: The physics (simulation only): ground truth for tests.
        self.plant = self.bench.plant
        try:
            self._pty = PtyLink(link, "arm")
        except PtyLinkError as exc:
            raise ArmEmulatorError(str(exc)) from None
        self._log = logger or _LOG
        self._lock = threading.RLock()
        self._loop = DeviceThread(self._run, f"arm-emulator {self._pty.link}")
        self._out = bytearray()
        self.bytes_in = 0
        self.bytes_out = 0
        self.bytes_dropped = 0
        self.truth = truth
        self.realtime = realtime
        #: Why the thread did not get its real-time priority (None: it did, or it was not asked).
        self.priority_note: str | None = None
        self._truth_tx = L.Sender()
        self.truth_bytes = 0
        self._rpc = [d.rad_per_count for d in params.drives]
        self._gate = 0  # setpoints frames seen by the gated clock
        self._until = 0  # ... which let it run to this step
        #: Tampers with the bytes between the pty and the firmware (fault injection); None passes them all.
        self.tap: WireTap | None = None
        #: The firmware's state changes as they happened: (its step, its new state, ``time.monotonic``).
        self.state_changes: list[tuple[int, int, float]] = []
        self._state = self.firmware.state
        self._rejections: dict[int, int] = {}
        #: In real time: the most control steps the thread was ever behind the wall clock (held up by the
        #: machine, it runs them in a burst; a board never is).
        self.max_behind_steps = 0

    @property
    def port(self) -> str:
        """The stable path the PC opens (a symlink to the pty)."""
        return self._pty.port

    def start(self) -> ArmEmulator:
        """Make the pty and its link, and run the firmware in a background thread."""
        if self._loop.started:
            return self
        device = self._pty.open()
        self._loop.start()
        self._log.info("arm emulator (%s, %s firmware): %s -> %s", self.pace, self._lib.precision, self._pty.link,
                       device)
        return self

    def stop(self, timeout_s: float = 5.0) -> None:
        """Stop the thread, close the pty, remove the link (and its folder if the emulator made it)."""
        self._loop.stop(timeout_s)
        with self._lock:
            self._pty.remove()

    def hang(self, timeout_s: float = 5.0) -> None:
        """Stop the firmware but leave the port open, as a board that hangs: bytes go in, nothing comes out."""
        self._loop.stop(timeout_s)

    def inject_fault(self, make: Callable[[Plant], ArmFault]) -> ArmFault:
        """Switch a fault of the arm on now: `make` builds it on the plant, between two control steps.

        Simulation only, a door into the emulator's process (a board has
        none, and its wire protocol no fault command).  One fault at a
        time: the one before is cleared first.
        """
        with self._lock:
            self.clear_fault()
            fault = make(self.plant)
            self.bench.fault = fault
            return fault

    def clear_fault(self) -> None:
        """Switch the fault of the arm off: what it changed in the plant is put back."""
        with self._lock:
            fault, self.bench.fault = self.bench.fault, None
            if fault is not None:
                fault.clear()

    def __enter__(self) -> ArmEmulator:
        return self.start()

    def __exit__(self, *exc: object) -> None:
        self.stop()

    # -- the thread ----------------------------------------------------------------

    def _run(self) -> None:
        if self.realtime:
            self.priority_note = realtime_priority()
        t0 = time.monotonic()
        fw = self.firmware
        stopping = self._loop.stopping
        while not stopping.is_set():
            fd = self._pty.master
            if fd is None:
                return
            readable, _, _ = select.select([fd], [], [], 0.0005)
            if readable:
                self._receive(fd)
            elif self.tap is not None:  # frames the tap held back may be due
                self._deliver(self.tap.to_firmware(b"", time.monotonic()))
            if self.pace == "realtime":
                due = int((time.monotonic() - t0) / self.dt)
                if due - fw.steps > self.max_behind_steps:
                    self.max_behind_steps = due - fw.steps
                with self._lock:  # (a fault goes in between two steps)
                    while fw.steps < due and not stopping.is_set():
                        self.bench.step()
                        self._note_state()
                        self._send(fd)
                if self.tap is not None:
                    self._send(fd)
            else:
                if fw.setpoints_ok != self._gate:  # new setpoints: one more chart step past their step
                    self._gate = fw.setpoints_ok
                    self._until = fw.last_setpoint_step + fw.board.status_every
                with self._lock:
                    while fw.state == L.State.RUNNING and fw.steps < self._until:
                        self.bench.step()
                self._note_state()
                self._send(fd)

    def _note_state(self) -> None:
        state = self.firmware.state
        if state != self._state:
            self._state = state
            self.state_changes.append((self.firmware.steps, state, time.monotonic()))

    def _receive(self, fd: int) -> None:
        try:
            data = os.read(fd, 4096)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:  # the PC side closed: nothing to read until it reopens
            time.sleep(0.001)
            return
        self.bytes_in += len(data)
        if self.tap is not None:
            data = self.tap.to_firmware(data, time.monotonic())
        self._deliver(data)

    def _deliver(self, data: bytes) -> None:
        if not data:
            return
        if self.pace == "gated" and self.firmware.state != L.State.RUNNING:
            self.bench.sense()  # no control step runs before START here: the readings a board would have
        fw = self.firmware
        ok = fw.frames_ok
        fw.rx(data)
        self._note_state()
        if fw.frames_ok - ok < data.count(0):  # a frame ended and was not taken: say which reason counted it
            self._log_rejections()

    def _log_rejections(self) -> None:
        """One log line per reason the firmware counted since the last look (a board's debug output)."""
        now = self.firmware.rejections()
        for reason, n in now.items():
            new = n - self._rejections.get(reason, 0)
            if new > 0:
                self._log.warning("link (firmware): rejected %d frame(s): %s (%d so far)", new,
                                  L.Reason(reason).name.lower(), n)
        self._rejections = now

    def _send(self, fd: int) -> None:
        data = self.firmware.tx()
        if self.tap is not None:
            data = self.tap.to_pc(data, time.monotonic())
        if data and self.truth:  # before the firmware's frames: the PC has it when it reads their status
            ps, pgs, ints, rpc = self.plant.ps, self.plant.pgs, self.plant.ints, self._rpc
            q, c0 = layout.PS_Q, layout.PI_C0
            flags = L.EMU_TRUTH_FLAG_GATED if self.pace == "gated" else 0
            frame = self._truth_tx.frame(L.EmuTruth(self.firmware.steps, flags, (
                float(ps[0, q]), float(ps[1, q]), float(ps[2, q]), float(pgs[layout.PGS_SV_Q])),
                ((ints[0, c0] + 0.5) * rpc[0], (ints[1, c0] + 0.5) * rpc[1],
                 (ints[2, c0] + 0.5) * rpc[2])))  # (live: a jumped encoder moves its offset)
            self.truth_bytes += len(frame)
            self._out += frame
        self._out += data
        if not self._out:
            return
        try:
            n = os.write(fd, self._out)
        except (BlockingIOError, InterruptedError):
            n = 0
        except OSError:
            n = 0
        self.bytes_out += n
        del self._out[:n]
        if len(self._out) > 65536:  # nobody reads: a UART drops what does not go out
            self.bytes_dropped += len(self._out)
            self._out.clear()


__all__ = ["ArmEmulator", "ArmEmulatorError", "ArmFault", "FirmwareOnPlant", "PACES", "WireTap"]
