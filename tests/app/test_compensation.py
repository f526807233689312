"""The gear-play feedforward stage: what it adds to the setpoints, and when."""

import dataclasses

import numpy as np
import pytest

from ttt_sm.app.compensation import GearPlayCompensation, play_offsets
from ttt_sm.params import load_params
from ttt_sm.sched.scheduler import Signals

P = load_params()


def _signals(q):
    s = Signals()
    s.q_set = q
    return s


@pytest.mark.parametrize("q", [[0.1, 0.9, -1.2, 0.3], np.array([-0.4, 0.5, -0.2, 0.0]), (0.0, 1.4, 0.3, -1.0)])
def test_the_stage_shifts_drives_2_and_3_by_the_play_gravity_takes_up(q):
    s = _signals(q)
    GearPlayCompensation(P, lambda: True).tick(s)
    expected = np.asarray(q, dtype=float).copy()
    expected[:3] -= P.control.gear_play_compensation * play_offsets(P, np.asarray(q, dtype=float))
    assert s.q_set == pytest.approx(expected.tolist(), abs=1e-15)
    assert s.q_set[0] == q[0] and s.q_set[3] == q[3]  # the base and the servo are left alone
    shift = np.abs(np.asarray(s.q_set) - np.asarray(q, dtype=float))[1:3]
    half_play = [P.drives[d].gear_clearance / 2 for d in (1, 2)]
    assert all(shift >= half_play)  # at least half the clearance: gravity loads both gears here


def test_nothing_is_added_before_the_drives_are_initialised_or_with_gain_zero():
    q = [0.1, 0.9, -1.2, 0.3]
    s = _signals(list(q))
    GearPlayCompensation(P, lambda: False).tick(s)
    assert s.q_set == q
    off = dataclasses.replace(P, control=dataclasses.replace(P.control, gear_play_compensation=0.0))
    s = _signals(list(q))
    GearPlayCompensation(off, lambda: True).tick(s)
    assert s.q_set == q
