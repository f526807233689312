"""The drive-initialisation charts on the real twin (thesis section 3.1.2)."""

import math

import numpy as np
import pytest

from ttt_sm.app.init_wiring import init_report, run_init
from ttt_sm.app.robot import Robot
from ttt_sm.params import load_params

P = load_params()
DEG = math.pi / 180


def one_count(d):
    return P.drives[d].rad_per_count


def test_from_the_rest_pose_every_drive_finds_its_index_to_within_a_count():
    r = run_init(P, seed=0)
    assert r.success
    assert r.limit_violations == 0 and r.board_zone_ticks == 0
    for d in range(3):
        assert abs(r.offset_error_rad[d]) < one_count(d)


def test_drive_1_turns_back_at_the_hard_stop_then_parks():
    robot = Robot(P, seed=0)  # rest pose: q1 = 0, above its index at -45 deg
    assert robot.run_until(lambda: "turn_back" in robot.active("DriveInit1"), timeout_s=10)
    # it turned back at the +170 deg stop, not before
    assert robot.truth.q[0] == pytest.approx(P.drives[0].limit_max_rad, abs=1 * DEG)
    assert robot.run_until(lambda: "wait_23" in robot.active("DriveInit1"), timeout_s=15)
    assert robot.value("DriveInit1", "ini_23") is True
    assert robot.truth.q[0] == pytest.approx(P.drives[0].park_rad, abs=0.2 * DEG)
    # drives 2 and 3 did not move before drive 1 parked
    assert abs(robot.truth.q[1] - 0.04) < 0.01


def test_drive_1_below_its_index_passes_it_without_touching_a_stop():
    robot = Robot(P, seed=0, q_start=np.radians([-120.0, 0.0, 0.0, 0.0]))
    seen = set()
    assert robot.run_until(lambda: seen.update(robot.active("DriveInit1")) or robot.initialised, 20)
    assert "turn_back" not in seen
    assert abs(robot.sim.offset_estimate[0] - robot.truth.offsets[0]) < one_count(0)


def test_nothing_passes_pos_in_before_all_drives_are_initialised():
    robot = Robot(P, seed=0)
    robot.run_for(2.0)
    assert not robot.initialised
    assert "pass_pos" not in robot.active("DriveInit2")
    assert robot.run_until(lambda: robot.initialised, 20)
    assert {"pass_pos"} <= robot.active("DriveInit1")
    assert robot.active("DriveInit2") == {"pass_pos"} == robot.active("DriveInit3")


def test_stop_halts_drive_1_and_it_resumes_where_it_was():
    robot = Robot(P, seed=0)
    robot.run_for(1.0)
    assert "turn_fwd" in robot.active("DriveInit1")
    robot.set_input("DriveInit1", "stop", True)
    robot.run_for(0.5)
    assert robot.active("DriveInit1") == {"stopped"}
    held = robot.truth.q[0]
    robot.run_for(0.5)
    assert abs(robot.truth.q[0] - held) < 0.002
    robot.set_input("DriveInit1", "stop", False)
    robot.chart_step()
    robot.chart_step()
    assert "turn_fwd" in robot.active("DriveInit1")  # history: back where it was
    assert robot.run_until(lambda: robot.initialised, 25)


def test_a_dead_index_switch_ends_in_failed_not_past_the_stops():
    robot = Robot(P, seed=0)
    robot.set_input("DriveInit1", "index", True, force=True)  # the switch never changes
    assert robot.run_until(lambda: "failed" in robot.active("DriveInit1"), timeout_s=30)
    q1 = robot.truth.q[0]
    assert P.drives[0].limit_min_rad - 0.01 <= q1 <= P.drives[0].limit_min_rad + 2 * DEG
    assert not robot.initialised


def test_drive_3_starting_on_its_switch_leaves_it_first():
    robot = Robot(P, seed=0, q_start=np.radians([0.0, 0.0, 28.5, 0.0]))
    seen = set()
    assert robot.run_until(lambda: seen.update(robot.active("DriveInit3")) or robot.initialised, 25)
    assert "leave_switch" in seen and "approach" not in seen
    assert abs(robot.sim.offset_estimate[2] - robot.truth.offsets[2]) < one_count(2)


def test_random_power_on_poses_all_initialise_safely():
    report = init_report(P, starts=8, seed=11)
    assert report["successes"] == 8
    assert report["limit_violations"] == 0
    assert report["board_zone_entries"] == 0
    assert report["max_offset_error_rad"] < report["one_count_rad"]


@pytest.mark.soak
def test_two_hundred_power_on_poses_all_initialise_safely():
    report = init_report(P, starts=200, seed=2026)
    assert report["successes"] == 200, report["failed_power_on_deg"]
    assert report["limit_violations"] == 0
    assert report["board_zone_entries"] == 0
    assert report["max_offset_error_rad"] < report["one_count_rad"]


def test_passing_and_gave_up_are_outputs_that_follow_pass_pos_and_failed():
    """What the application reads of the init charts (never their states): `passing`, `gave_up`."""
    robot = Robot(P, seed=0)
    charts = robot.init_stage.charts

    def consistent() -> bool:
        for c in charts:
            assert c.passing == ("pass_pos" in c.configuration_values)
            assert c.gave_up == ("failed" in c.configuration_values)
        return robot.initialised == all(c.passing for c in charts)

    assert robot.run_until(lambda: not consistent() or robot.initialised, 25) and consistent()
    # stopped after initialisation: drive 1 no longer passes its position through, and again once released
    robot.set_input("DriveInit1", "stop", True)
    robot.chart_step()
    assert consistent() and not charts[0].passing and not robot.initialised
    robot.set_input("DriveInit1", "stop", False)
    robot.chart_step()
    assert consistent() and charts[0].passing and robot.initialised
    # a dead switch: the chart gives up
    dead = Robot(P, seed=0)
    dead.set_input("DriveInit1", "index", True, force=True)
    assert dead.run_until(lambda: dead.init_stage.failed, 30)
    assert dead.init_stage.charts[0].gave_up and "failed" in dead.active("DriveInit1")


def test_init_runs_are_bounded_in_simulated_time_and_say_where_they_are():
    heard: list[str] = []
    report = init_report(P, 2, seed=3, timeout_s=1.0, status=heard.append)
    # one simulated second is too short to find the indexes: both runs stop there and count as failures
    assert report["successes"] == 0 and report["max_time_s"] == 1.0 and len(report["failed_power_on_deg"]) == 2
    assert heard == ["0/2 init: starting in this process"] + [f"{k}/2 init: 0 initialised so far" for k in (1, 2)]
