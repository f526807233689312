"""The DH table reproduces the thesis' forward kinematics (eqs. 3.17-3.25)."""

import math

import numpy as np

from ttt_sm.params import load_params
from ttt_sm.twin.kinematics.chain import fk
from ttt_sm.twin.kinematics.dh import dh_fk, dh_table


def test_dh_fk_equals_fk_at_random_poses_within_limits() -> None:
    p = load_params()
    rng = np.random.default_rng(26)
    for _ in range(500):
        q = rng.uniform(p.joint_min, p.joint_max)
        want, got = fk(q, p.geometry), dh_fk(q, p.geometry)
        assert np.max(np.abs(want[:3] - got[:3])) < 1e-12, q
        dphi = math.remainder(want[3] - got[3], 2 * math.pi)
        assert abs(dphi) < 1e-12, q


def test_dh_table_carries_the_link_lengths() -> None:
    g = load_params().geometry
    t = dh_table(g)
    assert t[:, 2].tolist() == [0.0, g.L2, g.L3, g.L4]
    assert t[:, 1].tolist() == [g.L1, g.l_f, 0.0, 0.0]
