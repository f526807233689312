"""The cascade controllers on the nonlinear twin: tracking, fr_sw, saturation, offsets (gains from twin/gains.py)."""

from __future__ import annotations

import math

import control as ct
import numpy as np
import pytest

from ttt_sm.twin.gains import (
    Gains,
    check_drive,
    max_joint_speed,
    setpoint_filter_matrices,
)
from ttt_sm.twin.sim import ArmSim

WORK_POSE = (0.0, 0.6, -1.0, 0.0)


def homed(params, gains, q0=WORK_POSE) -> tuple[ArmSim, np.ndarray]:
    sim = ArmSim(params, gains, q0=q0)
    sim.assume_initialised()
    return sim, np.append(sim.q_encoder, q0[3])


def test_setpoint_filter_is_exact_and_has_unit_dc_gain():
    dt, fc = 0.001, 8.0
    ad, bd = setpoint_filter_matrices(fc, dt)
    x = np.zeros(2)
    out = []
    for _ in range(600):
        x = ad @ x + bd * 1.0
        out.append(x[0])
    w = 2 * math.pi * fc
    cont = ct.ss([[0, 1], [-w * w, -2 * w]], [[0], [w * w]], [[1, 0]], 0)
    t = dt * np.arange(1, 601)
    ref = ct.step_response(cont, T=np.concatenate([[0.0], t])).outputs[1:]
    assert np.abs(np.array(out) - ref).max() < 1e-9  # ZOH-exact on a step
    assert out[-1] == pytest.approx(1.0, abs=1e-6)
    assert np.diff(out).min() >= 0.0  # critically damped: never overshoots


def test_holds_at_power_on_without_knowing_the_offsets(params, gains):
    sim = ArmSim(params, gains, q0=WORK_POSE)
    tr = sim.run(500)
    assert np.all(sim.offset_estimate == 0.0)
    assert np.abs(tr.q_encoder).max() < 5e-4  # held where it woke up, gravity notwithstanding
    assert np.abs(sim.truth.q - WORK_POSE).max() < 3e-3


def test_tracks_a_ramp(params, gains):
    sim, q = homed(params, gains)
    v = np.array([0.3, 0.3, -0.3, 0.0])
    errs, lags = [], []
    for k in range(600):  # chart ticks of 2 ms, as the scheduler sends setpoints
        sim.set_setpoints(q + v * k * 0.002)
        tr = sim.run(2)
        errs.append(tr.setpoint_filtered[-1, :3] - tr.q_encoder[-1])
        lags.append(tr.setpoint_raw[-1, :3] - tr.q_encoder[-1])
    errs_a = np.array(errs)[200:]
    # the cascade with speed feedforward follows its filtered setpoint within a few counts
    assert np.abs(errs_a).max() < 5e-4
    # against the raw ramp what remains is the setpoint filter's lag, 2 zeta / w times the speed
    lag_theory = 2.0 / (2 * math.pi * params.control.setpoint_cutoff_hz) * 0.3
    assert np.abs(lags[-1]) == pytest.approx(np.full(3, lag_theory), rel=0.1)


def test_fr_sw_slows_the_setpoint_filter(params, gains):
    t90 = {}
    for fr_sw in (False, True):
        sim, q = homed(params, gains)
        sim.set_setpoints(q + [0.1, 0.0, 0.0, 0.0], fr_sw=fr_sw)
        tr = sim.run(1500)
        frac = (tr.setpoint_filtered[:, 0] - q[0]) / 0.1
        t90[fr_sw] = tr.t[np.argmax(frac > 0.9)] - tr.t[0]
        assert np.abs(tr.setpoint_filtered[:, 0] - tr.q_encoder[:, 0]).max() < 0.01
    ratio = params.control.setpoint_cutoff_hz / params.control.setpoint_cutoff_slow_hz
    assert t90[True] / t90[False] == pytest.approx(ratio, rel=0.05)


def test_switching_fr_sw_mid_move_is_bumpless(params, gains):
    sim, q = homed(params, gains)
    sim.set_setpoints(q + [0.2, 0.0, 0.0, 0.0], fr_sw=True)
    a = sim.run(100)
    sim.set_setpoints(q + [0.2, 0.0, 0.0, 0.0], fr_sw=False)
    b = sim.run(100)
    r = np.concatenate([a.setpoint_filtered[:, 0], b.setpoint_filtered[:, 0]])
    step = np.diff(r)
    assert step[99] < 5 * step[98] + 1e-4  # no jump at the switch, only a faster approach


def test_speed_setpoint_is_clamped_and_a_long_saturated_slew_does_not_overshoot(params, gains):
    sim, q = homed(params, gains, q0=(-1.0, 0.6, -1.0, 0.0))
    sim.set_setpoints(q + [2.0, 0.0, 0.0, 0.0])
    tr = sim.run(1500)
    wmax = max_joint_speed(params.drives[0])
    assert np.abs(tr.speed_ref[:, 0]).max() == pytest.approx(wmax)
    assert np.abs(tr.duty[:, 0]).max() == 1.0  # the inner loop saturated too
    overshoot = (tr.q_encoder[:, 0] - (q[0] + 2.0)).max()
    assert overshoot < 1e-3  # 0.05 % of the move: the integrators did not wind up


def test_anti_windup_after_pushing_against_a_hard_stop(params, gains):
    d1 = params.drives[0]
    sim, q = homed(params, gains, q0=(d1.limit_max_rad - 0.2, 0.0, 0.0, 0.0))
    sim.set_setpoints(q + [0.5, 0.0, 0.0, 0.0])  # beyond the stop: the loop saturates for a second
    sim.run(1000)
    assert sim.truth.at_limit[0] and sim.duty[0] == 1.0
    assert sim.truth.current_a[0] == pytest.approx(d1.supply_v / d1.resistance_ohm, rel=0.01)  # stall current
    target = sim.q_encoder[0] - 0.3
    sim.set_setpoints(np.array([target, q[1], q[2], q[3]]))
    tr = sim.run(1000)
    assert tr.q_encoder[20, 0] < sim.q_encoder[0] + 0.3  # it leaves the stop at once
    assert (target - tr.q_encoder[:, 0]).max() < 1e-3  # and does not overshoot the new target
    assert abs(target - tr.q_encoder[-1, 0]) < 1e-4


def test_offset_estimate_change_does_not_move_the_arm(params, gains):
    sim = ArmSim(params, gains, q0=WORK_POSE)
    sim.run(200)
    before = sim.truth.q
    sim.set_offset_estimate(2, 1.234)
    sim.set_offset_estimate(3, -0.5)
    sim.run(500)
    assert sim.q_encoder[1] == pytest.approx(1.234, abs=2e-3)
    assert np.abs(sim.truth.q - before).max() < 5e-4


def test_disabled_drive_gets_no_pwm_and_enabling_holds_it(params, gains):
    sim, q = homed(params, gains, q0=(0.4, 0.0, 0.0, 0.0))
    sim.set_enabled(1, False)
    sim.set_setpoints(q + [0.5, 0.0, 0.0, 0.0])
    tr = sim.run(200)
    assert np.all(tr.duty[1:, 0] == 0.0)
    assert np.all(tr.q_encoder[:, 0] == tr.q_encoder[0, 0])
    assert sim.truth.current_a[0] == 0.0
    sim.set_enabled(1, True)  # holds where it is, whatever the old setpoint
    sim.run(200)
    assert abs(sim.q_encoder[0] - q[0]) < 1e-4


def test_servo_angle_is_sent_as_its_pwm_duty(params, gains):
    sim, q = homed(params, gains)
    sim.set_setpoints(q + [0.0, 0.0, 0.0, 0.7])
    tr = sim.run(50)
    assert tr.duty[-1, 3] == pytest.approx(params.servo.duty_for_angle(0.7))
    assert tr.setpoint_filtered[-1, 3] == pytest.approx(0.7)  # the angle that duty commands


def test_gains_are_numbered_like_the_thesis(gains):
    assert isinstance(gains, Gains)
    assert gains.drive(1) is gains.drives[0]
    assert check_drive(3) == 3
    with pytest.raises(ValueError):
        gains.drive(4)
