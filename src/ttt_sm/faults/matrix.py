"""The fault matrix: every fault of the arm in every phase of the robot's work (``ttt-sm faults``).

One cell is one fault (:mod:`.plant`, and ``camera_lost``) injected in one
phase, on a new robot built on a new arm (``arm``):

- ``"sim"``: the in-process twin, a :class:`~.twin.FaultyArm`;
- ``"emulator"`` (``ttt-sm faults --arm emulator``): the C firmware on the
  twin's plant (:class:`~ttt_sm.hardware.emulator.ArmEmulator`, gated: the
  PC's setpoints are its clock) behind a real pseudo-terminal, the robot on
  :class:`~ttt_sm.hardware.serial_arm.SerialArm`; the fault goes into the
  emulator's plant (:meth:`~ttt_sm.hardware.emulator.ArmEmulator.inject_fault`)
  and the C controller reads it as a board would.

The phases:

- ``initialising``: 1.5 s after power-on, while drive 1 searches its index;
- ``drawing the field``: 0.3 s into the field's first line, pen on the board;
- ``drawing a symbol``: 0.2 s into the first line of an X in cell (3, 3);
- ``erasing``: 0.3 s into the first pass of the sponge.

A fault of one drive is injected on the drive the PC commands fastest at
that moment (drive 1 while it initialises).  The cell then runs
:data:`WATCH_S` of simulated time, switches the fault off, posts the Safety
chart's ``reset`` and waits (at most :data:`RECOVER_S`) for the drives to be
initialised again.  It reports (docs/safety.md, "Fault matrix"):

- ``detected``: the Safety chart tripped within :data:`WATCH_S`;
  ``detect_ms``: how long after the onset;
- ``time_to_safe_ms``: from the onset until every joint has come to rest
  (true speeds below :data:`REST_RAD_S`) for good, within the watch; null if
  it never trips, or the arm still moves at the end;
- ``limit_violations``: chart steps whose setpoints, in true joint
  coordinates, lie beyond a hard stop (drive 1 may push its stop by its stall
  band while it initialises, as ``ttt-sm init`` allows), from the onset to
  the end of the recovery;
- ``board_zone_entries``: times the elbow, wrist or pen tip entered the board
  zone (docs/parameters.md) after the trip, within the watch: what the safe
  reaction did; ``board_zone_entries_reinit``: the same during the
  re-initialisation after the reset (its searches start where the arm stands);
- ``ink_smear_mm``: the path of the true pen tip while it pressed the board,
  from the onset to the end of the watch: ink the pen laid (or smeared) that
  the drawing did not ask for after the fault;
- ``record_intact``: the record written as it happened (a ``game.jsonl``
  of :class:`~ttt_sm.app.game_record.GameRecord`) reads back whole, with the onset, the
  trip and its reason, the reset and the end;
- ``recovered``: after the reset every drive is initialised again and the
  Safety chart watches.

Simulation only: it measures against the plant's ground truth (the twin's,
or the emulator's ``EMU_TRUTH`` frames: :class:`~ttt_sm.hardware.serial_arm.LinkTruth`).
"""

from __future__ import annotations

import math
import os
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..app.game_record import GameRecord, read_record
from ..app.init_wiring import servo_init_angle
from ..app.robot import Robot
from ..arm import Arm
from ..hardware.emulator import ArmEmulator
from ..hardware.firmware import build
from ..hardware.link_truth import LinkTruth
from ..hardware.serial_arm import SerialArm
from ..params import ArmParams
from ..runner import Runner, one_line, throughput
from ..sched.scheduler import Signals
from ..twin.gains import Gains
from ..twin.gains_cache import kept_gains
from ..twin.kinematics import arm_chain_py, link_points
from ..twin.sim import ArmSim
from ..twin.truth import ArmTruth
from ..twin.whiteboard import Whiteboard
from .plant import PlantFault
from .twin import DRIVE_FAULTS, TWIN_FAULTS, FaultyArm

PHASES = ("initialising", "drawing the field", "drawing a symbol", "erasing")
#: The arms a cell runs on (``ttt-sm faults --arm``).
ARMS = ("sim", "emulator")
#: What each arm is, as the report names it.
BACKENDS = {"sim": "the twin, in process (Python cascade on the plant)",
            "emulator": "the C firmware on the twin's plant, gated, behind a pseudo-terminal (SerialArm)"}
#: How long a cell watches after the onset before the fault is switched off, s.
WATCH_S = 1.5
#: Longest the re-initialisation after the reset may take, s (one takes 6-12 s from rest).
RECOVER_S = 40.0
#: The board zone is checked every this many chart steps (10 ms): a pass through it lasts longer.
ZONE_EVERY = 5
#: A joint slower than this is at rest, rad/s.
REST_RAD_S = 0.02
#: The targets of the matrix: detected within this long of the onset, s.
DETECT_TARGET_S = 0.1


class FaultMatrixError(ValueError):
    """A fault or phase the matrix does not know."""


@dataclass(frozen=True)
class Cell:
    """One fault in one phase, as ``ttt-sm faults --json`` reports it."""

    fault: str
    phase: str
    drive: int
    detected: bool
    detect_ms: float | None
    reason: str
    time_to_safe_ms: float | None
    limit_violations: int
    board_zone_entries: int
    board_zone_entries_reinit: int
    ink_smear_mm: float
    record_intact: bool
    recovered: bool
    sim_s: float
    wall_s: float


class _TwinBench:
    """A cell's arm: the in-process twin, its faults in a :class:`~.twin.FaultyArm`."""

    def __init__(self, params: ArmParams, seed: int, gains: Gains | None) -> None:
        self.sim = ArmSim(params, gains=gains, seed=seed)
        self.faulty = FaultyArm(self.sim)
        self.arm: Arm = self.faulty
        self.truth: ArmTruth | LinkTruth = self.sim.truth

    def inject(self, fault: str, drive: int) -> None:
        self.faulty.inject(fault, drive)

    def clear(self) -> None:
        self.faulty.clear()

    def close(self) -> None:
        pass


class _EmulatorBench:
    """A cell's arm: the C firmware on a gated emulator behind a pty, over :class:`SerialArm`, faults in its plant."""

    def __init__(self, params: ArmParams, seed: int, gains: Gains | None, folder: Path, cache: Path | None) -> None:
        self.emulator = ArmEmulator(params, pace="gated", link=folder / "arm", seed=seed, truth=True, cache=cache)
        self.emulator.start()
        try:
            self.serial = SerialArm(self.emulator.port, params, gains, servo_angle=servo_init_angle(params))
        except BaseException:
            self.emulator.stop()
            raise
        assert self.serial.truth is not None  # the emulator sends it before its first status
        self.arm = self.serial
        self.truth = self.serial.truth

    def inject(self, fault: str, drive: int) -> None:
        self.emulator.inject_fault(lambda plant: PlantFault(plant, fault, drive))

    def clear(self) -> None:
        self.emulator.clear_fault()

    def close(self) -> None:
        try:
            self.serial.close()
        finally:
            self.emulator.stop()


class _Watch:
    """Joint stage run last: limits, board-zone entries and the pen's path against the plant's ground truth."""

    def __init__(self, params: ArmParams, arm: Arm, truth: ArmTruth | LinkTruth, board: Whiteboard,
                 allowance_rad: float) -> None:
        self.params = params
        self.arm = arm
        self.truth = truth
        self.board = board
        allowance = (allowance_rad, 0.0, 0.0)
        self.lo = [d.limit_min_rad - a for d, a in zip(params.drives, allowance, strict=True)]
        self.hi = [d.limit_max_rad + a for d, a in zip(params.drives, allowance, strict=True)]
        g = params.true_geometry  # the true tool: the arm as built
        self._geometry = (g.L1, g.L2, g.L3, g.L4, g.l_f)
        self._step = 0
        self.limit_violations = 0
        self.zone_entries = 0
        self.smear_m = 0.0
        self.count_zone = False
        self.count_smear = False
        self._in_zone = True  # (where it was when the counting began does not count)
        self._pen: tuple[float, float] | None = None

    def tick(self, signals: Signals) -> None:
        truth, board = self.truth, self.params.board
        offsets, estimates, q_set = truth.offsets, self.arm.offset_estimates(), signals.q_set
        for i in range(3):
            q_cmd = q_set[i] - estimates[i] + offsets[i]
            if not self.lo[i] <= q_cmd <= self.hi[i]:
                self.limit_violations += 1
                break
        q1, q2, q3, q4 = truth.angles()
        x, y, z, _, _, _, _, _ = arm_chain_py(q1, q2, q3, q4, *self._geometry)
        self._step += 1
        if self.count_zone and self._step % ZONE_EVERY == 0:
            inside = any(board.in_zone(px, py, pz) for px, py, pz in link_points(np.array([q1, q2, q3, q4]),
                                                                                   self.params.true_geometry))
            if inside and not self._in_zone:
                self.zone_entries += 1
            self._in_zone = inside
        pressing = self.board.contact.pen_touching
        if self.count_smear and pressing and self._pen is not None:
            self.smear_m += math.hypot(x - self._pen[0], y - self._pen[1])
        self._pen = (x, y) if pressing else None


def _over_board(params: ArmParams, x: float, y: float) -> bool:
    x0, x1, y0, y1 = params.board.board_bounds()
    return x0 <= x <= x1 and y0 <= y <= y1


def _pen_down(robot: Robot, truth: ArmTruth | LinkTruth) -> bool:
    """The true pen tip presses the board with the pen upright (simulation only)."""
    x, y, z, phi = truth.tool_pose()
    return bool(robot.initialised and _over_board(robot.params, x, y) and z < robot.params.board.surface_z
                and abs(phi) < 0.2)


def _sponge_down(robot: Robot, truth: ArmTruth | LinkTruth) -> bool:
    """The sponge lies on the board (phi = 90 deg, the tool at sponge height)."""
    x, y, z, phi = truth.tool_pose()
    p = robot.params
    return bool(robot.control.erasing and abs(phi - math.pi / 2) < 0.05
                and z < p.board.surface_z + p.sponge.offset)


def reach_phase(robot: Robot, truth: ArmTruth | LinkTruth, phase: str) -> None:
    """Run the robot to the moment the phase's fault begins."""
    c = robot.control
    if phase == "initialising":
        robot.run_for(1.5)
        return
    if not robot.run_until(lambda: _pen_down(robot, truth), 120.0):
        raise FaultMatrixError("the field's first line never began")
    if phase == "drawing the field":
        robot.run_for(0.3)
        return
    if not robot.run_until(lambda: bool(c.ready), 200.0):
        raise FaultMatrixError("the field was never drawn")
    if phase == "drawing a symbol":
        c.row, c.column, c.symbol = 3, 3, 1
        robot.post("Control", "button")
        if not robot.run_until(lambda: _pen_down(robot, truth), 30.0):
            raise FaultMatrixError("the X's first line never began")
        robot.run_for(0.2)
        return
    robot.control_stage.erase_requested = True
    if not robot.run_until(lambda: _sponge_down(robot, truth), 60.0):
        raise FaultMatrixError("the sponge never came down")
    robot.run_for(0.3)


def _fastest_drive(robot: Robot) -> int:
    """The drive the PC commands fastest now (1-3)."""
    speeds = [abs(v) for v in robot.safety_stage.commanded_speed()]
    return 1 + int(np.argmax(speeds))


def run_cell(params: ArmParams, fault: str, phase: str, seed: int = 0, gains: Gains | None = None,
             arm: str = "sim", cache: Path | None = None) -> Cell:
    """Inject `fault` in `phase` on a new robot on a new `arm`, watch, reset, recover: one cell of the matrix.

    `cache`: the folder of the emulator's firmware builds (default: the user's cache).
    """
    if fault not in TWIN_FAULTS:
        raise FaultMatrixError(f"no fault {fault!r}; faults: {', '.join(TWIN_FAULTS)}")
    if phase not in PHASES:
        raise FaultMatrixError(f"no phase {phase!r}; phases: {', '.join(PHASES)}")
    if arm not in ARMS:
        raise FaultMatrixError(f"no arm {arm!r}; arms: {', '.join(ARMS)}")
    wall0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="ttt_sm_faults_") as tmp:
        bench = _TwinBench(params, seed, gains) if arm == "sim" else _EmulatorBench(params, seed, gains, Path(tmp),
                                                                                    cache)
        try:
            return _run_cell(params, fault, phase, seed, bench, Path(tmp), wall0)
        finally:
            bench.close()


def _run_cell(params: ArmParams, fault: str, phase: str, seed: int, bench: _TwinBench | _EmulatorBench,
              tmp: Path, wall0: float) -> Cell:
    arm, truth = bench.arm, bench.truth
    robot = Robot(params, seed=seed, arm=arm, truth=truth)
    one_step = robot.charts["DriveInit1"].search_speed * params.control.chart_dt  # type: ignore[attr-defined]
    watch = _Watch(params, arm, truth, robot.board,
                   allowance_rad=robot.charts["DriveInit1"].stall_lag + one_step)  # type: ignore[attr-defined]
    robot.sched.joint_stages.append(watch)
    record = GameRecord.open(tmp / "game.jsonl")
    robot.safety_stage.listeners.append(lambda kind, data: record.add(robot.t, kind, tick=robot.chart_ticks,
                                                                      **data))
    reach_phase(robot, truth, phase)
    drive = _fastest_drive(robot) if fault in DRIVE_FAULTS else 0
    t0 = robot.t
    record.add(t0, "fault", tick=robot.chart_ticks, fault=fault, phase=phase, drive=drive)
    if fault == "camera_lost":
        robot.camera_status.ok = False
    else:
        bench.inject(fault, drive or 1)
    watch.count_smear = True
    t_trip: float | None = None
    reason = ""
    moving_until = t0
    for _ in range(robot.sched.ticks_for(WATCH_S)):
        robot.chart_step()
        if t_trip is None and robot.tripped:
            t_trip = robot.t
            reason = robot.safety.reason  # the first reason: a held arm may trip the init charts next
            watch.count_zone = True
        if float(np.max(np.abs(truth.speed_load))) > REST_RAD_S:
            moving_until = robot.t
    watch.count_smear = False
    zone_in_watch = watch.zone_entries
    watch.count_zone = True  # the re-initialisation's entries, from the reset on
    bench.clear()
    robot.camera_status.ok = True
    record.add(robot.t, "fault_cleared", tick=robot.chart_ticks)
    robot.run_for(0.2)
    robot.post("Safety", "reset")
    robot.chart_step()
    recovered = robot.run_until(lambda: robot.initialised and not robot.tripped, RECOVER_S) \
        and not robot.tripped
    record.add(robot.t, "finished", tick=robot.chart_ticks, recovered=recovered)
    record.close()
    intact = _record_intact(record, tmp / "game.jsonl", t_trip is not None)
    detect = None if t_trip is None else round((t_trip - t0) * 1e3, 1)
    settled = t_trip is not None and moving_until < t0 + WATCH_S - 0.1
    return Cell(
        fault=fault, phase=phase, drive=drive, detected=t_trip is not None, detect_ms=detect, reason=reason,
        time_to_safe_ms=round(max(moving_until, t_trip or t0) * 1e3 - t0 * 1e3, 1) if settled else None,
        limit_violations=watch.limit_violations, board_zone_entries=zone_in_watch,
        board_zone_entries_reinit=watch.zone_entries - zone_in_watch,
        ink_smear_mm=round(watch.smear_m * 1e3, 2), record_intact=intact, recovered=bool(recovered),
        sim_s=round(robot.t, 3), wall_s=round(time.perf_counter() - wall0, 2),
    )


def _record_intact(record: GameRecord, path: Path, tripped: bool) -> bool:
    """The file holds every event recorded, in order, with the trip's reason if it tripped."""
    try:
        lines = read_record(path)
    except (OSError, ValueError):
        return False
    events = [line for line in lines if line.get("event") != "transition"]
    if events != [dict(e) for e in record.events] or events[-1]["event"] != "finished":
        return False
    trips = [e for e in events if e["event"] == "safety_trip"]
    return not tripped or (len(trips) >= 1 and bool(trips[0].get("reason")))


def _cell_task(params: ArmParams, fault: str, phase: str, seed: int, gains: Gains, arm: str,
               cache: Path | None) -> Cell:
    """One cell, as a worker runs it (a module-level function: a pool or Dask pickles it by name)."""
    return run_cell(params, fault, phase, seed, gains, arm, cache)


def _lost_cell(fault: str, phase: str, exc: BaseException) -> Cell:
    """A cell whose run raised, or that the pool or cluster lost: nothing detected, recovered or recorded;
    the reason says what happened."""
    return Cell(fault=fault, phase=phase, drive=0, detected=False, detect_ms=None,
                reason=f"the cell did not run to its end: {one_line(exc)}", time_to_safe_ms=None,
                limit_violations=0, board_zone_entries=0, board_zone_entries_reinit=0, ink_smear_mm=0.0,
                record_intact=False, recovered=False, sim_s=0.0, wall_s=0.0)


#: What a pool's fork server imports once for the fault matrix's workers.
FAULTS_PRELOAD = ("ttt_sm.faults.matrix",)


def fault_matrix(params: ArmParams, faults: Sequence[str] = TWIN_FAULTS, phases: Sequence[str] = PHASES,
                 seed: int = 0, status: Callable[[str], None] | None = None, arm: str = "sim",
                 cache: Path | None = None, runner: Runner | None = None) -> dict[str, Any]:
    """Every fault in every phase on `arm` (:data:`ARMS`): what ``ttt-sm faults --json`` prints.

    The cells share nothing (each builds its own robot on its own arm), so
    `runner` (:class:`~ttt_sm.runner.Runner`: this process by default, a local
    pool or a Dask cluster) runs them where it runs tasks; the report lists
    them in the order fault by phase whatever order they complete in, and
    is the same on every runner but for the wall times.  `status` hears
    ``k/N`` as the cells complete.  A cell that raises (or that the pool or
    cluster loses) is reported undetected, with the reason, and in
    ``errors``.  A Ctrl-C raises :class:`~ttt_sm.runner.SweepInterrupted`
    holding the report of the cells done so far (``"interrupted": true``).
    """
    if arm not in ARMS:
        raise FaultMatrixError(f"no arm {arm!r}; arms: {', '.join(ARMS)}")
    runner = runner or Runner()
    wall0 = time.perf_counter()
    load0 = _load()
    if arm == "emulator":
        build(cache=cache)  # here, once: a compiler that fails is one error, not one per cell
    gains = kept_gains(params)
    pairs = [(fault, phase) for fault in faults for phase in phases]
    tasks = [(params, fault, phase, seed, gains, arm, cache) for fault, phase in pairs]
    errors: dict[int, str] = {}

    def lost(i: int, exc: BaseException) -> Cell:
        errors[i] = f"{pairs[i][0]} while {pairs[i][1]}: {one_line(exc)}"
        return _lost_cell(*pairs[i], exc)

    def report(cells: list[Cell], cut: bool) -> dict[str, Any]:
        return _with_errors(_matrix_report(cells, arm, seed, wall0, load0, runner, interrupted=cut), errors)

    return runner.sweep(_cell_task, tasks, lost, report, "faults", status,
                        lambda cell, cells: f"{cell.fault} while {cell.phase} done")


def _with_errors(report: dict[str, Any], errors: dict[int, str]) -> dict[str, Any]:
    """`report` with ``errors``, the cells that did not run to their end, in the matrix's order (when any)."""
    if errors:
        report["errors"] = [errors[i] for i in sorted(errors)]
    return report


def _matrix_report(cells: list[Cell], arm: str, seed: int, wall0: float, load0: float | None, runner: Runner,
                   interrupted: bool) -> dict[str, Any]:
    """The report of `cells` (in the matrix's order), begun at `wall0` on `runner`."""
    detected = [c for c in cells if c.detected]
    late = [c for c in detected if c.detect_ms is not None and c.detect_ms > DETECT_TARGET_S * 1e3]
    wall_s = time.perf_counter() - wall0
    workers = runner.workers
    report: dict[str, Any] = {
        "arm": arm,
        "backend": BACKENDS[arm],
        "cells": [asdict(c) for c in cells],
        "summary": {
            "cells": len(cells),
            "detected": len(detected),
            "detected_within_100_ms": len(detected) - len(late),
            "undetected": [f"{c.fault} while {c.phase}" for c in cells if not c.detected],
            "max_detect_ms": max((c.detect_ms or 0.0) for c in detected) if detected else None,
            "limit_violations": sum(c.limit_violations for c in cells),
            "board_zone_entries": sum(c.board_zone_entries for c in cells),
            "board_zone_entries_reinit": sum(c.board_zone_entries_reinit for c in cells),
            "records_lost": sum(not c.record_intact for c in cells),
            "recovered": sum(c.recovered for c in cells),
        },
        "seed": seed,
        "wall_time_s": round(wall_s, 2),
        "load_average": [load0, _load()],
        # "backend" above is the arm's, as it was before the matrix had a runner: the runner's is "runner"
        "workers": workers,
        "runner": runner.backend,
        "throughput_per_worker": throughput(len(cells), wall_s, workers),
        "interrupted": interrupted,
    }
    return report


def _load() -> float | None:
    """The machine's load average over the last minute (None where the system tells none)."""
    try:
        return round(os.getloadavg()[0], 2)
    except (AttributeError, OSError):
        return None
