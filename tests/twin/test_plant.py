"""The simulated arm's physics: integration accuracy, friction, stops, gears, sensors, servo."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from ttt_sm.twin.gains import DriveNumberError
from ttt_sm.twin.sim import REST_POSE, ArmSim, SimError, gravity_torques


def open_loop_pattern(params, gains, substeps: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """All three drives under a PWM pattern: starts, reversals through the clearance, sticking, gravity."""
    sim = ArmSim(params, gains, q0=(0.0, 0.6, -0.9, 0.0), substeps=substeps, current_noise_a=0.0)
    pattern = [0.5, -0.3, 0.0, 0.8, -0.8, 0.05, -0.02, 0.3]
    parts = []
    for duty in pattern:
        sim.set_duty(1, duty)
        sim.set_duty(2, 0.6 * duty + 0.1)
        sim.set_duty(3, duty)
        parts.append(sim.run(120))
    cat = lambda name: np.concatenate([getattr(p, name) for p in parts])  # noqa: E731
    return cat("q_true")[:, :3], cat("q_motor"), cat("current_a")


def test_ten_substeps_match_a_hundred_times_finer_reference(params, gains):
    q, qm, i = open_loop_pattern(params, gains, 10)
    q_ref, qm_ref, i_ref = open_loop_pattern(params, gains, 1000)
    assert np.ptp(q_ref, axis=0).min() > 0.2  # the pattern really moves every drive
    assert np.abs(q - q_ref).max() < 1e-3
    assert np.abs(qm - qm_ref).max() < 1e-3
    assert np.abs(i - i_ref).max() < 0.05  # A, of currents swinging over about 12 A
    # and it converges: twice the sub-steps, about half the error (first order)
    q20, _, _ = open_loop_pattern(params, gains, 20)
    assert np.abs(q20 - q_ref).max() < 0.7 * np.abs(q - q_ref).max()


def test_unpowered_arm_only_loses_energy(params, gains):
    sim = ArmSim(params, gains, q0=(0.0, 1.2, -0.6, 0.0))
    for d in (1, 2, 3):
        sim.set_enabled(d, False)
    energy = [sim.truth.mechanical_energy()]
    for _ in range(1500):
        sim.step(1)
        energy.append(sim.truth.mechanical_energy())
    de = np.diff(energy)
    assert energy[-1] < 0.2 * energy[0]
    assert de.max() <= 1e-9 * energy[0]


def test_unpowered_drive_2_falls_toward_zero_and_friction_holds_it(params, gains):
    d2 = params.drives[1]
    sim = ArmSim(params, gains, q0=(0.0, 0.8, 0.0, 0.0))
    sim.settle_unpowered(3.0)
    q2 = sim.truth.q[1]
    # friction at the motor holds gravity up to the band where N Tc = gravity torque
    g_slope = -gravity_torques(params, (0.0, 1e-6, 0.0, 0.0))[1] / 1e-6  # N m / rad near zero
    band = d2.gear_ratio * d2.motor_coulomb / g_slope
    assert 0.05 < band < 0.2  # "within some degrees"
    assert abs(q2) < 1.1 * band
    # ... and it stays there: at rest, no current, the drives re-enabled hold it
    assert np.abs(sim.truth.speed_load).max() < 1e-9
    before = sim.truth.q
    sim.run(300, record=False)
    assert np.abs(sim.truth.q - before).max() < 1e-4


def test_rest_pose_is_held_by_friction_unpowered(params, gains):
    sim = ArmSim(params, gains)
    assert np.allclose(sim.truth.q, REST_POSE)
    sim.settle_unpowered(0.5)
    assert np.abs(sim.truth.q - REST_POSE).max() < 2e-3  # within the gear clearance and deflection


def test_hard_stop_holds_the_joint_and_the_motor_stalls(params, gains):
    d1 = params.drives[0]
    sim = ArmSim(params, gains, q0=(d1.limit_max_rad - 0.05, 0.0, 0.0, 0.0), current_noise_a=0.0)
    sim.set_duty(1, 0.6)
    tr = sim.run(800)
    assert tr.q_true[:, 0].max() <= d1.limit_max_rad  # never integrated past the stop
    assert sim.truth.q[0] == d1.limit_max_rad
    assert sim.truth.at_limit[0] and not sim.truth.at_limit[1]
    assert sim.truth.stalled[0]
    assert sim.truth.speed_motor[0] == 0.0
    stall_current = 0.6 * d1.supply_v / d1.resistance_ohm
    assert sim.truth.current_a[0] == pytest.approx(stall_current, rel=1e-3)
    # the motor winds into the gear only by the clearance and the spring deflection
    squeeze = sim.truth.q_motor[0] - d1.limit_max_rad
    torque = d1.torque_constant * stall_current * d1.gear_ratio
    assert squeeze == pytest.approx(d1.gear_clearance / 2 + (torque - 0) / d1.gear_stiffness, rel=0.05)


def test_pwm_saturates_at_the_supply_voltage(params, gains):
    def run(duty):
        sim = ArmSim(params, gains, q0=(-1.0, 0.0, 0.0, 0.0), current_noise_a=0.0)
        sim.set_duty(1, duty)
        return sim, sim.run(600)

    sim_sat, tr_sat = run(5.0)
    _, tr_one = run(1.0)
    assert np.array_equal(tr_sat.q_true, tr_one.q_true)
    assert tr_sat.duty[:, 0].max() == 1.0
    # at full duty the motor runs near its no-load speed V / Ke, less friction
    d1 = params.drives[0]
    no_load = d1.supply_v / d1.torque_constant
    assert 0.9 * no_load < sim_sat.truth.speed_motor[0] < no_load


def test_gear_clearance_load_lags_motor_on_reversal(params, gains):
    d1 = params.drives[0]
    sim = ArmSim(params, gains, q0=(0.0, 0.0, 0.0, 0.0), current_noise_a=0.0)
    sim.set_duty(1, 0.15)
    fwd = sim.run(400)
    sim.set_duty(1, -0.15)
    rev = sim.run(400)
    lag_fwd = fwd.q_motor[-1, 0] - fwd.q_true[-1, 0]
    lag_rev = rev.q_motor[-1, 0] - rev.q_true[-1, 0]
    # driving forward the motor side leads by half the clearance, reversed it trails by as much
    assert lag_fwd == pytest.approx(d1.gear_clearance / 2, rel=0.1)
    assert lag_rev == pytest.approx(-d1.gear_clearance / 2, rel=0.1)
    # on the way the motor crosses the clearance while the load coasts on, undriven
    gap = rev.q_motor[:, 0] - rev.q_true[:, 0]
    free = np.abs(gap) < 0.45 * d1.gear_clearance
    assert free.any() and not free[-100:].any()


def test_encoder_counts_are_relative_integers_that_quantize(params, gains):
    sim = ArmSim(params, gains, q0=(0.3, 0.5, -0.7, 0.0))
    s = sim.sensors()
    assert s.counts == (0, 0, 0)  # relative encoders: 0 at power-on
    assert np.all(sim.q_encoder == 0.0)  # offsets unknown to the controllers
    sim.set_duty(1, 0.3)
    sim.run(200)
    s = sim.sensors()
    assert all(isinstance(c, int) for c in s.counts)
    assert s.counts[0] > 1000
    sim.assume_initialised()
    rpc = np.array([d.rad_per_count for d in params.drives])
    err = sim.q_encoder - sim.truth.q_motor
    assert np.all(np.abs(err) <= rpc / 2 + 1e-12)
    assert np.allclose(sim.q_encoder / rpc - sim.offset_estimate / rpc, sim.sensors().counts)


def test_index_switch_level_and_latched_count_are_repeatable(params, gains):
    d1 = params.drives[0]
    offsets = []
    for q_start in (d1.index_rad + 0.3, d1.index_rad + 0.05):
        sim = ArmSim(params, gains, q0=(q_start, 0.0, 0.0, 0.0))
        assert sim.sensors().index[0] is True and sim.sensors().index_edges[0] == 0
        sim.set_duty(1, -0.2)
        while not sim.sensors().index_edges[0]:
            sim.step(1)
        down = sim.sensors()
        assert down.index[0] is False
        sim.run(100)
        sim.set_duty(1, 0.1)  # back over it, slowly, through the gear clearance
        while sim.sensors().index_edges[0] < 2:
            sim.step(1)
        up = sim.sensors()
        assert up.index[0] is True
        assert up.index_count[0] == down.index_count[0]  # the same count both ways
        # the init charts' estimate: the joint angle of the switch minus the latched counts
        estimate = d1.index_rad - up.index_count[0] * d1.rad_per_count
        assert abs(estimate - sim.truth.offsets[0]) <= d1.rad_per_count
        offsets.append(estimate - sim.truth.offsets[0])
    assert offsets[0] == pytest.approx(offsets[1], abs=1e-12)  # homing repeats to the count


def test_drive_3_index_switch_sits_just_below_its_upper_stop(params):
    d3 = params.drives[2]
    assert 0.0 < d3.limit_max_rad - d3.index_rad < math.radians(5.0)


def test_same_seed_same_run_other_seed_other_noise_only(params, gains):
    def run(seed):
        sim = ArmSim(params, gains, seed=seed, q0=(0.0, 0.5, -0.5, 0.0))
        sim.assume_initialised()
        sim.set_setpoints(np.append(sim.q_encoder + [0.2, -0.1, 0.1], 0.3))
        currents = []
        for _ in range(200):
            sim.step(2)
            currents.append(sim.sensors().current_a)
        return sim.truth.q, np.array(currents)

    q_a, i_a = run(7)
    q_b, i_b = run(7)
    q_c, i_c = run(8)
    assert np.array_equal(q_a, q_b) and np.array_equal(i_a, i_b)
    assert np.array_equal(q_a, q_c)  # the seed only draws the current-sensor noise
    assert not np.array_equal(i_a, i_c)
    assert 0.002 < np.std(i_a - i_c) < 0.03


def test_servo_follows_its_pwm_with_a_rate_limit(params, gains):
    s = params.servo
    sim = ArmSim(params, gains, q0=(0.0, 0.0, 0.0, 0.0))
    q = np.append(sim.q_encoder, 1.0)
    sim.set_setpoints(q)
    tr = sim.run(400)
    assert tr.duty[-1, 3] == pytest.approx(s.duty_for_angle(1.0))
    rate = np.diff(tr.q_true[:, 3]) / sim.dt
    assert rate.max() <= s.rate_rad_s * (1 + 1e-9)
    assert rate.max() > 0.99 * s.rate_rad_s  # a big step slews at the limit
    t_reach = tr.t[np.argmax(tr.q_true[:, 3] > 1.0 - s.clearance_rad)]
    assert 1.0 / s.rate_rad_s < t_reach < 1.0 / s.rate_rad_s + 5 * s.time_constant_s
    # gear play: the output stops within half the clearance of the command
    assert abs(sim.truth.q[3] - 1.0) <= s.clearance_rad / 2 + 1e-6


def test_bad_requests_are_specific_errors(params, gains):
    with pytest.raises(SimError, match=r"q0\[1\].*outside joint 2's limits"):
        ArmSim(params, gains, q0=(0.0, 3.0, 0.0, 0.0))
    with pytest.raises(SimError, match="4 finite joint angles"):
        ArmSim(params, gains, q0=(0.0, 0.0))
    sim = ArmSim(params, gains)
    with pytest.raises(DriveNumberError, match="drive must be 1, 2 or 3"):
        sim.set_enabled(0, False)
    with pytest.raises(SimError, match="4 finite angles"):
        sim.set_setpoints([0.0, float("nan"), 0.0, 0.0])
    for bad in ([0.0, 0.1, 0.2], [0.0, 0.1, 0.2, 0.3, 0.4], ["0.1", 0.0, 0.0, 0.0]):
        with pytest.raises(SimError, match="4 finite angles"):
            sim.set_setpoints(bad)  # type: ignore[arg-type]


def test_numba_disabled_runs_the_same_kernel(params, gains, tmp_path):
    code = textwrap.dedent("""
        import json, dataclasses
        from ttt_sm.params import load_params
        from ttt_sm.twin.gains import Gains, DriveGains
        from ttt_sm.twin.sim import ArmSim
        g = json.load(open(%r))
        gains = Gains(tuple(DriveGains(**d) for d in g))
        sim = ArmSim(load_params(), gains, q0=(0.0, 0.5, -0.5, 0.2))
        sim.assume_initialised()
        sim.set_setpoints(list(sim.q_encoder + [0.05, 0.05, -0.05]) + [0.4])
        sim.run(150)
        print(json.dumps(list(sim.truth.q) + list(sim.sensors().counts)))
    """)
    import dataclasses

    gfile = tmp_path / "gains.json"
    gfile.write_text(json.dumps([dataclasses.asdict(d) for d in gains.drives]))
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    out = subprocess.run([sys.executable, "-c", code % str(gfile)], env=env, capture_output=True,
                         text=True, check=True, timeout=120)
    slow = json.loads(out.stdout.strip().splitlines()[-1])
    sim = ArmSim(params, gains, q0=(0.0, 0.5, -0.5, 0.2))
    sim.assume_initialised()
    sim.set_setpoints(list(sim.q_encoder + [0.05, 0.05, -0.05]) + [0.4])
    sim.run(150)
    fast = list(sim.truth.q) + list(sim.sensors().counts)
    assert slow == pytest.approx(fast, abs=1e-9)


def test_the_plain_number_accessors_read_what_the_sensors_and_true_state_say(params, gains):
    sim = ArmSim(params, gains, seed=5)
    sim.set_offset_estimate(2, 0.125)
    sim.set_setpoints([0.2, 0.4, -0.6, 0.1])
    sim.run(300, record=False)  # mid-move
    sensors = sim.sensors()
    rpc = [d.rad_per_count for d in params.drives]
    offsets = sim.offset_estimate
    expected = [sensors.counts[d] * rpc[d] + offsets[d] for d in range(3)]
    assert sim.encoder_angles() == pytest.approx(expected, abs=1e-15) and offsets[1] == 0.125
    assert list(sim.truth.angles()) == sim.truth.q.tolist()
    assert all(type(v) is float for v in (*sim.encoder_angles(), *sim.truth.angles(), sim.t))
    assert sim.t == pytest.approx(0.3)
    sim.set_setpoints(np.array([0.1, 0.2, -0.3, 0.0], dtype=np.float32))  # any float type is taken
    sim.run(1, record=False)
    with pytest.raises(SimError):
        sim.set_setpoints([0.1, math.nan, 0.0, 0.0])
