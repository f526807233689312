"""The pen servo's feedback wire in the twin's plant: potentiometer -> RC filter -> ADC counts.

The plant reads the wiper of the servo's potentiometer (on its output
shaft) through the RC filter of the board's ADC pin into integer counts of
the board's ADC, with noise of its own generator (docs/hardware.md, "The
pen servo's feedback"); ``sensors().servo_rad`` is that reading through the
two-point calibration of ``[servo]``.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from ttt_sm.params import load_params
from ttt_sm.twin import layout
from ttt_sm.twin.plant import REST_POSE, Plant

P = load_params()
SERVO = P.servo


def _quiet(params=P, **servo):
    """`params` with the servo's feedback changed (noise off unless said)."""
    s = dataclasses.replace(params.servo, **{"feedback_noise_lsb": 0.0, **servo})
    return dataclasses.replace(params, servo=s)


def _plant(params, q4: float, seed: int = 0) -> Plant:
    return Plant(params, np.array([*REST_POSE[:3], q4]), np.random.default_rng(seed))


def _hold(q4: float) -> np.ndarray:
    """Actuator commands: the bridges off (the drives rest on friction), the servo commanded to `q4`."""
    act = np.zeros(layout.N_ACT)
    act[layout.ACT_SV_DUTY] = SERVO.duty_for_angle(q4)
    return act


def test_the_calibration_maps_its_two_points_and_is_linear_between_them():
    assert SERVO.feedback_counts(SERVO.feedback_cal_a_rad) == pytest.approx(SERVO.feedback_cal_a_counts)
    assert SERVO.feedback_counts(SERVO.feedback_cal_b_rad) == pytest.approx(SERVO.feedback_cal_b_counts)
    assert SERVO.feedback_angle(SERVO.feedback_cal_b_counts) == pytest.approx(SERVO.feedback_cal_b_rad)
    # the packaged calibration: 745 counts at -90 deg, 2978 at +90 deg, a 12-bit ADC
    assert SERVO.feedback_counts_per_rad == pytest.approx((2978 - 745) / math.pi)
    for q in (-1.5, 0.0, 0.7, 2.2):
        assert SERVO.feedback_angle(SERVO.feedback_counts(q)) == pytest.approx(q, abs=1e-12)


@pytest.mark.parametrize("q4", [-2.0, -0.5, 0.0, 0.3, 1.2, 2.5])
def test_without_noise_the_adc_reads_the_rounded_counts_of_the_servo_angle(q4):
    plant = _plant(_quiet(), q4)
    act = _hold(q4)
    for _ in range(50):
        plant.step(act)
    q_true = float(plant.pgs[layout.PGS_SV_Q])
    want = math.floor(SERVO.feedback_counts(q_true) + 0.5)
    assert plant.feedback_counts == want
    s = plant.sensors()
    # the angle the PC reads is the calibration of those counts: within half a count of the truth
    assert s.servo_rad == pytest.approx(SERVO.feedback_angle(want), abs=1e-12)
    assert abs(s.servo_rad - q_true) <= 0.5 / SERVO.feedback_counts_per_rad + 1e-12


def test_the_adc_clips_at_its_full_scale():
    # a calibration that puts the servo's upper end beyond the 12-bit range
    params = _quiet(feedback_cal_b_counts=4000.0)
    plant = _plant(params, 2.5)
    plant.step(_hold(2.5))
    assert plant.feedback_counts == 4095


def test_the_noise_is_about_one_count_rms_around_the_true_reading_and_independent_of_the_drives():
    q4 = 0.4
    plant = _plant(P, q4, seed=3)
    act = _hold(q4)
    for _ in range(200):  # the servo settles
        plant.step(act)
    ideal = SERVO.feedback_counts(float(plant.pgs[layout.PGS_SV_Q]))
    counts = []
    for _ in range(4000):
        plant.step(act)
        counts.append(plant.feedback_counts)
    c = np.array(counts, dtype=float)
    assert c.mean() == pytest.approx(ideal, abs=0.1)
    # 1 LSB rms of noise, and the rounding's 1/12 LSB^2: sqrt(1 + 1/12) = 1.04
    assert c.std() == pytest.approx(math.sqrt(1.0 + 1.0 / 12.0), rel=0.1)
    assert len(set(counts)) >= 5 and np.abs(c - ideal).max() < 6.0
    # seeded: the same seed reads the same counts; the drives' current noise is what it was without it
    again = _plant(P, q4, seed=3)
    quiet = _plant(_quiet(), q4, seed=3)
    for _ in range(200):
        again.step(act)
        quiet.step(act)
    again.step(act)
    quiet.step(act)
    assert again.feedback_counts == counts[0]
    assert again.sensors().current_a == quiet.sensors().current_a


def test_the_rc_filter_lags_a_move_by_its_time_constant():
    tau = 0.02  # a slow filter, so that its lag shows over the servo's own
    plant = _plant(_quiet(feedback_tau_s=tau), 0.0)
    act = _hold(0.5)
    lags = []
    for _ in range(400):
        plant.step(act)
        q = float(plant.pgs[layout.PGS_SV_Q])
        lags.append(q - SERVO.feedback_angle(plant.feedback_counts))
    lags_a = np.array(lags)
    # moving at the servo's slew rate (7 rad/s), a first-order filter trails by rate * tau (0.14 rad)
    assert lags_a.max() == pytest.approx(SERVO.rate_rad_s * tau, rel=0.1)
    assert abs(lags_a[-1]) < 1.0 / SERVO.feedback_counts_per_rad  # settled: within a count
    # the packaged 1 ms filter trails the same move by 0.007 rad at most
    plant = _plant(_quiet(), 0.0)
    worst = 0.0
    for _ in range(400):
        plant.step(act)
        worst = max(worst, float(plant.pgs[layout.PGS_SV_Q]) - SERVO.feedback_angle(plant.feedback_counts))
    assert worst == pytest.approx(SERVO.rate_rad_s * SERVO.feedback_tau_s, abs=1.0 / SERVO.feedback_counts_per_rad)


def test_a_stuck_servo_reads_where_it_stopped():
    plant = _plant(_quiet(), 0.0)
    plant.pg[layout.PG_SV_RATE] = 0.0  # what the fault matrix's servo_stuck does
    for _ in range(100):
        plant.step(_hold(0.8))
    assert plant.sensors().servo_rad == pytest.approx(0.0, abs=1.0 / SERVO.feedback_counts_per_rad)
