"""The simulated whiteboard: pen ink, holder drag, sponge wipes, hand symbols, pictures.

Joint angles come from the closed-form inverse kinematics (the test oracle),
so every path here is exactly what forward kinematics of those angles says.
"""

from __future__ import annotations

import math
import re
import time
from pathlib import Path

import cv2
import numpy as np
import pytest

from ttt_sm.files import RecordWriteError
from ttt_sm.params import load_params
from ttt_sm.twin._ink import ink_polyline
from ttt_sm.twin.kinematics import fk, ik_closed_form
from ttt_sm.twin.whiteboard import (
    CELL_MARGIN_M,
    INK_WIDTH_M,
    Whiteboard,
    WhiteboardError,
)

PARAMS = load_params()
GEOM = PARAMS.true_geometry  # the whiteboard sees the true pen: the arm as built
BOARD = PARAMS.board
DT = 1.0 / 500.0  # chart step
RES = 0.2e-3
Y_LINE = 0.25  # a pixel boundary of the 0.2 mm raster: the line's width is symmetric


def q_at(x: float, y: float, z: float, phi: float = 0.0) -> np.ndarray:
    return ik_closed_form([x, y, z, phi], GEOM)


def run_path(board: Whiteboard, points: np.ndarray, t0: float = 0.0, phi: float = 0.0) -> float:
    """Feed the board the joint angles of a sequence of (x, y, z) tool points, one per chart step."""
    t = t0
    for x, y, z in points:
        board.update(t, q_at(x, y, z, phi))
        t += DT
    return t


def line_path(a: tuple[float, float], b: tuple[float, float], speed: float, z_draw: float = -0.001,
              z_up: float = 0.004, lower_steps: int = 20) -> np.ndarray:
    """Lower the pen at a, draw to b at `speed` (m/s), lift it at b."""
    n = max(2, int(round(math.dist(a, b) / (speed * DT))) + 1)
    xs, ys = np.linspace(a[0], b[0], n), np.linspace(a[1], b[1], n)
    down = [(a[0], a[1], z) for z in np.linspace(z_up, z_draw, lower_steps)]
    draw = [(x, y, z_draw) for x, y in zip(xs, ys, strict=True)]
    up = [(b[0], b[1], z) for z in np.linspace(z_draw, z_up, lower_steps)]
    return np.array(down + draw + up)


def column_of(board: Whiteboard, x: float) -> int:
    return int((x - board.extent[0]) / RES)


def row_of(board: Whiteboard, y: float) -> int:
    return int((y - board.extent[2]) / RES)


@pytest.fixture(scope="module")
def drawn_line() -> Whiteboard:
    board = Whiteboard(PARAMS)
    run_path(board, line_path((-0.05, Y_LINE), (0.05, Y_LINE), speed=0.02))
    return board


# --------------------------------------------------------------------------- pen

def test_a_straight_line_is_one_stroke_of_the_marker_width_on_its_centreline(drawn_line):
    board = drawn_line
    (stroke,) = board.strokes
    assert stroke.author == "robot"
    assert np.allclose(stroke.points[:, 1], Y_LINE, atol=1e-9)
    assert stroke.points[0, 0] == pytest.approx(-0.05, abs=1e-9)
    # the tip lags L_s behind the holder, so the line ends that much short
    assert stroke.points[-1, 0] == pytest.approx(0.05 - board.tip_deviation_m, abs=2e-5)
    assert np.all(np.diff(stroke.times) > 0)
    mask = board.ink_mask()
    cols = mask[:, column_of(board, -0.045):column_of(board, 0.045)]
    widths = cols.sum(axis=0) * RES
    assert np.all(np.abs(widths - INK_WIDTH_M) <= RES)
    rows = np.nonzero(cols.any(axis=1))[0]
    centre = board.extent[2] + (rows.mean() + 0.5) * RES
    assert centre == pytest.approx(Y_LINE, abs=0.05e-3)
    assert board.ink_area_mm2() == pytest.approx(100.0 * 0.8, rel=0.03)
    assert not board.contact.pen_touching


def test_a_lifted_pen_inks_nothing():
    board = Whiteboard(PARAMS)
    run_path(board, line_path((-0.05, Y_LINE), (0.05, Y_LINE), speed=0.05, z_draw=0.0005))
    assert board.strokes == ()
    assert not board.ink_mask().any()
    assert board.contact.max_drag_m == 0.0


def test_the_spring_takes_the_compression_and_the_holder_overpresses_beyond_its_travel():
    board = Whiteboard(PARAMS)
    travel = PARAMS.pen.spring_travel
    board.update(0.0, q_at(0.0, Y_LINE, -0.003))
    c = board.contact
    assert c.pen_touching and not c.pen_overpress
    assert c.compression_m == pytest.approx(0.003, abs=1e-9)
    assert c.tip_m == pytest.approx((0.0, Y_LINE), abs=1e-9)  # the real tip rests on the surface
    board.update(DT, q_at(0.0, Y_LINE, -(travel + 0.001)))
    board.update(2 * DT, q_at(0.001, Y_LINE, -(travel + 0.002)))
    c = board.contact
    assert c.pen_overpress and c.pen_overpress_count == 1  # one event, not one per step
    board.update(3 * DT, q_at(0.002, Y_LINE, -0.002))
    assert not board.contact.pen_overpress
    board.update(4 * DT, q_at(0.003, Y_LINE, -(travel + 0.001)))
    assert board.contact.pen_overpress_count == 2
    (running,) = board.strokes  # the stroke being drawn is listed too
    assert running.points[-1, 0] > 0.002
    board.update(5 * DT, q_at(0.003, Y_LINE, 0.002))
    (stroke,) = board.strokes  # the overpressed pen still inked
    assert stroke.points[-1, 0] > 0.002


def test_a_tilted_pen_slides_back_along_its_axis():
    board = Whiteboard(PARAMS)
    phi, depth = math.radians(15.0), 0.003
    q = q_at(0.02, Y_LINE, -depth, phi)
    board.update(0.0, q)
    q1 = q[0]
    comp = depth / math.cos(phi)
    axis = np.array([-math.sin(q1) * math.sin(phi), math.cos(q1) * math.sin(phi)])  # tool axis, xy part
    expected = np.array([0.02, Y_LINE]) - comp * axis
    c = board.contact
    assert c.compression_m == pytest.approx(comp, rel=1e-9)
    assert np.allclose(c.tip_m, expected, atol=1e-12)
    assert math.dist(c.tip_m, (0.02, Y_LINE)) == pytest.approx(depth * math.tan(phi), rel=1e-9)


def test_the_holder_clearance_drags_the_tip_at_most_Ls_behind_the_motion():
    board = Whiteboard(PARAMS)
    ls = board.tip_deviation_m
    assert ls == pytest.approx(0.35e-3, rel=1e-9)  # eq. 3.13 for the 0.4 mm clearance
    path = line_path((-0.02, Y_LINE), (0.02, Y_LINE), speed=0.03)
    drags = []
    for k, (x, y, z) in enumerate(path):
        board.update(k * DT, q_at(x, y, z))
        c = board.contact
        if c.pen_touching:
            nominal = fk(q_at(x, y, z), GEOM)[:2]
            drags.append(nominal - np.array(c.tip_m))
    drags_arr = np.array(drags)
    size = np.hypot(drags_arr[:, 0], drags_arr[:, 1])
    assert size.max() <= ls + 1e-12
    assert size.max() == pytest.approx(ls, rel=1e-6)
    moving = size > 0.9 * ls
    assert np.all(drags_arr[moving, 0] > 0)  # motion along +x: the tip lags on the -x side
    assert np.allclose(drags_arr[moving, 1], 0.0, atol=1e-12)
    assert board.contact.max_drag_m == pytest.approx(ls, rel=1e-6)


def test_on_a_reversal_the_tip_stays_put_until_the_holder_has_crossed_the_clearance():
    board = Whiteboard(PARAMS)
    ls = board.tip_deviation_m
    xs = list(np.arange(0.0, 0.004, 1e-4)) + list(np.arange(0.004, -0.002, -1e-4))
    tips = []
    for k, x in enumerate(xs):
        board.update(k * DT, q_at(x, Y_LINE, -0.001))
        tips.append(board.contact.tip_m[0])
    turn = len(np.arange(0.0, 0.004, 1e-4))
    # after the turn the tip holds still for 2 L_s of holder travel, then follows L_s behind
    assert tips[turn + 6] == pytest.approx(tips[turn], abs=1e-12)  # x = 0.004 is the turn
    assert tips[-1] == pytest.approx(xs[-1] + ls, abs=1e-12)


def test_no_gaps_at_50_mm_per_second():
    board = Whiteboard(PARAMS)
    run_path(board, line_path((-0.07, 0.21), (0.07, 0.29), speed=0.05))
    mask = board.ink_mask().astype(np.uint8)
    n, _ = cv2.connectedComponents(mask, connectivity=4)
    assert n == 2  # background + one line
    strip = board.ink_mask()[:, column_of(board, -0.069):column_of(board, 0.069)]
    assert strip.any(axis=0).all()
    (stroke,) = board.strokes
    assert np.hypot(*np.diff(stroke.points, axis=0).T).max() <= RES + 1e-12


def test_the_pen_inks_only_on_the_board():
    board = Whiteboard(PARAMS)
    x_edge = board.extent[1]
    run_path(board, line_path((x_edge - 0.01, Y_LINE), (x_edge + 0.01, Y_LINE), speed=0.05))
    (stroke,) = board.strokes
    assert stroke.points[:, 0].max() <= x_edge
    assert not board.contact.pen_touching


def test_a_tip_coming_from_beneath_or_beside_the_board_collides_and_does_not_write():
    board = Whiteboard(PARAMS)
    zone = BOARD.zone_depth
    y_edge = board.extent[2]
    # hanging below the plane beside the board, then under it below its stand: free space
    run_path(board, [(0.0, y_edge - 0.02, -0.1), (0.0, y_edge + 0.05, -0.1), (0.0, 0.25, -(zone + 0.01))])
    assert board.contact.pen_collision_count == 0
    # rising through the stand and the board from beneath
    run_path(board, [(0.0, 0.25, z) for z in np.linspace(-zone + 0.002, -0.001, 10)])
    c = board.contact
    assert c.pen_colliding and not c.pen_touching and c.pen_collision_count == 1
    run_path(board, [(0.0, 0.25, 0.005)])  # out above the surface ...
    assert not board.contact.pen_colliding
    run_path(board, [(0.0, 0.25, -0.001), (0.01, 0.25, -0.001)])  # ... and down onto it: writing
    assert board.contact.pen_touching
    run_path(board, [(0.01, 0.25, 0.005), (0.0, y_edge - 0.01, 0.005), (0.0, y_edge - 0.01, -0.01),
                     (0.0, y_edge + 0.01, -0.01)])  # into the board's edge from the side
    assert board.contact.pen_collision_count == 2
    (stroke,) = board.strokes
    assert stroke.points[:, 0].min() >= -1e-9 and stroke.points[:, 0].max() <= 0.01


# --------------------------------------------------------------------------- sponge

def sponge_q(x: float, y: float, press: float) -> np.ndarray:
    """Tool pose at phi = 90 deg whose sponge face is `press` below the surface at (x, y)."""
    return q_at(x, y, PARAMS.sponge.offset - press, math.pi / 2)


def under_pads(points: np.ndarray, centres: np.ndarray, q1s: np.ndarray, half: float) -> np.ndarray:
    """Which points lie under a square pad of half-side `half` at any of the centres (edges turned by q1)."""
    hit = np.zeros(len(points), bool)
    for (cx, cy), q1 in zip(centres, q1s, strict=True):
        dx, dy = points[:, 0] - cx, points[:, 1] - cy
        u = dx * math.cos(q1) + dy * math.sin(q1)
        v = -dx * math.sin(q1) + dy * math.cos(q1)
        hit |= (np.abs(u) <= half) & (np.abs(v) <= half)
    return hit


@pytest.mark.parametrize("x_pass", [0.0, -0.06])  # pad square to the axes (q1 = 0), and turned
def test_at_phi_90_the_sponge_wipes_what_its_pad_sweeps_and_nothing_else(x_pass):
    board = Whiteboard(PARAMS)
    for y in (0.20, 0.23, 0.26, 0.29):  # crossed by the pass
        board.draw_stroke([(-0.1, y), (0.1, y)], jitter_mm=0.0, author="robot", width_mm=0.8)
    board.draw_stroke([(x_pass + 0.04, 0.17), (x_pass + 0.04, 0.32)], jitter_mm=0.0)  # beside it
    before = board.ink_mask().copy()
    ys_pass = np.arange(0.19, 0.30, 0.05 * DT)  # a pass along Y at 50 mm/s
    qs = [sponge_q(x_pass, y, 0.002) for y in ys_pass]
    board.update(0.0, qs[0])  # pressed onto the board
    assert board.contact.sponge_touching and not board.contact.pen_touching
    for k, q in enumerate(qs[1:]):
        board.update((k + 1) * DT, q)
    board.update(10.0, q_at(x_pass, ys_pass[-1], 0.03, math.pi / 2))
    assert not board.contact.sponge_touching

    half = PARAMS.sponge.width / 2
    centres = np.column_stack((np.full(len(ys_pass), x_pass), ys_pass))
    q1s = np.array([q[0] for q in qs])
    ys, xs = np.nonzero(before)
    pixels = board.pixel_centers_m(before)
    inside = under_pads(pixels, centres[::5], q1s[::5], half - RES)
    outside = ~under_pads(pixels, centres, q1s, half + RES)
    assert inside.sum() > 1000 and outside.sum() > 1000
    after = board.ink_mask()
    assert not after[ys[inside], xs[inside]].any()
    assert after[ys[outside], xs[outside]].all()
    assert not (after & ~before).any()
    assert board.wiped_pixels == np.count_nonzero(before & ~after)

    strokes = board.strokes
    assert len(strokes) == 4 * 2 + 1  # each crossed line split in two, the side line whole
    for s in strokes:
        assert not under_pads(s.points, centres[::5], q1s[::5], half - RES).any()
    # strokes and raster agree: every stroke point sits on ink, all ink lies along a stroke
    ix = ((np.concatenate([s.points[:, 0] for s in strokes]) - board.extent[0]) / RES).astype(int)
    iy = ((np.concatenate([s.points[:, 1] for s in strokes]) - board.extent[2]) / RES).astype(int)
    assert after[iy, ix].all()
    band = np.zeros(board.shape, np.uint8)
    for s in strokes:
        ink_polyline(band, board.extent[0], board.extent[2], RES, s.points[:, 0].copy(),
                     s.points[:, 1].copy(), s.width_m / 2 + RES, 1)
    assert not (after & (band == 0)).any()


def test_the_sponge_pad_turns_with_the_base_azimuth():
    board = Whiteboard(PARAMS)
    xc, yc = 0.06, 0.22
    board.draw_stroke([(0.0, yc), (0.12, yc)], jitter_mm=0.0, author="robot", width_mm=0.8)
    q = sponge_q(xc, yc, 0.001)
    board.update(0.0, q)
    board.update(DT, q_at(xc, yc, 0.03, math.pi / 2))
    q1 = q[0]
    assert abs(math.degrees(q1)) > 10.0  # a real turn of the pad
    (left, right) = sorted(board.strokes, key=lambda s: s.points[0, 0])
    gap = right.points[:, 0].min() - left.points[:, 0].max()
    assert gap == pytest.approx(PARAMS.sponge.width / math.cos(q1), abs=2 * RES)


def test_the_sponge_gives_within_its_compliance_and_overpresses_beyond():
    board = Whiteboard(PARAMS)
    comp = PARAMS.sponge.compliance
    board.update(0.0, sponge_q(0.0, 0.25, 0.5 * comp))
    c = board.contact
    assert c.sponge_touching and not c.sponge_overpress
    assert c.sponge_press_m == pytest.approx(0.5 * comp, abs=1e-9)
    board.update(DT, sponge_q(0.0, 0.25, 1.5 * comp))
    board.update(2 * DT, sponge_q(0.0, 0.251, 1.6 * comp))
    assert board.contact.sponge_overpress and board.contact.sponge_overpress_count == 1
    board.update(3 * DT, q_at(0.0, 0.25, 0.03, math.pi / 2))
    assert not board.contact.sponge_touching


def test_the_sponge_does_not_touch_while_the_pen_draws():
    board = Whiteboard(PARAMS)
    board.update(0.0, q_at(0.0, 0.25, -0.005))
    assert board.contact.pen_touching and not board.contact.sponge_touching


# --------------------------------------------------------------------------- hand

@pytest.mark.parametrize("kind,row,column", [("X", 1, 1), ("O", 2, 4), ("X", 5, 3), ("O", 3, 5)])
def test_hand_drawn_symbols_land_in_their_cell(kind, row, column):
    board = Whiteboard(PARAMS, seed=row * 10 + column)
    strokes = board.draw_symbol(kind, row, column)
    assert len(strokes) == (2 if kind == "X" else 1)
    assert all(s.author == "hand" for s in strokes)
    L = BOARD.cell_size
    x11, y11 = BOARD.field_bounds()[1], BOARD.field_bounds()[3]
    x_lo, x_hi = x11 - column * L, x11 - (column - 1) * L  # eqs. 3.37-3.38
    y_lo, y_hi = y11 - row * L, y11 - (row - 1) * L
    assert board.cell_bounds(row, column) == pytest.approx((x_lo, x_hi, y_lo, y_hi))
    ink = board.pixel_centers_m(board.ink_mask())
    assert np.all((ink[:, 0] > x_lo + CELL_MARGIN_M) & (ink[:, 0] < x_hi - CELL_MARGIN_M))
    assert np.all((ink[:, 1] > y_lo + CELL_MARGIN_M) & (ink[:, 1] < y_hi - CELL_MARGIN_M))
    for r in range(1, 6):
        for c in range(1, 6):
            share = board.cell_ink_fraction(r, c)
            assert (share > 0.04) if (r, c) == (row, column) else (share == 0.0)


def test_hand_strokes_are_jittered_reproducibly_from_the_seed():
    a, b, c = Whiteboard(PARAMS, seed=1), Whiteboard(PARAMS, seed=1), Whiteboard(PARAMS, seed=2)
    sa, sb, sc = (w.draw_symbol("O", 3, 3)[0] for w in (a, b, c))
    assert np.array_equal(sa.points, sb.points)
    assert not np.array_equal(sa.points, sc.points)
    exact = Whiteboard(PARAMS).draw_stroke([(0.0, 0.2), (0.03, 0.2)], jitter_mm=0.0)
    wobbly = Whiteboard(PARAMS).draw_stroke([(0.0, 0.2), (0.03, 0.2)])
    assert np.allclose(exact.points[:, 1], 0.2)
    dev = np.abs(wobbly.points[:, 1] - 0.2)
    assert 0.05e-3 < dev.max() <= 0.4e-3 + 1e-12


def test_cell_ink_fraction_is_the_inked_share_of_the_cell_inside_its_margin():
    board = Whiteboard(PARAMS)
    x_lo, x_hi, y_lo, y_hi = board.cell_bounds(3, 3)
    # the grid lines around the cell lie in the margin: they do not count
    for x in (x_lo, x_hi):
        board.draw_stroke([(x, y_lo), (x, y_hi)], jitter_mm=0.0, author="robot", width_mm=0.8)
    assert board.cell_ink_fraction(3, 3) == 0.0
    y = (y_lo + y_hi) / 2  # a pixel boundary: exactly 4 rows of 0.2 mm lie within 0.4 mm
    board.draw_stroke([(x_lo, y), (x_hi, y)], jitter_mm=0.0, width_mm=0.8)
    inner = (x_hi - x_lo) - 2 * CELL_MARGIN_M
    assert board.cell_ink_fraction(3, 3) == pytest.approx(0.8e-3 / inner, rel=0.02)
    assert board.cell_ink_fraction(3, 3, margin_m=0.0) > board.cell_ink_fraction(3, 3)
    with pytest.raises(WhiteboardError, match="row must be an integer 1..5"):
        board.cell_ink_fraction(0, 3)
    with pytest.raises(WhiteboardError, match="column"):
        board.cell_bounds(2, 6)


# --------------------------------------------------------------------------- pictures

def dark_box(image: np.ndarray) -> tuple[int, int, int, int]:
    rows, cols = np.nonzero(image.min(axis=2) < 128)
    return rows.min(), rows.max(), cols.min(), cols.max()


@pytest.mark.parametrize("view,corner", [("field", "top-left"), ("above", "top-right"),
                                         ("far_edge", "bottom-left")])
def test_render_puts_cell_1_1_where_each_view_says(view, corner):
    board = Whiteboard(PARAMS)
    board.draw_symbol("X", 1, 1, jitter_mm=0.0)
    image = board.render(px_per_mm=2, region=BOARD.field_bounds(), view=view)
    assert image.shape == (300, 300, 3) and image.dtype == np.uint8
    r0, r1, c0, c1 = dark_box(image)
    top, left = corner.startswith("top"), corner.endswith("left")
    assert (r1 < 60) if top else (r0 >= 240)
    assert (c1 < 60) if left else (c0 >= 240)


def test_field_view_reads_like_the_board_as_text():
    board = Whiteboard(PARAMS)
    board.draw_symbol("O", 1, 5, jitter_mm=0.0)  # top row, right column
    board.draw_symbol("X", 4, 2, jitter_mm=0.0)  # fourth row, second column
    image = board.render(px_per_mm=1, region=BOARD.field_bounds())
    cells = image.reshape(5, 30, 5, 30, 3).min(axis=(1, 3, 4)) < 128
    expected = np.zeros((5, 5), bool)
    expected[0, 4] = expected[3, 1] = True
    assert np.array_equal(cells, expected)


def test_render_draws_ink_in_its_colours_and_millimetre_paper_under_it():
    board = Whiteboard(PARAMS)
    plain = board.render(px_per_mm=4)
    assert plain.shape == (960, 1200, 3) and (plain == 255).all()
    paper = board.render(px_per_mm=4, grid_mm=True, region=(0.0, 0.02, 0.24, 0.26), view="above")
    assert paper.shape == (80, 80, 3)
    row = paper[41, :, :].min(axis=1)  # one image row, between horizontal lines
    lines = np.nonzero(row < 255)[0]
    assert np.array_equal(lines, np.arange(0, 80, 4))  # a line every millimetre
    assert paper[41, 0].tolist() != paper[41, 4].tolist()  # 10 mm lines darker than 1 mm ones
    board.draw_stroke([(0.005, 0.25), (0.015, 0.25)], jitter_mm=0.0, author="robot", width_mm=0.8)
    inked = board.render(px_per_mm=4, grid_mm=True, region=(0.0, 0.02, 0.24, 0.26), view="above")
    b, g, r = inked[39, 40].tolist()
    assert b > r + 40 and max(b, g, r) < 160  # dark blue robot ink


def test_render_overlays_the_desired_path_in_red():
    board = Whiteboard(PARAMS)
    image = board.render(px_per_mm=4, region=(0.0, 0.02, 0.24, 0.26), view="above",
                         desired=[[(0.002, 0.25), (0.018, 0.25)]])
    b, g, r = image[39:41, 40].astype(int).min(axis=0)
    assert r > 150 and b < 150


def test_save_png_round_trips_through_cv2(tmp_path):
    board = Whiteboard(PARAMS)
    board.draw_symbol("O", 2, 2)
    path = board.save_png(tmp_path / "board.png", px_per_mm=2, grid_mm=True)
    back = cv2.imread(str(path))
    assert np.array_equal(back, board.render(px_per_mm=2, grid_mm=True))
    # a folder that is not there: the error names the picture (not the temporary file it was written to first)
    with pytest.raises(RecordWriteError, match="No such file or directory") as refused:
        board.save_png(tmp_path / "missing" / "board.png")
    assert refused.value.filename == str(tmp_path / "missing" / "board.png")


# --------------------------------------------------------------------------- tails

def test_longest_tail_finds_a_3_mm_tail_and_nothing_on_a_clean_line():
    desired = [[(-0.03, Y_LINE), (0.03, Y_LINE)]]
    clean = Whiteboard(PARAMS)
    clean.draw_stroke(desired[0], jitter_mm=0.0, author="robot", width_mm=0.8)
    assert clean.longest_tail_mm(desired, tol_m=0.5e-3) == 0.0
    assert not clean.ink_outside(desired, 0.5e-3).any()

    tailed = Whiteboard(PARAMS)
    # a pen-lift tail: the line goes on 3 mm past its end, then a 1 mm hook sideways
    tailed.draw_stroke([(-0.03, Y_LINE), (0.033, Y_LINE)], jitter_mm=0.0, author="robot", width_mm=0.8)
    tailed.draw_stroke([(0.0, Y_LINE), (0.0, Y_LINE + 1.2e-3)], jitter_mm=0.0, width_mm=0.8)
    tail = tailed.longest_tail_mm(desired, tol_m=0.5e-3)
    assert 3.0 - 0.5 - 0.2 <= tail <= 3.0 + 0.4 + 0.2  # beyond the band, up to the end of the ink
    outside = tailed.pixel_centers_m(tailed.ink_outside(desired, 0.5e-3))
    assert outside[:, 0].max() == pytest.approx(0.0334, abs=0.2e-3)


def test_the_robot_lines_drag_tail_is_within_the_default_band(drawn_line):
    assert drawn_line.longest_tail_mm([[(-0.05, Y_LINE), (0.05, Y_LINE)]]) == 0.0


# --------------------------------------------------------------------------- housekeeping

def test_reset_cleans_the_board_and_the_counters():
    board = Whiteboard(PARAMS, seed=3)
    first = board.draw_symbol("X", 1, 1)
    board.update(0.0, q_at(0.0, 0.25, -0.01))
    board.reset()
    assert board.strokes == () and not board.ink_mask().any()
    c = board.contact
    assert not c.pen_touching and c.pen_overpress_count == 0 and c.max_drag_m == 0.0
    again = board.draw_symbol("X", 1, 1)
    assert np.array_equal(first[0].points, again[0].points)


def test_bad_arguments_are_named():
    board = Whiteboard(PARAMS)
    with pytest.raises(WhiteboardError, match="resolution_mm"):
        Whiteboard(PARAMS, resolution_mm=0.0)
    with pytest.raises(WhiteboardError, match="on the board"):
        board.draw_stroke([(0.0, 0.0), (0.01, 0.0)])
    with pytest.raises(WhiteboardError, match="kind"):
        board.draw_symbol("Z", 1, 1)
    with pytest.raises(WhiteboardError, match="view"):
        board.render(view="side")
    with pytest.raises(WhiteboardError, match="does not overlap"):
        board.ink_area_mm2((1.0, 2.0, 1.0, 2.0))
    with pytest.raises(WhiteboardError, match="finite"):
        board.update(0.0, [0.0, float("nan"), 0.0, 0.0])


def test_update_is_cheap():
    board = Whiteboard(PARAMS)
    lifted = q_at(0.0, 0.25, 0.02)
    inking = [q_at(x, 0.25, -0.001) for x in np.linspace(-0.05, 0.05, 2000)]
    board.update(0.0, inking[0])  # compile outside the timing
    n = 2000
    start = time.perf_counter()
    for k in range(n):
        board.update(k * DT, lifted)
    lifted_us = (time.perf_counter() - start) / n * 1e6
    start = time.perf_counter()
    for k, q in enumerate(inking):
        board.update(k * DT, q)
    inking_us = (time.perf_counter() - start) / n * 1e6
    # generous bounds (measured ~1 and ~2 us): 500 updates must fit far inside 1/50 s
    assert lifted_us < 20.0
    assert inking_us < 40.0


def test_docs_example_runs_and_prints_what_the_docs_say(tmp_path, monkeypatch, capsys):
    doc = Path(__file__).resolve().parents[2] / "docs" / "whiteboard.md"
    text = doc.read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert blocks
    monkeypatch.chdir(tmp_path)  # the example writes board.png
    namespace: dict = {"__name__": "whiteboard_docs"}
    for i, block in enumerate(blocks):
        exec(compile(block, f"{doc.name}[block {i}]", "exec"), namespace)  # noqa: S102
    printed = capsys.readouterr().out
    assert printed.strip() in text
    assert cv2.imread(str(tmp_path / "board.png")) is not None
