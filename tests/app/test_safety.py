"""The Safety chart on the robot: no trip over normal runs, a real trip held, recorded and reset.

The chart's states and transitions are covered by the scenarios of
tests/scenarios; these tests drive the whole robot and assert what the arm
did (docs/safety.md).
"""

from __future__ import annotations

import numpy as np
import pytest

from ttt_sm.app.game import GameSession
from ttt_sm.app.game_outcome import GameError
from ttt_sm.app.init_wiring import random_power_on
from ttt_sm.app.robot import Robot
from ttt_sm.params import load_params

P = load_params()


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_whole_games_never_trip_the_safety_chart(seed: int) -> None:
    session = GameSession(P, seed=seed, robot_symbol="O" if seed % 2 else "X", engine="strong", camera="direct",
                          record_trace=False)
    report = session.play()
    assert report["outcome"] in ("X", "O", "draw") and report["erased"]
    safety = session.robot.safety
    assert safety.trips == 0 and not safety.tripped and safety.reason == ""
    assert not any(e["event"].startswith("safety") for e in session.record.events)


def test_initialising_from_random_power_on_poses_never_trips_the_safety_chart() -> None:
    rng = np.random.default_rng(7)
    poses = [q for q in (random_power_on(P, rng) for _ in range(12)) if q[1] < np.radians(90.0)][:5]
    assert len(poses) == 5
    for k, q in enumerate(poses):
        robot = Robot(P, seed=10 + k, q_start=q, settle_s=1.0)
        assert robot.run_until(lambda r=robot: r.initialised, 40.0), robot.safety.reason
        assert robot.safety.trips == 0


def test_a_drive_2_search_that_runs_into_its_hard_stop_trips_before_the_init_chart_gives_up() -> None:
    """Switched on with q2 near its upper stop (135 deg), drive 2's first turn (+34 deg) runs into it:
    the encoder stands still while the setpoint moves on, and the Safety chart stops the drive
    within 100 ms, long before DriveInit2 turns back and gives up (thesis section 3.1.2)."""
    robot = Robot(P, seed=15, q_start=np.radians([18.0, 134.0, -7.0, 10.0]), settle_s=1.0)
    sim = robot.sim
    assert sim is not None
    assert robot.run_until(lambda: sim.truth.at_limit[1] != 0 or robot.tripped, 40.0)
    assert not robot.tripped
    t_stop = robot.t
    assert robot.run_until(lambda: robot.tripped, 1.0)
    assert robot.t - t_stop <= 0.1
    # pushing the stop, the drive lags its setpoints and its encoder stops: either check trips the chart
    assert robot.safety.reason.startswith(("encoder stalled while commanded to move on drive 2",
                                           "following error on drive 2"))
    assert sim.truth.at_limit[1] == 1  # it stands at its upper stop
    assert not robot.init_stage.failed


def test_a_blocked_drive_mid_line_is_held_and_the_game_ends_with_the_reason_in_its_record() -> None:
    session = GameSession(P, seed=5, robot_symbol="O", engine="strong", camera="direct", record_trace=False)
    robot = session.robot
    board_z = P.board.surface_z
    x0, x1, y0, y1 = P.board.board_bounds()

    def pen_on_board() -> bool:
        x, y, z, _ = robot.truth.tool_pose()
        return bool(robot.initialised and x0 <= x <= x1 and y0 <= y <= y1 and z < board_z)

    assert robot.run_until(pen_on_board, 120.0)
    robot.run_for(0.3)
    # block the drive the line moves fastest where it stands: its hard stops close in on it
    sim = robot.sim
    assert sim is not None
    k = int(np.argmax(np.abs(robot.safety_stage.commanded_speed())))
    from ttt_sm.twin import layout
    sim.plant.pp[k, layout.PP_QMIN] = sim.plant.pp[k, layout.PP_QMAX] = float(sim.truth.q[k])
    t0 = robot.t
    assert robot.run_until(lambda: robot.tripped, 0.2)
    assert robot.t - t0 <= 0.1
    # the controller pushes against the block: its current, following error or stalled encoder trips the chart
    assert robot.safety.reason.startswith((f"overcurrent on drive {k + 1}", f"following error on drive {k + 1}",
                                           f"encoder stalled while commanded to move on drive {k + 1}"))
    held = np.delete(robot.arm.encoder_angles(), k)
    robot.run_for(1.0)
    assert np.allclose(np.delete(robot.arm.encoder_angles(), k), held, atol=0.01)  # the others held where they stood
    with pytest.raises(GameError, match="safety stop: "):
        session.play()
    trips = [e for e in session.record.events if e["event"] == "safety_trip"]
    assert len(trips) == 1 and trips[0]["reason"] == robot.safety.reason and trips[0]["drive"] == k + 1
    assert session.record.ended == "error"
    assert session.record.events[-1]["message"] == f"safety stop: {robot.safety.reason}"


def test_reset_after_a_trip_initialises_the_drives_again_and_the_arm_draws_the_field() -> None:
    robot = Robot(P, seed=0)
    assert robot.run_until(lambda: robot.initialised, 40.0)
    robot.run_for(2.0)
    robot.set_input("Safety", "err_1", 0.5, force=True)  # as if drive 1 lagged half a radian
    robot.chart_step()
    assert robot.tripped and robot.safety.reason == "following error on drive 1: 0.5 rad > 0.025 rad"
    robot.release("Safety", "err_1")
    robot.run_for(0.5)
    robot.post("Safety", "reset")
    robot.run_for(0.01)
    assert not robot.initialised and not robot.tripped
    assert robot.run_until(lambda: robot.initialised, 40.0)
    offsets = np.array(robot.arm.offset_estimates())
    assert robot.sim is not None
    assert np.allclose(offsets, robot.sim.truth.offsets, atol=2 * max(d.rad_per_count for d in P.drives))
    # the new Control chart starts from the beginning: it draws the field
    assert robot.run_until(lambda: bool(robot.control.ready), 150.0)
    assert robot.safety.trips == 1 and not robot.tripped


def test_the_monitor_block_feeds_what_the_arm_reports_every_chart_step() -> None:
    """The compiled Monitor (app/_monitor.py) against its definitions, checked inside every chart step of
    a robot initialising and then drawing the field: encoder angles (the arm's), encoder speeds from the
    counts, currents' magnitudes, the tool's height by forward kinematics of the encoder angles."""
    from ttt_sm.twin.kinematics import arm_chain_py

    robot = Robot(P, seed=4)
    arm, chart, g = robot.arm, robot.safety, P.geometry
    rpc = [d.rad_per_count for d in P.drives]
    dt = P.control.chart_dt

    class Probe:
        """A joint stage after the Safety stage: what the chart was fed, against the arm's readings now."""

        def __init__(self) -> None:
            self.counts = arm.sensors().counts
            self.checked = self.moving = 0

        def tick(self, signals: object) -> None:
            sensors = arm.sensors()
            enc = arm.encoder_angles()
            assert [chart.q_1, chart.q_2, chart.q_3] == list(enc)
            assert [chart.current_1, chart.current_2, chart.current_3] == [abs(i) for i in sensors.current_a]
            speeds = [abs(c - k) * r / dt for c, k, r in zip(sensors.counts, self.counts, rpc, strict=True)]
            assert [chart.speed_1, chart.speed_2, chart.speed_3] == pytest.approx(speeds, rel=1e-12, abs=1e-12)
            z = arm_chain_py(*enc, arm.servo_setpoint, g.L1, g.L2, g.L3, g.L4, g.l_f)[2]
            assert chart.Z_now == pytest.approx(z, abs=1e-12)
            assert robot.safety_stage.err == [chart.err_1, chart.err_2, chart.err_3]
            self.counts = sensors.counts
            self.checked += 1
            self.moving += any(abs(v) > 0.05 for v in (chart.cmd_speed_1, chart.cmd_speed_2, chart.cmd_speed_3))

    probe = Probe()
    stages = robot.sched.joint_stages
    stages.insert(stages.index(robot.safety_stage) + 1, probe)
    robot.run_for(30.0)
    assert robot.initialised and not robot.tripped
    assert probe.checked == robot.chart_ticks and probe.moving > 1000  # the init searches, then the field
    # the model follows the setpoints: the following errors stay within the limit the chart applies
    assert max(abs(chart.err_1), abs(chart.err_2), abs(chart.err_3)) < P.safety.max_following_error_rad
