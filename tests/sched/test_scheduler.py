"""The scheduler drives the real loop: twin, controllers, IK, stages, clamps."""

import numpy as np
import pytest

from ttt_sm.params import load_params
from ttt_sm.sched.clock import WallClock
from ttt_sm.sched.scheduler import PathStage, Scheduler, Signals, tool_path
from ttt_sm.sched.stages import JointMoveStage
from ttt_sm.sched.trajectory import Waypoint, distance_to_path, sample_polyline
from ttt_sm.twin.kinematics import HOME_Q, IKSolver, fk
from ttt_sm.twin.sim import ArmSim

P = load_params()


def ready(seed=0, record=False):
    """A twin standing at the home pose, homed, with its scheduler."""
    q0 = np.asarray(HOME_Q)
    sim = ArmSim(P, seed=seed, q0=q0)
    sched = Scheduler(P, sim, record=record)
    sim.assume_initialised()
    sched.mark_all_homed()
    return sim, sched


class TruthRecorder:
    """A joint stage that records the true joint angles every chart step (simulation only)."""

    def __init__(self, sim):
        self.sim = sim
        self.q = []

    def tick(self, signals: Signals) -> None:
        self.q.append(self.sim.truth.q)


class CountingStage:
    def __init__(self):
        self.ticks = 0
        self.times = []

    def tick(self, signals: Signals) -> None:
        self.ticks += 1
        self.times.append(signals.t)


def test_charts_tick_every_second_control_step():
    sim, sched = ready()
    stage = CountingStage()
    sched.task_stages = [stage]
    for _ in range(10):
        sched.control_step()
    assert sched.steps == 10
    assert stage.ticks == 5
    assert np.allclose(np.diff(stage.times), P.control.chart_dt)
    sched.run_for(0.1)
    assert stage.ticks == 5 + 50
    assert sim.t == pytest.approx(0.01 + 0.1)


def test_the_tool_follows_a_line_on_the_real_loop():
    sim, sched = ready(record=True)
    truth = TruthRecorder(sim)
    start = fk(sim.truth.q, P.geometry)
    line = [Waypoint(*start), Waypoint(start[0] - 0.04, start[1], start[2]),
            Waypoint(start[0] - 0.04, start[1] - 0.03, start[2])]
    samples = sample_polyline(line, 0.02, P.control.chart_dt)
    path = PathStage(samples)
    sched.task_stages = [path]
    sched.joint_stages = [truth]
    assert sched.run_until(lambda: path.done, timeout_s=10.0)
    sched.run_for(1.0)
    assert len(truth.q) == len(sched.record.q_encoder)
    tool = tool_path(P, np.asarray(truth.q))
    # the true tool (forward kinematics of the true joint angles) stays near the line
    dev = distance_to_path(tool[:, :3], samples[:, :3])
    assert dev.max() < 0.002
    # and ends where the path ends (static accuracy: gear play and encoder quantization)
    assert np.linalg.norm(tool[-1, :3] - samples[-1, :3]) < 0.001
    assert sched.ik_failures == 0 and sched.limit_clamps == 0


def test_an_unreachable_pose_holds_the_arm_and_is_reported():
    sim, sched = ready()
    sched.run_for(0.2)
    held = sim.truth.q.copy()
    far = np.array([[2.0, 0.0, 0.0, 0.0]] * 50)
    sched.task_stages = [PathStage(far)]
    sched.run_for(0.5)
    assert sched.ik_failures == 250
    assert "2" in sched.signals.ik_error
    assert np.abs(sim.truth.q - held).max() < 0.01
    lo, hi = np.asarray(P.joint_min), np.asarray(P.joint_max)
    assert np.all(sim.truth.q >= lo) and np.all(sim.truth.q <= hi)


class PastLimitStage:
    """A joint stage that asks drive 2 for more than its upper limit."""

    def tick(self, signals: Signals) -> None:
        q = np.array(signals.q_set, dtype=float)
        q[1] = P.drives[1].limit_max_rad + 0.3
        signals.q_set = q


def test_setpoints_past_a_joint_limit_are_clamped_once_homed():
    sim, sched = ready()
    sched.task_stages = []
    sched.joint_stages = [PastLimitStage()]
    sched.run_for(2.0)
    assert sched.limit_clamps == 1000
    assert sched.signals.q_set[1] == pytest.approx(P.drives[1].limit_max_rad)
    assert sim.truth.q[1] <= P.drives[1].limit_max_rad + P.drives[1].gear_clearance


def test_unhomed_drives_are_not_clamped_in_encoder_coordinates():
    sim = ArmSim(P, seed=1, q0=np.asarray(HOME_Q))
    sched = Scheduler(P, sim)
    sched.joint_stages = [PastLimitStage()]
    sched.run_for(0.01)
    assert sched.limit_clamps == 0
    assert sched.signals.q_set[1] > P.drives[1].limit_max_rad


def test_joint_move_stage_reaches_its_target_without_ik():
    sim, sched = ready()
    q_from = np.asarray(sim.q_encoder.tolist() + [sim.truth.q[3]])
    q_to = q_from + np.radians([20.0, -10.0, 10.0, 5.0])
    move = JointMoveStage(q_from, q_to, P.control.chart_dt, max_speed=0.5)
    sched.joint_stages = [move]
    assert sched.run_until(lambda: move.done, timeout_s=5.0)
    sched.run_for(1.0)
    assert np.abs(sim.q_encoder - q_to[:3]).max() < 2e-4
    assert abs(sim.truth.q[3] - q_to[3]) < np.radians(1.0)


def test_sensors_are_read_lazily_and_fresh_each_chart_step():
    sim, sched = ready()
    seen = []

    class Reader:
        def tick(self, signals):
            seen.append(signals.sensors)

    sched.task_stages = [Reader()]
    sched.run_for(0.01)
    assert len(seen) == 5
    assert [s.t for s in seen] == pytest.approx([k * P.control.chart_dt for k in range(5)])


def test_wall_clock_paces_every_control_step():
    sim, sched = ready()
    clock = WallClock(period_s=P.control.dt)
    sched.set_clock(clock)
    sched.run_for(0.05)
    assert clock.stats().periods == 50
    assert sim.t == pytest.approx(0.05)


def test_runs_are_reproducible_from_the_seed():
    def run(seed):
        sim = ArmSim(P, seed=seed)
        sched = Scheduler(P, sim)
        sim.assume_initialised()
        sched.mark_all_homed()
        ik = IKSolver(P)
        target = ik.solve(np.array([0.0, 0.25, 0.05, 0.0]), q0=np.asarray(HOME_Q)).q
        sched.joint_stages = [JointMoveStage(np.asarray(sim.q_encoder.tolist() + [sim.truth.q[3]]),
                                             target, P.control.chart_dt)]
        sched.run_for(1.0)
        s = sim.sensors()
        return sim.truth.q, s.counts, np.asarray(s.current_a)

    a, b = run(3), run(3)
    assert np.array_equal(a[0], b[0]) and tuple(a[1]) == tuple(b[1]) and np.array_equal(a[2], b[2])
    c = run(4)
    assert not np.array_equal(c[2], a[2])  # the seed drives the current-sensor noise
