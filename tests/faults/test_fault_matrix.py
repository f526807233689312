"""Faults injected into the twin, and the matrix the Safety chart is measured by (docs/safety.md).

A quick subset runs in the default suite; the whole matrix is a soak test
(`make soak`): it takes minutes.
"""

from __future__ import annotations

import json
from collections.abc import Callable

import numpy as np
import pytest

from ttt_sm.app.robot import Robot
from ttt_sm.cli import main
from ttt_sm.faults.matrix import DETECT_TARGET_S, PHASES, WATCH_S, FaultMatrixError, fault_matrix, reach_phase, run_cell
from ttt_sm.faults.twin import ENCODER_JUMP_RAD, TWIN_FAULTS, FaultError, FaultyArm
from ttt_sm.params import load_params
from ttt_sm.twin import layout
from ttt_sm.twin.sim import ArmSim
from ttt_sm.twin.tuning import design_gains

P = load_params()
GAINS = design_gains(P)


def _arm() -> FaultyArm:
    sim = ArmSim(P, gains=GAINS, seed=0)
    sim.assume_initialised()
    return FaultyArm(sim)


def test_a_frozen_encoder_reads_the_same_count_while_the_motor_turns_and_clearing_restores_it() -> None:
    arm = _arm()
    arm.set_setpoints([0.3, *arm.encoder_angles()[1:], arm.servo_setpoint])
    arm.step(50)
    arm.inject("encoder_frozen", 1)
    frozen = arm.sensors().counts[0]
    q0 = arm.sim.truth.q[0]
    arm.step(200)
    assert arm.sensors().counts[0] == frozen and arm.sim.truth.q[0] != q0  # the arm moved, the count did not
    arm.clear()
    arm.step(1)
    assert arm.sensors().counts[0] != frozen


def test_an_encoder_jump_moves_the_count_by_its_angle_for_good() -> None:
    arm = _arm()
    before = arm.sensors().counts[1]
    arm.inject("encoder_jump", 2)
    arm.step(1)
    jump = (arm.sensors().counts[1] - before) * P.drives[1].rad_per_count
    assert jump == pytest.approx(ENCODER_JUMP_RAD, abs=5e-4)
    arm.clear()
    arm.step(1)
    assert (arm.sensors().counts[1] - before) * P.drives[1].rad_per_count == pytest.approx(jump, abs=1e-4)


def test_a_blocked_motor_and_a_power_cut_change_the_plant_and_clearing_puts_it_back() -> None:
    arm = _arm()
    pp = arm.sim.plant.pp.copy()
    pg = arm.sim.plant.pg.copy()
    arm.inject("motor_blocked", 3)
    assert arm.sim.plant.pp[2, layout.PP_QMIN] == arm.sim.plant.pp[2, layout.PP_QMAX]
    arm.inject("power_cut")  # one fault at a time: the block is lifted first
    assert np.all(arm.sim.plant.pp[:, layout.PP_SUPPLY] == 0.0) and arm.sim.plant.pg[layout.PG_SV_RATE] == 0.0
    assert arm.sim.plant.pp[2, layout.PP_QMIN] == pp[2, layout.PP_QMIN]
    arm.clear()
    assert np.array_equal(arm.sim.plant.pp, pp) and np.array_equal(arm.sim.plant.pg, pg)


def test_a_current_spike_is_in_the_readings_for_its_duration_only() -> None:
    arm = _arm()
    arm.inject("current_spike", 2)
    assert arm.sensors().current_a[1] > 9.0
    arm.step(10)
    assert abs(arm.sensors().current_a[1]) < 3.0


def test_unknown_faults_and_phases_are_refused_by_name() -> None:
    with pytest.raises(FaultError, match="the twin has no fault 'gremlins'"):
        _arm().inject("gremlins")
    with pytest.raises(FaultError, match="drive must be 1, 2 or 3"):
        _arm().inject("encoder_jump", 4)
    with pytest.raises(FaultMatrixError, match="no phase 'lunch'"):
        run_cell(P, "power_cut", "lunch")


@pytest.mark.parametrize("fault", ["encoder_jump", "current_spike", "motor_blocked"])
def test_faults_while_initialising_are_detected_in_time_and_the_arm_recovers(fault: str) -> None:
    cell = run_cell(P, fault, "initialising", gains=GAINS)
    assert cell.detected and cell.detect_ms is not None and cell.detect_ms <= DETECT_TARGET_S * 1e3, cell
    assert cell.drive == 1  # drive 1 is the one searching
    assert cell.limit_violations == 0 and cell.record_intact and cell.recovered, cell


def test_a_frozen_encoder_mid_line_is_detected_and_its_drive_switched_off() -> None:
    cell = run_cell(P, "encoder_frozen", "drawing the field", gains=GAINS)
    assert cell.detected and cell.detect_ms is not None and cell.detect_ms <= DETECT_TARGET_S * 1e3, cell
    assert cell.reason.startswith(f"encoder stalled while commanded to move on drive {cell.drive}")
    assert cell.limit_violations == 0 and cell.record_intact and cell.recovered, cell


def test_a_stuck_servo_while_erasing_is_detected_in_time_and_the_drives_lift_the_sponge_off() -> None:
    """While erasing the PC turns the servo 0.02 rad in 100 ms: its feedback falls behind the model by more
    than max_servo_error (0.015 rad) for servo_error_s (20 ms) within 100 ms of the onset."""
    cell = run_cell(P, "servo_stuck", "erasing", gains=GAINS)
    assert cell.detected and cell.detect_ms is not None and cell.detect_ms <= DETECT_TARGET_S * 1e3, cell
    assert cell.reason.startswith("servo stuck: pen servo at ") and cell.drive == 0
    assert cell.limit_violations == 0 and cell.record_intact and cell.recovered, cell


def test_a_servo_stuck_mid_line_is_found_once_its_model_leaves_it_and_the_drives_lift_the_pen() -> None:
    sim = ArmSim(P, gains=GAINS, seed=0)
    arm = FaultyArm(sim)
    robot = Robot(P, seed=0, arm=arm, truth=sim.truth)
    reach_phase(robot, sim.truth, "drawing the field")
    assert robot.board.contact.pen_touching
    arm.inject("servo_stuck")
    stuck = sim.truth.angles()[3]
    assert robot.run_until(lambda: robot.tripped, WATCH_S)
    assert robot.safety.reason.startswith("servo stuck") and robot.active("Safety") == {"safe", "lift"}
    # what tripped it: the model of the servo had moved on from where it stuck by more than the limit
    model = robot.safety.servo_q + robot.safety.servo_err
    assert abs(robot.safety.servo_q - stuck) < 0.005 and abs(model - stuck) > P.safety.max_servo_error_rad
    robot.run_for(1.0)
    assert robot.active("Safety") == {"safe", "hold"}
    # the drives lifted the pen off the board, 15 mm up (the servo, stuck, turned nothing)
    assert not robot.board.contact.pen_touching
    assert sim.truth.tool_pose()[2] > P.board.surface_z + 0.01
    assert sim.truth.angles()[3] == pytest.approx(stuck, abs=1e-9)


def test_a_servo_stuck_while_initialising_is_harmless_until_its_next_move_and_found_there() -> None:
    """While the drives initialise the servo is held still: a stuck servo goes unseen (the matrix's
    initialising cell), and is found at the first move the PC commands of it, once the Control chart runs."""
    sim = ArmSim(P, gains=GAINS, seed=0)
    arm = FaultyArm(sim)
    robot = Robot(P, seed=0, arm=arm, truth=sim.truth)
    robot.run_for(1.5)
    arm.inject("servo_stuck")
    stuck, t0 = arm.servo_setpoint, robot.t
    held: list[float] = []

    class Setpoints:
        def tick(self, signals: object) -> None:
            if not robot.tripped:
                held.append(abs(arm.servo_setpoint - stuck))

    robot.sched.joint_stages.append(Setpoints())
    assert robot.run_until(lambda: robot.tripped, 60.0)
    assert robot.initialised and robot.t - t0 > WATCH_S  # later than the matrix watches
    assert robot.safety.reason.startswith("servo stuck")
    # the servo was commanded nowhere until shortly before the trip
    steps_moving = sum(h > 1e-9 for h in held)
    assert max(held) > P.safety.max_servo_error_rad and steps_moving < len(held) // 10


def test_faults_json_reports_every_cell_with_its_keys(capsys: pytest.CaptureFixture[str]) -> None:
    code = main(["faults", "--only", "current_spike", "--phases", "init", "--json"])
    report = json.loads(capsys.readouterr().out)
    (cell,) = report["cells"]
    assert {"detected", "time_to_safe_ms", "limit_violations", "board_zone_entries", "ink_smear_mm",
            "record_intact", "recovered"} <= set(cell)
    assert cell["fault"] == "current_spike" and cell["phase"] == "initialising" and cell["detected"]
    assert code == 0 and report["summary"]["cells"] == 1


@pytest.mark.soak
def test_the_whole_matrix_meets_its_targets_but_for_the_servo_where_it_is_commanded_too_slowly(
        assert_matrix_targets: Callable[[list[dict]], None]) -> None:
    report = fault_matrix(P)
    cells = report["cells"]
    assert len(cells) == len(TWIN_FAULTS) * len(PHASES)
    assert_matrix_targets(cells)
