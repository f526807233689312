"""Faults of the serial link, injected on the emulator's wire (``ttt-sm faults --link``, docs/safety.md).

:class:`LinkTap` stands between the pseudo-terminal and the firmware's UART
in ``ttt-sm arm serve``'s emulator (:attr:`ttt_sm.hardware.emulator.ArmEmulator.tap`):
the bytes the PC writes are cut into frames at each 0x00 and tampered with
before the firmware reads them, and the firmware's frames before they go
into the pty.  The PC (:class:`~ttt_sm.hardware.serial_arm.SerialArm`) and
the firmware (the C of ``firmware/``) see a link that misbehaves and
nothing else:

- ``frames_lost``: every third frame, each way, vanishes;
- ``frames_garbled``: every third frame, each way, has one bit flipped
  (under the COBS, so the frame still ends where it did: a bad CRC);
- ``frames_duplicated``: every third frame, each way, arrives twice;
- ``frames_late``: every frame from the PC arrives :data:`LATE_S` late
  (the firmware judges a ``SETPOINTS`` frame late more than 2 ms past its step);
- ``frames_out_of_order``: every third frame, each way, is overtaken by the next;
- ``link_cut``: nothing passes either way until the fault is cleared
  (the cable pulled and plugged in again).

:func:`run_link_cell` runs one fault against the firmware emulator in real
time: the PC streams setpoints at the chart rate (drive 1 swinging, as
``ttt-sm bench``'s link bench does), the fault lasts :data:`FAULT_S`, and
after it the PC re-arms the firmware if the link was lost (the Safety
chart's ``reset``).  It measures what each end counted and rejected, when
the firmware stopped the drives and when the PC declared the link lost.
"""

from __future__ import annotations

import math
import tempfile
import threading
import time
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from ..hardware import link as L
from ..hardware.emulator import ArmEmulator
from ..hardware.serial_arm import SerialArm
from ..params import ArmParams
from ..twin.gains import Gains
from ..twin.gains_cache import kept_gains
from ..twin.plant import REST_POSE

#: The link's faults, in the order the matrix lists them.
LINK_FAULTS = ("frames_lost", "frames_garbled", "frames_duplicated", "frames_late", "frames_out_of_order",
               "link_cut")
#: Faults that make the link unusable: the firmware must stop the drives and the PC declare the link lost.
STOPPING_FAULTS = ("frames_late", "link_cut")
#: Every this many frames, one is lost, garbled, duplicated or overtaken.
EVERY = 3
LATE_S = 0.005
"""How late ``frames_late`` delivers the PC's frames, s (the firmware's limit: 2 control steps, 2 ms)."""
OVERTAKE_S = 0.005
"""A frame held back to be overtaken goes on alone after this long, s, when no next frame came."""
LATE_LIMIT = 10
"""So many setpoints refused as late outside the fault, or more, and the cell is ``disturbed``.

One hold-up of the PC makes one setpoint late (the next catches up); the
watchdog needs 25 chart steps in a row without one.  A quiet machine makes
0 to 4 in a cell; the machine's sustained slowness (the PC and the
emulator's thread sharing two busy cores) makes a run of them without any
single long hold-up."""
#: Streaming before the fault, during it, and after it (before and after a re-arm), s of the wall clock.
WARMUP_S = 0.3
FAULT_S = 0.3
AFTER_S = 0.2
#: What the firmware's watchdog and the PC's limit are: no setpoints / no status for this long, s.
LINK_LIMIT_S = 0.050


class LinkFaultError(ValueError):
    """A link fault the matrix does not know."""


@dataclass
class _Lane:
    """One direction of the wire: frames cut at each 0x00, tampered with while a fault is on."""

    name: str
    buf: bytearray = field(default_factory=bytearray)
    held: list[tuple[float, bytes]] = field(default_factory=list)  # (due, frame), in order
    seen: int = 0  # whole frames seen while a fault was on
    counts: Counter[str] = field(default_factory=Counter)

    def feed(self, data: bytes, now: float, fault: str | None) -> bytes:
        out = bytearray()
        if fault == "link_cut":
            if data:
                self.counts["cut_bytes"] += len(data)
            self.buf.clear()
        else:
            self.buf += data
            while True:
                end = self.buf.find(0)
                if end < 0:
                    break
                frame = bytes(self.buf[:end + 1])
                del self.buf[:end + 1]
                out += self._frame(frame, now, fault)
        while self.held and self.held[0][0] <= now:  # held back long enough
            out += self.held.pop(0)[1]
        return bytes(out)

    def _frame(self, frame: bytes, now: float, fault: str | None) -> bytes:
        if fault is None:
            if self.held:  # frames held back go first: the order is kept once the fault is off
                self.held.append((now, frame))
                return b""
            return frame
        self.seen += 1
        chosen = self.seen % EVERY == 0
        if fault == "frames_late":
            self.counts["delayed"] += 1
            self.held.append((now + LATE_S, frame))
            return b""
        if fault == "frames_out_of_order":
            if self.held:  # this frame overtakes the one held back
                self.counts["overtaken"] += 1
                return frame + self.held.pop(0)[1]
            if chosen:
                self.held.append((now + OVERTAKE_S, frame))
                return b""
            return frame
        if not chosen or len(frame) < 2:
            return frame
        if fault == "frames_lost":
            self.counts["dropped"] += 1
            return b""
        if fault == "frames_duplicated":
            self.counts["duplicated"] += 1
            return frame + frame
        if fault == "frames_garbled":
            self.counts["garbled"] += 1
            return garble(frame)
        raise LinkFaultError(f"no link fault {fault!r}")


def garble(frame: bytes) -> bytes:
    """`frame` (COBS, closing 0x00) with one bit of its type, number or body flipped: its CRC no longer holds."""
    raw = bytearray(L.cobs_decode(frame[:-1]))
    raw[len(raw) // 2 - 1 if len(raw) > 4 else 0] ^= 0x10  # not in the CRC itself
    return L.cobs_encode(bytes(raw)) + b"\x00"


class LinkTap:
    """The emulator's wire, with one link fault at a time switched on (:meth:`inject`) or off (:meth:`clear`).

    An :class:`~ttt_sm.hardware.emulator.WireTap`: set it as the emulator's
    ``tap``.  ``frames_late`` delays only the PC's frames (the firmware judges
    lateness; the PC waits for the step it asked for); the other faults act
    both ways.  :attr:`counts` says what it did, per direction.
    """

    def __init__(self) -> None:
        self.fault: str | None = None
        self._lock = threading.Lock()
        self.pc_to_fw = _Lane("pc_to_firmware")
        self.fw_to_pc = _Lane("firmware_to_pc")

    def inject(self, fault: str) -> None:
        if fault not in LINK_FAULTS:
            raise LinkFaultError(f"no link fault {fault!r}; faults: {', '.join(LINK_FAULTS)}")
        with self._lock:
            self.fault = fault

    def clear(self) -> None:
        with self._lock:
            self.fault = None

    def to_firmware(self, data: bytes, now: float) -> bytes:
        with self._lock:
            return self.pc_to_fw.feed(data, now, self.fault)

    def to_pc(self, data: bytes, now: float) -> bytes:
        with self._lock:
            fault = None if self.fault == "frames_late" else self.fault
            return self.fw_to_pc.feed(data, now, fault)

    @property
    def counts(self) -> dict[str, dict[str, int]]:
        return {lane.name: dict(lane.counts) for lane in (self.pc_to_fw, self.fw_to_pc)}


@dataclass(frozen=True)
class LinkCell:
    """One link fault, as ``ttt-sm faults --link --json`` reports it (docs/safety.md, "Faults of the link")."""

    fault: str
    expected: str
    """``rejected``: bad frames counted and refused, the drives run on; ``stopped``: the firmware stops the
    drives and the PC declares the link lost."""
    injected: dict[str, dict[str, int]]
    rejected_by_firmware: dict[str, int]
    rejected_by_pc: dict[str, int]
    lost_frames_firmware: int
    lost_frames_pc: int
    bad_frames_acted_on: int
    """Frames tampered with (garbled, duplicated, overtaken) that the receiving end took as valid."""
    firmware_stopped: bool
    firmware_stop_ms: float | None
    """From the onset to the firmware's safe stop, on the firmware's clock (its control steps)."""
    firmware_stop_wall_ms: float | None
    """The same on the wall clock (the emulator's thread may run its steps late, in bursts)."""
    watchdog_steps: int | None
    """Control steps between the last setpoints the firmware took and its safe stop."""
    pc_declared: bool
    pc_detect_ms: float | None
    """From the onset until the PC's ``link_ok`` turned false (its own declaration or the firmware's stop)."""
    pc_silence_ms: float | None
    """How long nothing valid had come when the PC declared the link lost (its limit: 50 ms)."""
    pc_reason: str
    as_expected: bool
    rearmed: bool
    recovered: bool
    """After the fault (and the re-arm when the link was lost) the firmware runs and takes setpoints."""
    end_state: str
    """When not recovered: the link, the firmware's state and the setpoints it took at the end, and why."""
    pc_max_stall_ms: float
    """The longest chart step of the PC's loop that found the link sound, wall clock (one is 2 ms)."""
    emulator_max_behind_ms: float
    """The longest the emulator's thread fell behind the wall clock (it then runs the steps in a burst)."""
    process_max_late_ms: float
    """The longest a 1 ms sleep of the process overslept (:class:`PaceProbe`): the machine's hold-ups."""
    late_outside_fault: int
    """Setpoints the firmware refused as late before the fault and from the re-arm on: the PC answered a
    status more than 2 ms after the firmware sent it, and no fault delayed them then (the machine did)."""
    disturbed: bool
    """The machine held up the PC, the emulator or the process for half the watchdog's 50 ms or more, or the
    link was lost before the fault began: what the cell saw may be the machine's doing, not the fault's."""
    onset_time: float
    """When the fault began, ``time.time()`` (the log's clock): the log lines it caused come after."""
    wall_s: float


class _Streamer:
    """The PC's side of a cell: setpoints at the chart rate, drive 1 swinging, as ``ttt-sm bench``'s link bench."""

    def __init__(self, arm: SerialArm) -> None:
        self.arm = arm
        self.q0 = arm.encoder_angles()
        self.servo = arm.servo_setpoint
        self.t0 = time.monotonic()
        self.not_ok_at: float | None = None
        self.max_stall_s = 0.0

    def run(self, seconds: float, losing: bool = False) -> None:
        """Stream for `seconds`; `losing`: the fault may lose the link (a step then waits for it: not a stall)."""
        arm, divider = self.arm, self.arm.divider
        end = last = time.monotonic()
        end += seconds
        while time.monotonic() < end:
            t = time.monotonic() - self.t0
            sound = arm.link_ok
            arm.set_setpoints([self.q0[0] + 0.2 * math.sin(2 * math.pi * 0.5 * t), self.q0[1], self.q0[2],
                               self.servo])
            arm.step(divider)
            now = time.monotonic()
            # a step that began on a sound link and took long was held up by the machine, even when the
            # link was lost meanwhile (the firmware's watchdog ran out on it); one that a fault may have
            # lost the link in waited for the link: the fault's doing
            if sound and (arm.link_ok or not losing):
                self.max_stall_s = max(self.max_stall_s, now - last)
            if not arm.link_ok and self.not_ok_at is None:
                self.not_ok_at = now
            last = now


class PaceProbe:
    """A thread that sleeps 1 ms at a time and keeps how late it woke at most: the machine's hold-ups.

    The PC's loop and the emulator's thread measure their own delays, but not
    all of them (a re-arm's settling, a step that lost the link while the
    process was not scheduled).  This measures the process as a whole, with
    a cost of a thousand short wake-ups a second: a cell the machine held up
    past half the watchdog's limit is not the fault's evidence.
    """

    PERIOD_S = 0.001

    def __init__(self) -> None:
        self.max_late_s = 0.0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="ttt_sm-pace-probe", daemon=True)

    def _run(self) -> None:
        while True:
            before = time.monotonic()
            if self._stop.wait(self.PERIOD_S):
                return
            self.max_late_s = max(self.max_late_s, time.monotonic() - before - self.PERIOD_S)

    def __enter__(self) -> PaceProbe:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join()


def _reasons(counts: dict[int, int], before: dict[int, int]) -> dict[str, int]:
    return {L.Reason(r).name.lower(): n - before.get(r, 0) for r, n in sorted(counts.items())
            if n - before.get(r, 0)}


def run_link_cell(params: ArmParams, fault: str, seed: int = 0, gains: Gains | None = None,
                  cache: Path | None = None, realtime: bool = True) -> LinkCell:
    """Stream, inject `fault` for :data:`FAULT_S`, clear it, re-arm if the link was lost: one cell."""
    if fault not in LINK_FAULTS:
        raise LinkFaultError(f"no link fault {fault!r}; faults: {', '.join(LINK_FAULTS)}")
    wall0 = time.perf_counter()
    tap = LinkTap()
    with tempfile.TemporaryDirectory(prefix="ttt_sm_linkfaults_") as tmp, \
            ArmEmulator(params, pace="realtime", link=Path(tmp) / "arm", seed=seed, cache=cache,
                        realtime=realtime) as emu:
        emu.tap = tap
        fw = emu.firmware
        arm = SerialArm(emu.port, params, gains, servo_angle=REST_POSE[3])
        try:
            with PaceProbe() as probe:  # from here on, the machine's hold-ups count
                pc = _Streamer(arm)
                emu.max_behind_steps = 0  # (opening the link held the emulator's thread up: that is no fault)
                late0 = fw.rejections()[L.Reason.LATE]
                pc.run(WARMUP_S)
                if not arm.link_ok:
                    arm.rearm()
                    pc.run(WARMUP_S)
                # the machine held an end up before the onset: the firmware stopped, or the PC lost the link
                lost_before = fw.state != L.State.RUNNING or not arm.link_ok or bool(arm.losses) or any(
                    state == L.State.SAFE_STOP for _, state, _ in emu.state_changes)
                pc.not_ok_at = None
                fw_rej, pc_rej = dict(fw.rejections()), dict(arm.rx.rejections)
                late_outside = fw_rej[L.Reason.LATE] - late0
                fw_lost, pc_lost = fw.lost, arm.rx.seq.lost
                losses = len(arm.losses)
                changes = len(emu.state_changes)
                onset_step, onset, onset_time = fw.steps, time.monotonic(), time.time()
                tap.inject(fault)
                losing = fault in STOPPING_FAULTS
                pc.run(FAULT_S, losing)
                tap.clear()
                pc.run(AFTER_S, losing)
                stops = [(step, at) for step, state, at in emu.state_changes[changes:] if state == L.State.SAFE_STOP]
                fw_after = dict(fw.rejections())
                pc_after = {int(r): n for r, n in arm.rx.rejections.items()}
                counts = tap.counts
                loss = arm.losses[losses] if len(arm.losses) > losses else None
                not_ok_at = pc.not_ok_at
                fault_text = arm.link_fault or ""
                watchdog = None
                if stops:
                    watchdog = stops[0][0] - fw.last_setpoint_step
                late_rearm = fw.rejections()[L.Reason.LATE]  # (the fault's late frames are long through)
                rearmed = False
                if not arm.link_ok:
                    rearmed = arm.rearm()
                taken = fw.setpoints_ok
                pc.run(AFTER_S)
                late_outside += fw.rejections()[L.Reason.LATE] - late_rearm
                recovered = arm.link_ok and fw.state == L.State.RUNNING and fw.setpoints_ok > taken
                end_text = "" if recovered else (f"at the end: link_ok={arm.link_ok}, firmware state {fw.state}, "
                                                 f"{fw.setpoints_ok - taken} setpoints taken; {arm.link_fault or ''}")
                stall_ms, behind_ms = pc.max_stall_s * 1e3, emu.max_behind_steps * params.control.dt * 1e3
        finally:
            arm.close()
        probe_ms = probe.max_late_s * 1e3
        # every bad frame is either rejected by its receiver or taken as valid; taken ones were acted on
        bad_reasons = {"frames_garbled": (L.Reason.CRC, "garbled"), "frames_duplicated": (L.Reason.DUPLICATE,
                       "duplicated"), "frames_out_of_order": (L.Reason.OUT_OF_ORDER, "overtaken")}
        acted = 0
        if fault in bad_reasons:
            reason, key = bad_reasons[fault]
            acted = max(0, counts["pc_to_firmware"].get(key, 0) - (fw_after.get(reason, 0) - fw_rej.get(reason, 0)))
            acted += max(0, counts["firmware_to_pc"].get(key, 0) - (pc_after.get(reason, 0) - pc_rej.get(reason, 0)))
        fw_stopped = bool(stops)
        fw_stop_ms = round((stops[0][0] - onset_step) * params.control.dt * 1e3, 1) if stops else None
        fw_stop_wall_ms = round((stops[0][1] - onset) * 1e3, 1) if stops else None
        pc_declared = not_ok_at is not None
        expected = "stopped" if fault in STOPPING_FAULTS else "rejected"
        stopped_ok = fw_stopped and pc_declared and watchdog is not None and watchdog <= round(
            LINK_LIMIT_S / params.control.dt) + params.control.chart_divider
        as_expected = acted == 0 and (stopped_ok if expected == "stopped" else not fw_stopped and not pc_declared)
        return LinkCell(
            fault=fault, expected=expected, injected=counts,
            rejected_by_firmware=_reasons(fw_after, fw_rej),
            rejected_by_pc=_reasons(pc_after, {int(r): n for r, n in pc_rej.items()}),
            lost_frames_firmware=fw.lost - fw_lost, lost_frames_pc=arm.rx.seq.lost - pc_lost,
            bad_frames_acted_on=acted, firmware_stopped=fw_stopped, firmware_stop_ms=fw_stop_ms,
            firmware_stop_wall_ms=fw_stop_wall_ms,
            watchdog_steps=watchdog, pc_declared=pc_declared,
            pc_detect_ms=round((not_ok_at - onset) * 1e3, 1) if not_ok_at is not None else None,
            pc_silence_ms=round(loss.silence_s * 1e3, 1) if loss is not None else None,
            pc_reason=fault_text if pc_declared else "",
            as_expected=as_expected, rearmed=rearmed, recovered=bool(recovered), end_state=end_text,
            pc_max_stall_ms=round(stall_ms, 1), emulator_max_behind_ms=round(behind_ms, 1),
            process_max_late_ms=round(probe_ms, 1), late_outside_fault=late_outside,
            disturbed=lost_before or max(stall_ms, behind_ms, probe_ms) >= LINK_LIMIT_S * 1e3 / 2
            or late_outside >= LATE_LIMIT,
            onset_time=onset_time, wall_s=round(time.perf_counter() - wall0, 2),
        )


def link_fault_matrix(params: ArmParams, faults: Sequence[str] = LINK_FAULTS, seed: int = 0,
                      cache: Path | None = None, status: Callable[[str], None] | None = None) -> dict[str, Any]:
    """Every link fault against the emulator in real time: what ``ttt-sm faults --link --json`` prints."""
    wall0 = time.perf_counter()
    gains = kept_gains(params)
    cells: list[LinkCell] = []
    for fault in faults:
        if status is not None:
            status(f"link faults: {fault} ({len(cells) + 1} of {len(faults)})")
        cells.append(run_link_cell(params, fault, seed, gains, cache))
    stopping = [c for c in cells if c.expected == "stopped"]
    return {
        "cells": [asdict(c) for c in cells],
        "summary": {
            "cells": len(cells),
            "as_expected": sum(c.as_expected for c in cells),
            "bad_frames_acted_on": sum(c.bad_frames_acted_on for c in cells),
            "max_firmware_stop_ms": max((c.firmware_stop_ms or 0.0) for c in stopping) if stopping else None,
            "max_pc_detect_ms": max((c.pc_detect_ms or 0.0) for c in stopping) if stopping else None,
            "recovered": sum(c.recovered for c in cells),
            "disturbed": [c.fault for c in cells if c.disturbed],
        },
        "seed": seed,
        "wall_time_s": round(time.perf_counter() - wall0, 2),
    }


__all__ = ["LINK_FAULTS", "LinkCell", "LinkFaultError", "LinkTap", "garble", "link_fault_matrix", "run_link_cell"]
