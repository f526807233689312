"""Forward and inverse kinematics of the RRRR arm (thesis section 3.4).

The closed-form solution is the oracle: it is exact, short, and shares no
code with the iterative solver the arm runs.
"""

from __future__ import annotations

import doctest
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from ttt_sm.params import IKParams, load_params
from ttt_sm.twin import kinematics as kin
from ttt_sm.twin.kinematics import (
    HOME_Q,
    IKError,
    IKResult,
    IKSolver,
    JointLimitError,
    NonFiniteTargetError,
    UnreachableTargetError,
    arm_chain,
    arm_chain_py,
    arm_points,
    damped_least_squares,
    fk,
    ik_closed_form,
    jacobian,
    link_points,
)
from ttt_sm.twin.kinematics.bench import bench_ik, cold_targets

PARAMS = load_params()
GEOM = PARAMS.geometry
BOARD = PARAMS.board
TOL = PARAMS.ik.tolerance
Q_MIN = np.array(PARAMS.joint_min)
Q_MAX = np.array(PARAMS.joint_max)
PHI_SPONGE = math.pi / 2

PROPERTY = settings(derandomize=True, max_examples=150, deadline=None,
                    suppress_health_check=[HealthCheck.filter_too_much, HealthCheck.too_slow])


# --------------------------------------------------------------------------- helpers

def transform(rot_z: bool, angle: float, offset: tuple[float, float, float]) -> np.ndarray:
    """A 4x4 homogeneous transform: rotation about Z or X, then `offset`."""
    c, s = math.cos(angle), math.sin(angle)
    T = np.eye(4)
    T[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]] if rot_z else [[1, 0, 0], [0, c, -s], [0, s, c]]
    T[:3, 3] = offset
    return T


def t40(q: np.ndarray) -> np.ndarray:
    """T40 = T10 T21 T32 T43, the matrices of eqs. 3.17-3.21 as printed."""
    q1, q2, q3, q4 = q
    g = GEOM
    return (transform(True, q1, (-g.l_f, 0, g.L1))
            @ transform(False, q2, (0, g.L2 * math.sin(q2), -g.L2 * math.cos(q2)))
            @ transform(False, q3, (0, g.L3 * math.sin(q3), -g.L3 * math.cos(q3)))
            @ transform(False, q4, (g.l_f, g.L4 * math.sin(q4), -g.L4 * math.cos(q4))))


def reach(q: np.ndarray) -> float:
    """r: how far the tool reaches out in the arm plane."""
    return GEOM.L2 * math.sin(q[1]) + GEOM.L3 * math.sin(q[1] + q[2]) + GEOM.L4 * math.sin(q[1:].sum())


def within_limits(q: np.ndarray, margin: float = 0.0) -> bool:
    return bool(np.all(q >= Q_MIN + margin) and np.all(q <= Q_MAX - margin))


def reachable(target: np.ndarray) -> bool:
    """The elbow-up closed form exists and lies within the joint limits."""
    try:
        return within_limits(ik_closed_form(target, GEOM))
    except UnreachableTargetError:
        return False


def full_reach_target(x: float, y: float, phi: float, q3: float = 0.0) -> np.ndarray:
    """The pose above (x, y) with tilt phi where the elbow is bent by exactly `q3`."""
    g = GEOM
    length = math.sqrt(g.L2**2 + g.L3**2 + 2 * g.L2 * g.L3 * math.cos(q3))
    r_w = math.sqrt((x + g.l_f) ** 2 + y**2 - g.l_f**2) - g.L4 * math.sin(phi)
    z = g.L1 - g.L4 * math.cos(phi) - math.sqrt(length**2 - r_w**2)
    return np.array([x, y, z, phi])


def r_zero_pose(q1: float, q2: float, q4: float) -> np.ndarray:
    """Joint angles with the tool on the arm-plane origin (r = 0): bisect q3 in (-pi, 0)."""
    lo, hi = -math.pi, 0.0
    def r_of(q3: float) -> float:
        return reach(np.array([q1, q2, q3, q4]))
    assert r_of(lo) * r_of(hi) < 0
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if r_of(lo) * r_of(mid) <= 0 else (mid, hi)
    return np.array([q1, q2, 0.5 * (lo + hi), q4])


def field_grid(n: int) -> list[tuple[float, float]]:
    x0, x1, y0, y1 = BOARD.field_bounds()
    return [(x, y) for x in np.linspace(x0, x1, n) for y in np.linspace(y0, y1, n)]


board_x = st.floats(BOARD.board_bounds()[0], BOARD.board_bounds()[1])
board_y = st.floats(BOARD.board_bounds()[2], BOARD.board_bounds()[3])


@st.composite
def board_targets(draw: st.DrawFn) -> np.ndarray:
    """Poses over the board: pen vertical, or sponge down with phi = 90 deg."""
    phi = draw(st.sampled_from([0.0, PHI_SPONGE]))
    if phi == 0.0:
        z = draw(st.floats(BOARD.surface_z - 0.005, BOARD.surface_z + 0.06))
    else:
        z = draw(st.floats(BOARD.surface_z + PARAMS.sponge.offset - 0.005, BOARD.surface_z + 0.08))
    return np.array([draw(board_x), draw(board_y), z, phi])


joint_angles = st.tuples(st.floats(-3.0, 3.0), st.floats(-3.0, 3.0), st.floats(-3.0, 3.0),
                         st.floats(-3.0, 3.0)).map(np.array)


# --------------------------------------------------------------------------- forward kinematics

def test_fk_of_zero_hangs_the_arm_straight_down_with_the_pen_vertical() -> None:
    g = GEOM
    np.testing.assert_allclose(fk(np.zeros(4), GEOM), [0.0, 0.0, g.L1 - g.L2 - g.L3 - g.L4, 0.0], atol=1e-15)


@PROPERTY
@given(joint_angles)
def test_fk_is_the_product_of_the_transformation_matrices(q: np.ndarray) -> None:
    T = t40(q)
    pose = fk(q, GEOM)
    np.testing.assert_allclose(pose[:3], T[:3, 3], atol=1e-12)
    # eq. 3.27: phi from R40 is q2 + q3 + q4 (up to whole turns).
    phi_from_r = math.atan2(T[2, 1], T[2, 2])
    assert math.remainder(pose[3] - phi_from_r, 2 * math.pi) == pytest.approx(0.0, abs=1e-12)


def test_printed_eqs_3_23_and_3_24_carry_typos_that_eq_3_21_does_not() -> None:
    q = np.radians([20.0, 70.0, -80.0, 10.0])
    q1, q2, q3, q4 = q
    g = GEOM
    x, y, z, _ = t40(q)[:3, 3].tolist() + [0.0]
    s1, c1 = math.sin(q1), math.cos(q1)
    r = reach(q)
    printed_x = (g.l_f * c1 - g.L2 * s1 * math.sin(q2) - g.L4 * s1 * math.sin(q2 + q3 + q4)
                 - g.L3 * s1 * math.sin(q2 + q3) - g.l_f)
    printed_y = g.l_f * s1 - r * c1
    printed_z = g.L1 - g.L2 * math.cos(q2) - g.L4 * math.cos(q4) + q3 + q2 - g.L3 * math.cos(q2 + q3)
    assert printed_x == pytest.approx(x, abs=1e-12)  # eq. 3.22 is right
    assert abs(printed_y - y) > 0.1  # eq. 3.23: -r cos q1 should be +r cos q1
    assert abs(printed_z - z) > 0.1  # eq. 3.24: L4 cos(q2 + q3 + q4), not L4 cos q4 + q3 + q2
    corrected_y = g.l_f * s1 + r * c1
    corrected_z = g.L1 - g.L2 * math.cos(q2) - g.L3 * math.cos(q2 + q3) - g.L4 * math.cos(q2 + q3 + q4)
    assert (corrected_y, corrected_z) == pytest.approx((y, z), abs=1e-12)


@PROPERTY
@given(joint_angles)
def test_the_one_arm_chain_gives_the_tool_pose_and_orientation_of_the_matrices(q: np.ndarray) -> None:
    g = GEOM
    lengths = (g.L1, g.L2, g.L3, g.L4, g.l_f)
    x, y, z, phi, s1, c1, s_phi, c_phi = arm_chain(*q.tolist(), *lengths)
    T = t40(q)
    np.testing.assert_allclose((x, y, z), T[:3, 3], atol=1e-12)
    assert phi == pytest.approx(q[1:].sum(), abs=1e-15)
    R = T[:3, :3]
    np.testing.assert_allclose((c1, s1, 0.0), R[:, 0], atol=1e-12)  # the tool's sideways offset
    np.testing.assert_allclose((-s1 * s_phi, c1 * s_phi, -c_phi), -R[:, 2], atol=1e-12)  # axis, to the tip
    np.testing.assert_allclose((s1 * c_phi, -c1 * c_phi, -s_phi), -R[:, 1], atol=1e-12)  # sponge normal
    # the Python original that chart-step code calls is the same chain
    np.testing.assert_allclose(arm_chain_py(*q.tolist(), *lengths), (x, y, z, phi, s1, c1, s_phi, c_phi),
                               rtol=0.0, atol=1e-15)


@PROPERTY
@given(joint_angles)
def test_arm_points_are_the_origins_of_the_matrices_along_the_chain(q: np.ndarray) -> None:
    q1, q2, q3, _ = q
    g = GEOM
    t10 = transform(True, q1, (-g.l_f, 0, g.L1))
    t20 = t10 @ transform(False, q2, (0, g.L2 * math.sin(q2), -g.L2 * math.cos(q2)))
    t30 = t20 @ transform(False, q3, (0, g.L3 * math.sin(q3), -g.L3 * math.cos(q3)))
    pts = arm_points(q, g)
    np.testing.assert_allclose(pts[0], (-g.l_f, 0.0, 0.0), atol=1e-15)  # the column's foot
    np.testing.assert_allclose(pts[1], t10[:3, 3], atol=1e-12)  # shoulder, joint 2
    np.testing.assert_allclose(pts[2], t20[:3, 3], atol=1e-12)  # elbow, joint 3
    np.testing.assert_allclose(pts[3], t30[:3, 3], atol=1e-12)  # wrist, the servo axis
    np.testing.assert_allclose(pts[4], t40(q)[:3, 3], atol=1e-12)  # pen tip
    np.testing.assert_array_equal(link_points(q, g), pts[2:])


def test_the_base_axis_is_the_vertical_line_x_minus_l_f() -> None:
    for q1 in np.linspace(-3, 3, 7):
        x, y, _, _ = fk([q1, 1.2, -0.9, 0.3], GEOM)
        r = reach(np.array([q1, 1.2, -0.9, 0.3]))
        assert math.hypot(x + GEOM.l_f, y) == pytest.approx(math.hypot(GEOM.l_f, r), abs=1e-12)


@PROPERTY
@given(joint_angles)
def test_jacobian_matches_central_finite_differences(q: np.ndarray) -> None:
    h = 1e-6
    numeric = np.column_stack([(fk(q + h * e, GEOM) - fk(q - h * e, GEOM)) / (2 * h) for e in np.eye(4)])
    np.testing.assert_allclose(jacobian(q, GEOM), numeric, atol=1e-8)


@PROPERTY
@given(joint_angles)
def test_jacobian_determinant_vanishes_with_the_elbow_straight_or_r_zero(q: np.ndarray) -> None:
    expected = -reach(q) * GEOM.L2 * GEOM.L3 * math.sin(q[2])
    assert np.linalg.det(jacobian(q, GEOM)) == pytest.approx(expected, abs=1e-12)


# --------------------------------------------------------------------------- closed form

@PROPERTY
@given(board_targets(), st.booleans())
def test_closed_form_agrees_with_fk(target: np.ndarray, elbow_up: bool) -> None:
    try:
        q = ik_closed_form(target, GEOM, elbow_up=elbow_up)
    except UnreachableTargetError:
        assume(False)
    np.testing.assert_allclose(fk(q, GEOM), target, atol=1e-12)
    assert (q[2] <= 0) == elbow_up or q[2] == 0


@pytest.mark.parametrize("target, why", [
    ([2.0, 0.0, 0.0, 0.0], "links"),
    ([-GEOM.l_f, 0.01, 0.1, 0.0], "base axis"),
])
def test_closed_form_rejects_unreachable_targets(target: list[float], why: str) -> None:
    with pytest.raises(UnreachableTargetError) as info:
        ik_closed_form(target, GEOM)
    assert why in str(info.value)
    assert info.value.residual > 0


# --------------------------------------------------------------------------- iterative solver

@PROPERTY
@given(board_targets())
def test_cold_solve_reaches_every_reachable_board_pose(target: np.ndarray) -> None:
    assume(reachable(target))
    solver = IKSolver(PARAMS)
    result = solver.solve(target)
    assert result.converged and result.residual <= TOL
    assert np.linalg.norm(fk(result.q, GEOM) - target) <= TOL
    assert within_limits(result.q, margin=-1e-9)
    assert np.all(np.isfinite(result.q))


@PROPERTY
@given(board_targets(), st.tuples(*[st.floats(-0.05, 0.05)] * 4))
def test_solver_from_a_nearby_start_finds_the_closed_form_solution(target: np.ndarray,
                                                                  offset: tuple[float, ...]) -> None:
    assume(reachable(target))
    oracle = ik_closed_form(target, GEOM)
    assume(abs(math.sin(oracle[2])) > 0.05)  # away from full reach, the elbow-up solution is unique nearby
    result = IKSolver(PARAMS).solve(target, q0=oracle + np.array(offset))
    # The solver stops at |e| <= TOL (m and rad mixed), which bounds the joints only to TOL / sigma_min(J):
    # 3.7e-4 rad at (0.06, 0.35) m, where the found q is 1.4e-4 rad from the closed form.
    atol = max(1e-4, TOL / np.linalg.svd(jacobian(oracle, GEOM), compute_uv=False).min())
    np.testing.assert_allclose(result.q, oracle, atol=atol)


def test_warm_start_continues_from_the_last_solution() -> None:
    solver = IKSolver(PARAMS)
    assert solver.last_q is None
    first = solver.solve([0.0, 0.25, 0.0, 0.0])
    assert solver.last_q is first.q
    for k in range(1, 50):  # a drawn line, 0.15 mm per tick
        result = solver.solve([0.00015 * k, 0.25, 0.0, 0.0])
        assert result.iterations <= 2
    solver.reset()
    assert solver.last_q is None


def test_solve_pose_gives_solve_s_answers_and_errors() -> None:
    """The control loop's solve_pose: same angles, warm start and errors as solve."""
    fast, full = IKSolver(PARAMS), IKSolver(PARAMS)
    rng = np.random.default_rng(3)
    x, y = 0.0, 0.25
    for _ in range(300):  # a random walk over the field, 0.2 mm per tick, and a few jumps
        x, y = x + rng.normal(0.0, 2e-4), y + rng.normal(0.0, 2e-4)
        if rng.random() < 0.02:
            x, y = rng.uniform(-0.08, 0.08), rng.uniform(0.18, 0.32)
        pose = [x, y, 0.01, 0.0]
        q, iterations = fast.solve_pose(*pose)
        result = full.solve(pose)
        assert q == tuple(result.q.tolist()) and all(type(v) is float for v in q)
        assert iterations == result.iterations
        if rng.random() < 0.1:  # last_q, made on demand, is the same answer, read-only
            np.testing.assert_array_equal(fast.last_q, q)
            assert not fast.last_q.flags.writeable
    with pytest.raises(UnreachableTargetError):
        fast.solve_pose(2.0, 0.0, 0.0, 0.0)
    with pytest.raises(JointLimitError):
        fast.solve_pose(0.0, 0.25, 0.05, math.radians(-80))
    with pytest.raises(NonFiniteTargetError):
        fast.solve_pose(0.0, math.nan, 0.0, 0.0)
    np.testing.assert_array_equal(fast.last_q, full.last_q)  # errors leave the warm start alone
    assert fast.solve_pose(x, y, 0.01, 0.0)[0] == tuple(full.solve([x, y, 0.01, 0.0]).q.tolist())
    fast.reset()
    assert fast.last_q is None
    assert fast.solve_pose(0.0, 0.25, 0.0, 0.0)[0] == tuple(IKSolver(PARAMS).solve([0.0, 0.25, 0.0, 0.0]).q.tolist())


def test_result_is_frozen_and_its_angles_read_only() -> None:
    result = IKSolver(PARAMS).solve([0.0, 0.25, 0.02, 0.0])
    assert isinstance(result, IKResult)
    with pytest.raises(AttributeError):
        result.iterations = 0  # type: ignore[misc]
    with pytest.raises(ValueError):
        result.q[0] = 1.0


def test_home_pose_is_elbow_up_above_the_field_centre() -> None:
    x, y, z, phi = fk(HOME_Q, GEOM)
    assert (x, y) == pytest.approx((BOARD.field_center_x, BOARD.field_center_y), abs=0.01)
    assert 0.03 < z - BOARD.surface_z < 0.07 and phi == pytest.approx(0.0, abs=1e-12)
    assert HOME_Q[2] < 0 and within_limits(np.array(HOME_Q), margin=math.radians(5))


def test_a_start_in_the_other_elbow_configuration_falls_back_to_the_home_pose() -> None:
    target = np.array([0.03, 0.2, 0.01, 0.0])
    elbow_down = ik_closed_form(target, GEOM, elbow_up=False)
    assert elbow_down[2] > Q_MAX[2]  # that solution breaks the elbow limit
    result = IKSolver(PARAMS).solve(target, q0=elbow_down)
    np.testing.assert_allclose(result.q, ik_closed_form(target, GEOM), atol=1e-5)


def test_python_kernel_matches_the_compiled_one() -> None:
    """NUMBA_DISABLE_JIT=1 runs the same code as plain Python; both must agree."""
    kernel = kin.dls._dls_kernel
    python_kernel = getattr(kernel, "py_func", kernel)
    target = np.array([0.05, 0.3, 0.01, 0.0])
    geom = np.array([GEOM.L1, GEOM.L2, GEOM.L3, GEOM.L4, GEOM.l_f])
    compiled = kernel(target, np.array(HOME_Q), geom, 1e-3, 1e-5, 100, True)
    python = python_kernel(target, np.array(HOME_Q), geom, 1e-3, 1e-5, 100, True)
    np.testing.assert_allclose(python[0], compiled[0], atol=1e-12)
    assert python[1] == compiled[1]


# --------------------------------------------------------------------------- singular poses

@pytest.mark.parametrize("start", [np.zeros(4), np.array(HOME_Q)], ids=["hanging q=0", "home"])
def test_fixed_damping_fails_on_cold_starts_where_adaptive_damping_never_does(start: np.ndarray) -> None:
    """The thesis' loop with lambda = 0.001 over 1000 board poses (a fifth of them at full reach).

    From the hanging pose (r = 0 and q3 = 0: det J = 0) its first step is about
    |e| / (2 lambda), hundreds of radians; from home, turning phi by 90 deg
    in one Newton step winds joints into a far local minimum.  Adaptive
    damping with a 1 rad step limit converges everywhere in a few steps.
    """
    targets = cold_targets(PARAMS, np.random.default_rng(0), 1000)
    fixed = [damped_least_squares(t, start, GEOM, PARAMS.ik, adaptive=False) for t in targets]
    adaptive = [damped_least_squares(t, start, GEOM, PARAMS.ik, adaptive=True) for t in targets]
    assert all(r.converged for r in adaptive)
    assert max(r.iterations for r in adaptive) <= 12
    assert sum(not r.converged for r in fixed) >= 3
    assert max(np.abs(r.q).max() for r in fixed) > 10 * 2 * math.pi  # wound through many turns


@pytest.mark.parametrize("q_star", [
    np.array([0.3, 1.0, 0.0, -1.0]),  # elbow straight, full reach
    r_zero_pose(0.3, 0.8, 0.2),  # tool on the arm-plane origin
    np.array([0.2, 0.0, 0.0, 0.0]),  # both: hanging straight down
], ids=["q3=0", "r=0", "both"])
def test_fixed_damping_creeps_near_a_singular_target_where_adaptive_converges(q_star: np.ndarray) -> None:
    """Within sqrt(mu) of the singular solution the fixed-lambda step shrinks; |e| falls like 1/k."""
    target = fk(q_star, GEOM)
    q0 = q_star + np.array([0.1, -0.1, 0.1, -0.1])
    strict = IKParams(damping=PARAMS.ik.damping, tolerance=1e-8, max_iterations=100)
    fixed = damped_least_squares(target, q0, GEOM, strict, adaptive=False)
    adaptive = damped_least_squares(target, q0, GEOM, strict, adaptive=True)
    assert not fixed.converged and 1e-8 < fixed.residual < TOL  # stalled on the plateau
    assert adaptive.converged and adaptive.iterations <= 15
    # At the thesis' tolerance both get there; the plateau starts just above it.
    assert damped_least_squares(target, q0, GEOM, PARAMS.ik, adaptive=True).iterations <= \
        damped_least_squares(target, q0, GEOM, PARAMS.ik, adaptive=False).iterations


@pytest.mark.parametrize("phi", [0.0, PHI_SPONGE])
@pytest.mark.parametrize("q3", [0.0, -1e-4, -1e-2])
def test_solver_converges_at_full_reach_over_the_board(phi: float, q3: float) -> None:
    x0, x1, _, y1 = BOARD.board_bounds()
    target = full_reach_target(0.5 * x0 if phi == 0 else 0.0, y1 if phi == 0 else 0.6 * y1, phi, q3)
    solver = IKSolver(PARAMS)
    result = solver.solve(target)
    assert np.linalg.norm(fk(result.q, GEOM) - target) <= TOL
    assert abs(result.q[2]) < 0.02


def test_solver_converges_with_the_tool_on_the_arm_plane_origin() -> None:
    target = fk(r_zero_pose(0.0, 1.0, -0.5), GEOM)
    result = IKSolver(PARAMS).solve(target)
    assert np.linalg.norm(fk(result.q, GEOM) - target) <= TOL


# --------------------------------------------------------------------------- errors

def test_unreachable_target_names_the_target_and_the_best_residual() -> None:
    with pytest.raises(UnreachableTargetError) as info:
        IKSolver(PARAMS).solve([2.0, 0.0, 0.0, 0.0])
    err = info.value
    assert err.target == (2.0, 0.0, 0.0, 0.0)
    # The best the arm can do is to stretch towards it: about 2 m - (l_f + L2 + L3 + L4) short.
    assert 1.4 < err.residual < 1.8
    assert "x=2.0000 m" in str(err) and f"{err.residual:.3g}" in str(err)
    assert isinstance(err, IKError) and isinstance(err, ValueError)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_targets_are_rejected(bad: float) -> None:
    solver = IKSolver(PARAMS)
    for i in range(4):
        target = [0.0, 0.25, 0.0, 0.0]
        target[i] = bad
        with pytest.raises(NonFiniteTargetError):
            solver.solve(target)
        with pytest.raises(NonFiniteTargetError):
            ik_closed_form(target, GEOM)
    with pytest.raises(NonFiniteTargetError):
        solver.solve([0.0, 0.25, 0.0, 0.0], q0=[0.0, bad, 0.0, 0.0])
    assert solver.last_q is None


def test_a_pose_only_reachable_outside_the_servo_range_raises_joint_limit_error() -> None:
    target = [0.0, 0.25, 0.05, math.radians(-80)]  # the tool tilted back: q4 ~ -123 deg
    with pytest.raises(JointLimitError) as info:
        IKSolver(PARAMS).solve(target)
    assert info.value.joint == 4
    assert info.value.angle < Q_MIN[3]
    assert "q4 = -123" in str(info.value)


def test_wrong_shapes_are_rejected() -> None:
    with pytest.raises(IKError):
        IKSolver(PARAMS).solve([0.0, 0.25, 0.0])


@settings(derandomize=True, max_examples=300, deadline=None)
@given(st.tuples(*[st.floats(-1.0, 1.0)] * 3), st.floats(-math.pi, math.pi))
def test_the_solver_never_returns_nan_nor_a_wrong_answer(xyz: tuple[float, float, float], phi: float) -> None:
    solver = IKSolver(PARAMS)
    target = np.array([*xyz, phi])
    try:
        result = solver.solve(target)
    except IKError:
        return
    assert np.all(np.isfinite(result.q))
    assert np.linalg.norm(fk(result.q, GEOM) - target) <= TOL
    assert within_limits(result.q, margin=-1e-9)


# --------------------------------------------------------------------------- reachability (issue item 2)

MARGIN = math.radians(5.0)
MIN_SIN_Q3 = 0.2  # elbow bent by more than ~11.5 deg: away from full reach
MIN_REACH = 0.10  # m: the tool well away from the arm-plane origin (r = 0)


@pytest.mark.parametrize("phi, z_from", [(0.0, 0.0), (PHI_SPONGE, PARAMS.sponge.offset)],
                         ids=["pen vertical", "sponge down"])
def test_the_whole_field_is_reachable_with_margin(phi: float, z_from: float) -> None:
    """Every point of the 15 x 15 cm field, up to 5 cm above the working height."""
    worst_margin, worst_sin_q3, worst_reach = math.inf, math.inf, math.inf
    for x, y in field_grid(31):  # 5 mm grid
        for lift in np.linspace(0.0, 0.05, 6):
            target = np.array([x, y, BOARD.surface_z + z_from + lift, phi])
            q = ik_closed_form(target, GEOM)
            worst_margin = min(worst_margin, (q - Q_MIN).min(), (Q_MAX - q).min())
            worst_sin_q3 = min(worst_sin_q3, abs(math.sin(q[2])))
            worst_reach = min(worst_reach, reach(q))
    assert worst_margin >= MARGIN, f"joint limit margin only {math.degrees(worst_margin):.1f} deg"
    assert worst_sin_q3 >= MIN_SIN_Q3, f"elbow nearly straight: |sin q3| = {worst_sin_q3:.3f}"
    assert worst_reach >= MIN_REACH, f"tool near the arm-plane origin: r = {worst_reach:.3f} m"


# --------------------------------------------------------------------------- bench

def test_bench_reports_the_agreed_keys_and_solves_every_cold_target() -> None:
    result = bench_ik(PARAMS, seed=1, cold_count=60)
    assert set(result) == {"ik_warm_median_us", "ik_warm_median_iterations", "ik_offset_median_us",
                           "ik_offset_median_iterations", "ik_cold_success_rate",
                           "ik_cold_median_iterations", "ik_cold_median_us", "ik_cold_targets"}
    assert result["ik_cold_targets"] == 60 and result["ik_cold_success_rate"] == 1.0
    assert result["ik_warm_median_iterations"] <= 2


def test_the_example_in_docs_kinematics_md_runs() -> None:
    doc = Path(__file__).resolve().parents[2] / "docs" / "kinematics.md"
    result = doctest.testfile(str(doc), module_relative=False)
    assert result.attempted >= 5 and result.failed == 0


def test_link_points_end_at_the_tool_and_keep_link_lengths():
    from ttt_sm.twin.kinematics import link_points

    g = load_params().geometry
    rng = np.random.default_rng(7)
    for _ in range(50):
        q = rng.uniform(-3, 3, size=4)
        pts = link_points(q, g)
        assert np.allclose(pts[2], fk(q, g)[:3])
        # the shoulder is on the base axis at height L1; the elbow is L2 from it
        assert np.linalg.norm(pts[0] - np.array([-g.l_f, 0.0, g.L1])) == pytest.approx(g.L2)
        assert np.linalg.norm(pts[1] - pts[0]) == pytest.approx(g.L3)
        assert np.linalg.norm(pts[2] - pts[1]) == pytest.approx(np.hypot(g.L4, g.l_f))
