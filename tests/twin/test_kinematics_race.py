"""The IK race: every method lands within 1e-5 m where it converges, and says why when it does not."""

import numpy as np

from ttt_sm.params import load_params
from ttt_sm.twin.kinematics.chain import fk
from ttt_sm.twin.kinematics.race import METHODS, race

P = load_params()


def test_every_converged_method_is_within_1e_5_m_over_reachable_targets() -> None:
    rng = np.random.default_rng(26)
    converged = dict.fromkeys(METHODS, 0)
    for _ in range(40):
        # a pen target over the board's area in front of the arm, up to 3 cm above it, pen tilted a little
        target = rng.uniform([-0.12, 0.10, 0.0, -0.3], [0.12, 0.30, 0.03, 0.3])
        results = race(target, P)
        if results[2].reason == "out of reach":
            continue  # the arm reached it from behind the base axis: not a board target
        for r in results:
            if r.converged:
                assert r.reason == "converged"
                assert np.linalg.norm(fk(r.q, P.geometry)[:3] - target[:3]) <= 1e-5, (r.method, target)
                converged[r.method] += 1
            else:
                assert r.reason in ("singular", "iteration limit"), (r.method, r.reason)
    assert min(converged.values()) >= 5, converged


def test_out_of_reach_is_reported_as_such() -> None:
    results = race([0.0, 2.0, 0.0], P)
    assert [r.reason for r in results] == ["out of reach"] * len(METHODS)
    assert not any(r.converged for r in results)


def test_a_singular_start_is_reported_as_singular() -> None:
    # elbow straight (q3 = 0): det J = -r L2 L3 sin q3 = 0; the undamped twist step cannot move
    start = [0.0, 0.5, 0.0, 0.0]
    twist = race([0.05, 0.2, 0.0, 0.3], P, q0=start)[-1]
    assert twist.method == "twist"
    assert not twist.converged and twist.reason == "singular"
    assert len(twist.iterates) == 1
