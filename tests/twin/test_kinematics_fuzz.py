"""IK targets under fuzz: whatever a chart or a command line asks for, the solvers answer right or
raise an IKError; they never raise numpy's or Python's own errors, and never return a wrong pose."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import strategies as st

from fuzzing import fuzz
from ttt_sm.params import load_params
from ttt_sm.twin.kinematics import IKError, IKSolver, fk, ik_closed_form

PARAMS = load_params()
SOLVER = IKSolver(PARAMS)
Q_MIN, Q_MAX = np.array(PARAMS.joint_min), np.array(PARAMS.joint_max)

_FLOATS = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.floats(-0.6, 0.6),
                    st.sampled_from([0.0, -0.0, 1e-300, 1e308, -1e308, 0.25, 0.175, 0.325]))
_TARGETS = st.one_of(
    st.lists(_FLOATS, min_size=4, max_size=4),
    st.lists(_FLOATS, max_size=6),
    st.lists(st.one_of(_FLOATS, st.integers(-(10**400), 10**400), st.text(max_size=3), st.none()), min_size=4,
             max_size=4),
    st.just([[0.0, 0.25], [0.0, 0.0]]), st.text(max_size=5), st.none(), st.integers())


def solve_any(target: object) -> None:
    try:
        result = SOLVER.solve(target)
    except IKError as exc:
        assert "\n" not in str(exc) and len(str(exc)) < 500
    else:
        t = np.asarray(target, dtype=float)
        assert np.linalg.norm(fk(result.q, PARAMS.geometry) - t) <= PARAMS.ik.tolerance
        assert np.all(result.q >= Q_MIN - 1e-9) and np.all(result.q <= Q_MAX + 1e-9)
    try:
        ik_closed_form(target, PARAMS.geometry)
    except IKError:
        pass


test_any_target_is_solved_or_an_ik_error, test_any_target_is_solved_or_an_ik_error_soak = fuzz(
    _TARGETS, quick=300, soak=20000)(solve_any)


@pytest.mark.parametrize("target", [["a", "b", "c", "d"], [10**400, 0, 0, 0], [[1, 2], [3, 4]], None, "xyzw"])
def test_targets_that_are_not_four_numbers_are_an_ik_error(target):
    with pytest.raises(IKError, match=r"target must (have 4|be 4) "):
        SOLVER.solve(target)
    with pytest.raises(IKError, match=r"target must (have 4|be 4) "):
        ik_closed_form(target, PARAMS.geometry)
