"""The field, cell, X and O geometry of thesis section 3.6.1 (eqs. 3.37-3.51), on its own.

Values are worked out by hand from the equations for the default field:
upper right corner ``x11, y11 = 0.075, 0.325`` m, cells ``L = 0.03`` m, 5 x 5.
"""

from __future__ import annotations

import math

import pytest

from ttt_sm.charts.geometry import (
    O_START,
    arc_end,
    cell_corner,
    circle_point,
    circle_x,
    circle_y,
    field_line,
    o_centre,
    o_radius,
    on_x_line_1,
    on_x_line_2,
    pass_ends,
    pass_x,
    x_line_1,
    x_line_2,
    x_start,
)

X11, Y11, L, CELLS = 0.075, 0.325, 0.03, 5
approx = pytest.approx


# ------------------------------------------------------------------------ cells


@pytest.mark.parametrize("row, column, corner", [
    (1, 1, (0.075, 0.325)),   # the field's upper right corner itself
    (1, 5, (-0.045, 0.325)),
    (5, 1, (0.075, 0.205)),
    (5, 5, (-0.045, 0.205)),
    (2, 3, (0.015, 0.295)),
    (4, 2, (0.045, 0.235)),
])
def test_a_cells_upper_right_corner_is_x11_y11_less_whole_cells(row, column, corner):
    assert cell_corner(X11, Y11, L, row, column) == approx(corner, abs=1e-12)


def test_the_25_cells_tile_the_field_without_gap_or_overlap():
    corners = {(r, c): cell_corner(X11, Y11, L, r, c) for r in range(1, 6) for c in range(1, 6)}
    for (r, c), (x, y) in corners.items():
        # eqs. 3.37-3.38 without the margin: one cell side per column and per row
        assert x == approx(X11 - (c - 1) * 0.03, abs=1e-12) and y == approx(Y11 - (r - 1) * 0.03, abs=1e-12)
        if c < 5:  # the neighbour in the next column starts where this cell ends
            assert corners[r, c + 1][0] == approx(x - L, abs=1e-12) and corners[r, c + 1][1] == y
        if r < 5:
            assert corners[r + 1, c][1] == approx(y - L, abs=1e-12) and corners[r + 1, c][0] == x
    xs = sorted({round(x, 9) for x, _ in corners.values()})
    ys = sorted({round(y, 9) for _, y in corners.values()})
    # the cells' lower left corners reach the field's lower left corner, x11 - 5L, y11 - 5L
    assert xs[0] - L == approx(X11 - 0.15) and ys[0] - L == approx(Y11 - 0.15)
    assert len(xs) == len(ys) == 5


# ------------------------------------------------------------------------ the X


def test_the_thesis_x_starts_l_over_5_inside_the_cell_corner():
    # eqs. 3.37-3.38: x_ini = x11 - (column - 1) L - L/5, for the X of side 3L/5
    x_ini, y_ini = x_start(X11, Y11, L, 2, 3, size=3 * L / 5)
    assert (x_ini, y_ini) == approx((0.015 - 0.006, 0.295 - 0.006), abs=1e-12)
    h1 = x_line_1(x_ini, y_ini)  # eq. 3.39
    assert h1 == approx(0.289 - 0.009, abs=1e-12)
    # line 1 (eqs. 3.40-3.41) from (0.009, 0.289) down to x = 0.009 - 0.018, at 45 degrees
    x_end = x_ini - 3 * L / 5
    y_end = on_x_line_1(x_end, h1)
    assert (x_end, y_end) == approx((-0.009, 0.271), abs=1e-12)
    assert on_x_line_1(x_ini, h1) == approx(y_ini, abs=1e-12)
    # line 2 (eqs. 3.42-3.44) starts at (x_ini, Y_end) and ends at (x_end, y_ini): 135 degrees
    h2 = x_line_2(y_end, x_ini)
    assert h2 == approx(0.271 + 0.009, abs=1e-12)
    assert on_x_line_2(x_ini, h2) == approx(y_end, abs=1e-12)
    assert on_x_line_2(x_end, h2) == approx(y_ini, abs=1e-12)
    # both lines cross at the cell's centre, (0.015 - L/2, 0.295 - L/2)
    assert on_x_line_1(0.0, h1) == approx(0.28, abs=1e-12) and on_x_line_2(0.0, h2) == approx(0.28, abs=1e-12)


@pytest.mark.parametrize("row, column", [(r, c) for r in range(1, 6) for c in range(1, 6)])
def test_an_x_as_large_as_its_cell_draws_the_cells_diagonals_through_its_four_corners(row, column):
    x_hi, y_hi = cell_corner(X11, Y11, L, row, column)
    x_lo, y_lo = x_hi - L, y_hi - L
    x_ini, y_ini = x_start(X11, Y11, L, row, column, size=L)
    assert (x_ini, y_ini) == (x_hi, y_hi)  # no margin: the upper right corner
    h1 = x_line_1(x_ini, y_ini)
    y_end = on_x_line_1(x_lo, h1)
    assert y_end == approx(y_lo, abs=1e-12)  # line 1 ends at the lower left corner
    h2 = x_line_2(y_end, x_ini)
    assert on_x_line_2(x_hi, h2) == approx(y_lo, abs=1e-12)  # line 2 from the lower right corner
    assert on_x_line_2(x_lo, h2) == approx(y_hi, abs=1e-12)  # to the upper left corner


@pytest.mark.parametrize("size", [0.006, 0.018, 0.024])
def test_an_x_of_any_size_is_centred_in_its_cell(size):
    x_ini, y_ini = x_start(X11, Y11, L, 4, 2, size)
    margin = (L - size) / 2
    assert (x_ini, y_ini) == approx((0.045 - margin, 0.235 - margin), abs=1e-12)
    h1 = x_line_1(x_ini, y_ini)
    h2 = x_line_2(on_x_line_1(x_ini - size, h1), x_ini)
    # the lines cross at the centre of cell (4, 2): (0.045 - 0.015, 0.235 - 0.015)
    assert on_x_line_1(0.03, h1) == approx(0.22, abs=1e-12) and on_x_line_2(0.03, h2) == approx(0.22, abs=1e-12)


# ------------------------------------------------------------------------ the O


def test_the_o_is_centred_in_its_cell_with_the_thesis_radius_a_quarter_cell():
    assert o_centre(X11, Y11, L, 2, 3) == approx((0.0, 0.28), abs=1e-12)  # eqs. 3.45-3.46
    assert o_centre(X11, Y11, L, 1, 1) == approx((0.06, 0.31), abs=1e-12)
    assert o_centre(X11, Y11, L, 5, 5) == approx((-0.06, 0.19), abs=1e-12)
    assert o_radius(L / 2) == approx(L / 4)  # eq. 3.47's R = L/4: an O half a cell across
    assert o_radius(0.018) == approx(0.009)


def test_the_circle_equations_give_the_four_halves():
    x0, y0, R = 0.0, 0.28, 0.009
    # a 3-4-5 triangle: (0.0054, 0.0072) from the centre lies on the circle of radius 0.009
    assert circle_y(0.0054, x0, y0, R, -1.0) == approx(0.28 - 0.0072, abs=1e-12)  # eq. 3.49, lower half
    assert circle_y(0.0054, x0, y0, R, 1.0) == approx(0.28 + 0.0072, abs=1e-12)
    assert circle_x(0.28 + 0.0072, x0, y0, R, -1.0) == approx(-0.0054, abs=1e-12)  # eq. 3.51, left half
    assert circle_x(0.28 - 0.0072, x0, y0, R, 1.0) == approx(0.0054, abs=1e-12)
    assert circle_y(0.0, x0, y0, R, -1.0) == approx(0.271) and circle_x(0.28, x0, y0, R, 1.0) == approx(0.009)
    # a hair beyond the circle (round-off at an arc's end) gives the circle's extreme, not NaN
    assert circle_y(R * (1 + 1e-12), x0, y0, R, 1.0) == y0
    assert circle_x(y0 - R * (1 + 1e-12), x0, y0, R, -1.0) == x0


@pytest.mark.parametrize("overlap", [0.0, 0.035, 0.15])
def test_the_o_is_four_arcs_each_a_bit_over_a_quarter_that_close_the_circle(overlap):
    starts = [O_START] + [arc_end(k, overlap) for k in range(3)]
    ends = [arc_end(k, overlap) for k in range(4)]
    assert O_START == approx(math.radians(-45.0))  # the lower right: eq. 3.48 decreases X from there
    for a, b in zip(starts, ends, strict=True):
        assert a - b == approx(math.pi / 2 + overlap)  # a quarter, and the overlap, clockwise (eqs. 3.48-3.51)
    # together they turn 2 pi and four overlaps: the last arc runs past the first one's start
    assert O_START - ends[-1] == approx(2 * math.pi + 4 * overlap)
    x0, y0, R = 0.0, 0.28, 0.009
    # each arc's ends lie on the half of the circle whose single equation the chart follows
    # (section 3.6.1's second reason for four parts): lower (y, eq. 3.49), left (x, eq. 3.51), upper (y),
    # right (x): the signs of the roots the thesis gives each part
    halves = [("y", -1.0), ("x", -1.0), ("y", 1.0), ("x", 1.0)]
    for a, b, (axis, side) in zip(starts, ends, halves, strict=True):
        for angle in (a, b):
            px, py = circle_point(x0, y0, R, angle)
            assert math.hypot(px - x0, py - y0) == approx(R)
            if axis == "y":
                assert circle_y(px, x0, y0, R, side) == approx(py, abs=1e-12)
            else:
                assert circle_x(py, x0, y0, R, side) == approx(px, abs=1e-12)


def test_arc_ends_by_hand_for_two_degrees_of_overlap():
    ov = math.radians(2.0)
    assert [math.degrees(arc_end(k, ov)) for k in range(4)] == approx([-137.0, -229.0, -321.0, -413.0])
    assert circle_point(0.0, 0.28, 0.009, math.radians(-90.0)) == approx((0.0, 0.271), abs=1e-12)


# ------------------------------------------------------------------ field lines and sponge passes


def test_the_field_is_4_lines_along_x_and_4_along_y_spanning_it_back_and_forth():
    lines = [field_line(X11, Y11, L, CELLS, k) for k in range(8)]
    assert lines[0] == approx((0.075, 0.295, -0.075, 0.295))  # first line along X, one cell below y11
    assert lines[1] == approx((-0.075, 0.265, 0.075, 0.265))  # and back
    assert lines[3] == approx((-0.075, 0.205, 0.075, 0.205))
    assert lines[4] == approx((0.045, 0.325, 0.045, 0.175))  # first line along Y, one cell left of x11
    assert lines[7] == approx((-0.045, 0.175, -0.045, 0.325))
    for xa, ya, xb, yb in lines:
        assert math.hypot(xb - xa, yb - ya) == approx(0.15)  # 15 cm, as the thesis says


def test_sponge_passes_run_over_the_middle_of_the_first_and_last_columns_and_beyond_the_field():
    assert [pass_x(X11, L, CELLS, k) for k in range(5)] == approx([0.06, 0.03, 0.0, -0.03, -0.06])
    assert pass_ends(Y11, L, CELLS, 0) == approx((0.33, 0.17))
    assert pass_ends(Y11, L, CELLS, 1) == approx((0.17, 0.33))
