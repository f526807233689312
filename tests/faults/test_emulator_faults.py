"""Faults of the arm injected into the firmware emulator's plant: the C controller reads them as a board would.

The fault definitions are the twin's (``ttt_sm.faults.plant``); here they go
into a gated :class:`~ttt_sm.hardware.emulator.ArmEmulator` (the C firmware
on the twin's plant, behind a real pseudo-terminal) through its in-process
door, and the PC's side is :class:`~ttt_sm.hardware.serial_arm.SerialArm`.
First what each fault does to what the firmware reads; then a few cells of
the matrix over the emulator, asserting on what the emulated arm did (its
``EMU_TRUTH``).  The cells of the default suite are the cheap phases
(initialising, the field's first line: 5-20 s each on a loaded 2-core
machine; a symbol or the sponge needs the whole field drawn first, 30-55 s);
the whole matrix is a soak test (12 min).
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable, Iterator
from pathlib import Path

import numpy as np
import pytest

from ttt_sm.cli import main
from ttt_sm.faults.matrix import DETECT_TARGET_S, PHASES, Cell, fault_matrix, run_cell
from ttt_sm.faults.plant import SPIKE_A, FaultError, PlantFault
from ttt_sm.faults.twin import TWIN_FAULTS
from ttt_sm.hardware.emulator import ArmEmulator
from ttt_sm.hardware.serial_arm import SerialArm
from ttt_sm.params import load_params
from ttt_sm.twin import layout
from ttt_sm.twin.plant import REST_POSE, Plant
from ttt_sm.twin.tuning import design_gains

P = load_params()
GAINS = design_gains(P)
DIVIDER = P.control.chart_divider


@pytest.fixture
def linked(tmp_path: Path, firmware_cache: Path) -> Iterator[tuple[ArmEmulator, SerialArm]]:
    """A gated emulator sending its ground truth, and the PC's arm on its pty, the drives running."""
    with ArmEmulator(P, pace="gated", link=tmp_path / "arm", truth=True, cache=firmware_cache) as emu:
        arm = SerialArm(emu.port, P, GAINS, servo_angle=REST_POSE[3])
        try:
            yield emu, arm
        finally:
            arm.close()


def _fault(name: str, drive: int = 1) -> Callable[[Plant], PlantFault]:
    return lambda plant: PlantFault(plant, name, drive)


def test_a_frozen_encoder_is_the_count_the_c_controller_reads_while_the_motor_turns_on(linked) -> None:
    emu, arm = linked
    q = arm.encoder_angles()
    arm.set_setpoints([q[0] + 0.3, q[1], q[2], arm.servo_setpoint])
    arm.step(20 * DIVIDER)
    frozen = int(emu.plant.ints[0, layout.PI_COUNTS])
    emu.inject_fault(_fault("encoder_frozen", 1))
    q_true = arm.truth.q[0]
    arm.step(100 * DIVIDER)
    # the firmware read the frozen count at every step, and so did the PC; the load turned on regardless
    assert emu.firmware.sensors.counts[0] == frozen and arm.sensors().counts[0] == frozen
    assert abs(arm.truth.q[0] - q_true) > 0.05
    emu.clear_fault()
    arm.step(2 * DIVIDER)
    assert arm.sensors().counts[0] != frozen and emu.bench.fault is None


def test_a_current_spike_is_in_the_firmwares_reading_and_the_status_for_its_duration_only(linked) -> None:
    emu, arm = linked
    arm.step(5 * DIVIDER)
    before = arm.sensors().current_a[1]
    emu.inject_fault(_fault("current_spike", 2))
    arm.step(DIVIDER)
    assert arm.sensors().current_a[1] == pytest.approx(before + SPIKE_A, abs=2.0)  # the firmware's milliamps
    arm.step(5 * DIVIDER)
    assert abs(arm.sensors().current_a[1]) < 3.0


def test_a_blocked_motor_and_a_power_cut_change_the_emulators_plant_and_clearing_puts_it_back(linked) -> None:
    emu, arm = linked
    pp, pg = emu.plant.pp.copy(), emu.plant.pg.copy()
    emu.inject_fault(_fault("motor_blocked", 3))
    assert emu.plant.pp[2, layout.PP_QMIN] == emu.plant.pp[2, layout.PP_QMAX]
    emu.inject_fault(_fault("power_cut"))  # one fault at a time: the block is lifted first
    assert np.all(emu.plant.pp[:, layout.PP_SUPPLY] == 0.0) and emu.plant.pg[layout.PG_SV_RATE] == 0.0
    assert emu.plant.pp[2, layout.PP_QMIN] == pp[2, layout.PP_QMIN]
    arm.step(10 * DIVIDER)
    emu.clear_fault()
    assert np.array_equal(emu.plant.pp, pp) and np.array_equal(emu.plant.pg, pg)
    with pytest.raises(FaultError, match="drive must be 1, 2 or 3"):
        emu.inject_fault(_fault("encoder_jump", 4))
    assert emu.bench.fault is None


def _check(cell: Cell, reason: str) -> None:
    """The targets of the matrix, on what the emulated arm did."""
    assert cell.detected and cell.detect_ms is not None and cell.detect_ms <= DETECT_TARGET_S * 1e3, cell
    assert cell.reason.startswith(reason), cell
    assert cell.limit_violations == 0 and cell.board_zone_entries == 0, cell
    assert cell.record_intact and cell.recovered, cell


def test_a_frozen_encoder_while_initialising_over_the_emulator(firmware_cache: Path) -> None:
    cell = run_cell(P, "encoder_frozen", "initialising", gains=GAINS, arm="emulator", cache=firmware_cache)
    _check(cell, "encoder stalled while commanded to move on drive 1")
    assert cell.drive == 1 and cell.time_to_safe_ms is not None  # the stalled drive was switched off: at rest


def test_a_blocked_motor_mid_line_over_the_emulator(firmware_cache: Path) -> None:
    cell = run_cell(P, "motor_blocked", "drawing the field", gains=GAINS, arm="emulator", cache=firmware_cache)
    _check(cell, f"encoder stalled while commanded to move on drive {cell.drive}")
    assert cell.time_to_safe_ms is not None and cell.ink_smear_mm < 5.0, cell


def test_a_power_cut_mid_line_over_the_emulator(firmware_cache: Path) -> None:
    cell = run_cell(P, "power_cut", "drawing the field", gains=GAINS, arm="emulator", cache=firmware_cache)
    _check(cell, "encoder stalled while commanded to move on drive")
    assert cell.ink_smear_mm > 10.0, cell  # nothing holds drives 2 and 3 against gravity: docs/safety.md


def test_faults_arm_emulator_json_names_the_backend_and_reports_the_twins_keys(capsys) -> None:
    code = main(["faults", "--arm", "emulator", "--only", "current_spike", "--phases", "field", "--json"])
    report = json.loads(capsys.readouterr().out)
    assert report["arm"] == "emulator" and "C firmware" in report["backend"]
    (cell,) = report["cells"]
    assert set(cell) == {f.name for f in dataclasses.fields(Cell)}  # the same keys as the twin's cells
    assert cell["fault"] == "current_spike" and cell["phase"] == "drawing the field"
    assert cell["detected"] and cell["detect_ms"] <= DETECT_TARGET_S * 1e3 and cell["reason"].startswith(
        f"overcurrent on drive {cell['drive']}")
    assert cell["limit_violations"] == 0 and cell["record_intact"] and cell["recovered"], cell
    assert code == 0 and report["summary"]["cells"] == 1


def test_faults_refuses_an_arm_it_cannot_put_a_fault_in(capsys) -> None:
    with pytest.raises(SystemExit):
        main(["faults", "--arm", "serial:/dev/ttyACM0"])
    assert "which an arm behind a serial link has none of; choose emulator" in capsys.readouterr().err
    assert main(["faults", "--link", "--arm", "emulator"]) == 2
    assert "the link's faults always run against the firmware emulator" in capsys.readouterr().err


@pytest.mark.soak
def test_the_whole_matrix_over_the_emulator_meets_its_targets_but_for_the_servo_where_it_is_commanded_too_slowly(
        firmware_cache: Path, assert_matrix_targets: Callable[[list[dict]], None]) -> None:
    report = fault_matrix(P, arm="emulator", cache=firmware_cache)
    cells = report["cells"]
    assert report["arm"] == "emulator" and len(cells) == len(TWIN_FAULTS) * len(PHASES)
    assert_matrix_targets(cells)
