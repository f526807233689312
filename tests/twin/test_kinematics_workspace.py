"""The reachable workspace (twin/kinematics/workspace.py) and the Lab exercises it answers (docs/kinematics.md)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ttt_sm.params import load_params
from ttt_sm.twin.kinematics import UnreachableTargetError, ik_closed_form
from ttt_sm.twin.kinematics.closed_form import solve_point
from ttt_sm.twin.kinematics.workspace import (
    BOTH,
    DOWN_ONLY,
    UNREACHABLE,
    UP_ONLY,
    classify,
    field_cells,
    solve_grid,
    with_lengths,
    workspace,
)

P = load_params()


def _limits(q2_max_deg: float | None = None, q3_max_deg: float | None = None) -> list[float]:
    hi = list(P.joint_max)
    if q2_max_deg is not None:
        hi[1] = math.radians(q2_max_deg)
    if q3_max_deg is not None:
        hi[2] = math.radians(q3_max_deg)
    return hi


def test_the_grid_solution_is_the_closed_form_point_by_point() -> None:
    rng = np.random.default_rng(3)
    pts = rng.uniform([-0.45, -0.45, -0.1], [0.45, 0.45, 0.4], size=(400, 3))
    g = P.geometry
    solved = 0
    for phi in (0.0, 0.7):
        for up in (True, False):
            q = solve_grid(pts[:, 0], pts[:, 1], pts[:, 2], phi, g, up)
            for p, qg in zip(pts, q, strict=True):
                try:
                    ref = ik_closed_form([*p, phi], g, elbow_up=up)
                except UnreachableTargetError:
                    assert np.isnan(qg).all()
                    continue
                solved += 1
                assert np.allclose(qg, ref, atol=1e-12)
    assert solved > 300  # the sample holds reachable and unreachable points both


def test_the_plain_float_closed_form_is_the_closed_form() -> None:
    rng = np.random.default_rng(5)
    g = P.geometry
    for p in rng.uniform([-0.45, -0.45, -0.1, -1.0], [0.45, 0.45, 0.4, 1.0], size=(300, 4)):
        for up in (True, False):
            got = solve_point(*p, g, up)
            try:
                ref = ik_closed_form(p, g, elbow_up=up)
            except UnreachableTargetError:
                assert got is None
                continue
            assert got is not None
            diff = np.array(got) - ref
            diff[0] = math.remainder(diff[0], 2 * math.pi)
            assert np.allclose(diff, 0.0, atol=1e-12)


def test_a_code_is_the_closed_form_within_the_limits() -> None:
    rng = np.random.default_rng(4)
    pts = rng.uniform([-0.45, -0.45], [0.45, 0.45], size=(300, 2))
    codes = classify(pts[:, 0], pts[:, 1], 0.0, P)
    lo, hi = np.array(P.joint_min), np.array(P.joint_max)
    for (x, y), code in zip(pts, codes, strict=True):
        want = 0
        for bit, up in ((UP_ONLY, True), (DOWN_ONLY, False)):
            try:
                q = ik_closed_form([x, y, 0.0, 0.0], P.geometry, elbow_up=up)
            except UnreachableTargetError:
                continue
            if np.all((q >= lo) & (q <= hi)):
                want |= bit
        assert code == want
    assert set(np.unique(codes)) >= {UNREACHABLE, UP_ONLY, BOTH}


def test_the_packaged_arm_draws_every_cell_elbow_up_with_the_pen_and_the_sponge() -> None:
    for tool in ("pen_vertical", "sponge"):
        w = workspace(P, tool, resolution=16)
        assert w.needs("elbow up") == [(i, j) for i in range(5) for j in range(5)]
    w = workspace(P, resolution=16)
    # the elbow-down branch bends q3 past its +30 deg stop over the whole field
    assert (w.top == DOWN_ONLY).sum() == 0


def test_exercise_a_the_cells_that_need_elbow_down() -> None:
    """docs/kinematics.md, Lab, exercise (a): q3 max 100 deg, q2 max 86 deg."""
    cells = field_cells(P, 5, q_max=_limits(86.0, 100.0))
    down = [(i, j) for i, row in enumerate(cells) for j, c in enumerate(row) if c == "elbow down"]
    assert down == [(i, j) for i in range(3) for j in range(5)] + [(3, 0), (3, 1), (3, 2)]
    assert cells[4] == ["elbow up"] * 5
    # with only one of the two stops moved, no cell needs elbow down
    assert all(c == "elbow up" for row in field_cells(P, 5, q_max=_limits(None, 100.0)) for c in row)


def test_exercise_b_the_shortest_upper_arm_for_a_6x6_field() -> None:
    """docs/kinematics.md, Lab, exercise (b): 6 x 6 cells of 3 cm need L2 >= 0.22 m (5 mm steps)."""
    def fits(l2: float) -> bool:
        return workspace(P, geometry=with_lengths(P.geometry, L2=l2), resolution=8, cells=6,
                         field_size=0.18).as_dict()["fits"]
    assert not fits(0.215) and fits(0.22)
    cells = field_cells(P, 6, 0.18, geometry=with_lengths(P.geometry, L2=0.215))
    assert [(i, j) for i, r in enumerate(cells) for j, c in enumerate(r) if c == "unreachable"] == [(5, 5)]


def test_an_unknown_tool_and_a_silly_resolution_are_refused() -> None:
    with pytest.raises(ValueError, match="tool must be one of"):
        classify(0.0, 0.25, 0.0, P, tool="brush")
    with pytest.raises(ValueError, match="resolution"):
        workspace(P, resolution=2)
