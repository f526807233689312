"""Where the Control chart draws: the field, its cells, the X and the O (thesis section 3.6.1).

Pure functions of plain numbers, so each can be checked against the thesis'
equations on its own (``tests/charts/test_geometry.py``) and the Control chart
(:mod:`ttt_sm.charts.control`) reads as a sequence of moves.  Coordinates are
metres in the global frame; ``x11, y11`` is the field's upper right corner
(fig. 3.26), ``L`` the side of a cell, rows and columns are 1-based and count
from that corner towards smaller y and x.

* :func:`field_line`: the 4 + 4 lines of the field (the moves of eq. 3.36).
* :func:`cell_corner`: a cell's upper right corner (eqs. 3.37-3.38, 3.45-3.46).
* :func:`x_start`, :func:`x_line_1`, :func:`x_line_2`, :func:`on_x_line_1`,
  :func:`on_x_line_2`: the X's two lines at 45 and 135 degrees (eqs. 3.37-3.44).
* :func:`o_centre`, :func:`o_radius`, :func:`arc_end`, :func:`circle_point`,
  :func:`circle_y`, :func:`circle_x`: the O drawn as four arcs, each a bit
  over a quarter so that the circle closes (eqs. 3.45-3.51).
* :func:`pass_x`, :func:`pass_ends`: the sponge's passes over the field (Erase).

Where the thesis prints a typo, the function follows the geometry and says so;
docs/thesis_map.md lists them.
"""

from __future__ import annotations

import math

#: Angle where the O's first arc starts: the lower right of the circle (rad).  Part 1 runs from there
#: along the lower half with X decreasing (eqs. 3.48-3.49): the O is drawn clockwise, seen from above.
O_START = -0.25 * math.pi


def field_line(x11: float, y11: float, L: float, cells: int, k: int) -> tuple[float, float, float, float]:
    """Start and end ``(x_a, y_a, x_b, y_b)`` of field line `k`, m.

    Lines 0 .. cells-2 run parallel to X, at ``y = y11 - (k + 1) L``; lines
    cells-1 .. 2 cells-3 parallel to Y, at ``x = x11 - (k - cells + 2) L``.
    Each spans the whole field (``cells L``), alternately one way and back,
    so that the pen travels little between them (section 3.6.1,
    Drawing_playing_field).
    """
    n = cells - 1
    size = cells * L
    x_lo, y_lo = x11 - size, y11 - size
    if k < n:
        y = y11 - (k + 1) * L
        xs = (x11, x_lo) if k % 2 == 0 else (x_lo, x11)
        return xs[0], y, xs[1], y
    x = x11 - (k - n + 1) * L
    ys = (y11, y_lo) if k % 2 == 0 else (y_lo, y11)
    return x, ys[0], x, ys[1]


def cell_corner(x11: float, y11: float, L: float, row: int, column: int) -> tuple[float, float]:
    """Upper right corner ``(x, y)`` of cell (`row`, `column`), m.

    ``x11 - (column - 1) L`` and ``y11 - (row - 1) L``: eqs. 3.37-3.38 without
    the X's margin, and eqs. 3.45-3.46 without the half cell.  The cell spans
    ``L`` from there towards smaller x and y.
    """
    return x11 - (column - 1) * L, y11 - (row - 1) * L


def x_start(x11: float, y11: float, L: float, row: int, column: int, size: float) -> tuple[float, float]:
    """Start ``(x_ini, y_ini)`` of the X's first line, m (eqs. 3.37-3.38).

    The cell's upper right corner moved in by the margin ``(L - size) / 2``
    on both axes, so that an X of side `size` sits in the middle of the cell.
    The thesis' margin ``L/5`` is the case ``size = 3L/5``.
    """
    margin = (L - size) / 2
    x, y = cell_corner(x11, y11, L, row, column)
    return x - margin, y - margin


def x_line_1(x_ini: float, y_ini: float) -> float:
    """``h1 = y_ini - x_ini`` (eq. 3.39): where the X's first line, ``Y = X + h1``, meets the Y axis."""
    return y_ini - x_ini


def on_x_line_1(x: float, h1: float) -> float:
    """The first line's y at `x`: ``Y = X + h1``, 45 degrees (eq. 3.41)."""
    return x + h1


def x_line_2(y_end: float, x_ini: float) -> float:
    """``h2 = Y_end + x_ini`` (eq. 3.42): the second line, ``Y = -X + h2``, starts at ``(x_ini, Y_end)``.

    `y_end` is the y where the first line ended.
    """
    return y_end + x_ini


def on_x_line_2(x: float, h2: float) -> float:
    """The second line's y at `x`: ``Y = -X + h2``, 135 degrees (eq. 3.44).

    The X decreases along it, as along the first line: the thesis' eq. 3.43
    prints ``X_out_p + inc``, which would leave the cell.
    """
    return -x + h2


def o_centre(x11: float, y11: float, L: float, row: int, column: int) -> tuple[float, float]:
    """Centre ``(x0, y0)`` of an O in cell (`row`, `column`), m: the cell's middle (eqs. 3.45-3.46)."""
    x, y = cell_corner(x11, y11, L, row, column)
    return x - L / 2, y - L / 2


def o_radius(size: float) -> float:
    """Radius of an O of diameter `size`, m (eq. 3.47).

    The thesis prints ``R = L/4``: an O half a cell across, the case
    ``size = L/2``.
    """
    return size / 2


def arc_end(k: int, overlap: float) -> float:
    """Angle (rad) where arc `k` (0-3) of the O ends, clockwise from :data:`O_START` (eqs. 3.48-3.51).

    Each arc is a quarter turn plus `overlap`, so the four together turn
    ``2 pi + 4 overlap``: the circle closes with its ends overlapping
    (section 3.6.1, Drawing_O, first reason).  Below ``pi / 16`` of overlap
    every arc stays on one half of the circle, where one equation gives it
    (:func:`circle_y`, :func:`circle_x`: the second reason).
    """
    return O_START - (k + 1) * (math.pi / 2 + overlap)


def circle_point(x0: float, y0: float, R: float, angle: float) -> tuple[float, float]:
    """The point ``(x0 + R cos a, y0 + R sin a)`` of the circle, m."""
    return x0 + R * math.cos(angle), y0 + R * math.sin(angle)


def circle_y(x: float, x0: float, y0: float, R: float, side: float) -> float:
    """The circle's y at `x`: ``y0 + side sqrt(R^2 - (x - x0)^2)``, m.

    `side` -1 is the lower half, eq. 3.49 (the circle's equation
    ``(X - x0)^2 + (Y - y0)^2 = R^2`` solved for Y); +1 the upper half, the
    same with the positive root.  Where round-off puts `x` a hair beyond the
    circle, the root is 0.
    """
    return y0 + side * math.sqrt(max(R ** 2 - (x - x0) ** 2, 0.0))


def circle_x(y: float, x0: float, y0: float, R: float, side: float) -> float:
    """The circle's x at `y`: ``x0 + side sqrt(R^2 - (y - y0)^2)``, m.

    `side` -1 is the left half, eq. 3.51; +1 the right half, the same with
    the positive root.
    """
    return x0 + side * math.sqrt(max(R ** 2 - (y - y0) ** 2, 0.0))


def pass_x(x11: float, L: float, cells: int, k: int) -> float:
    """x of the sponge's pass `k` (0 .. cells-1) over the field, m.

    The first pass runs over the middle of the first column, the last over
    the middle of the last; the others are spread evenly between them.
    """
    return x11 - L / 2 - k * (cells * L - L) / (cells - 1)


def pass_ends(y11: float, L: float, cells: int, k: int, beyond: float = 0.005) -> tuple[float, float]:
    """Start and end y of the sponge's pass `k`, m: the whole field and `beyond` past its edges.

    Passes run alternately one way and back, so the sponge travels little.
    """
    far, near = y11 + beyond, y11 - cells * L - beyond
    return (far, near) if k % 2 == 0 else (near, far)
