"""The board picture for people: cropped to the field, cells labelled as the thesis numbers them, to scale."""

from __future__ import annotations

import numpy as np
import pytest

from ttt_sm.params import load_params
from ttt_sm.twin.board_picture import (
    FIELD_MARGIN_M,
    PX_PER_MM,
    SCALE_BAR_MM,
    board_figure,
    crop_region,
    save_board_picture,
)
from ttt_sm.twin.whiteboard import Whiteboard

P = load_params()
FIELD = P.board.field_bounds()


@pytest.fixture()
def board() -> Whiteboard:
    b = Whiteboard(P, seed=3)
    b.draw_symbol("O", 2, 4, jitter_mm=0.0)
    return b


def _on_pixel_grid(v: float, origin: float, res: float) -> bool:
    k = (v - origin) / res
    return abs(k - round(k)) < 1e-6


def test_the_crop_is_the_field_with_its_margin_on_whole_pixels(board):
    x0, x1, y0, y1 = crop = crop_region(board)
    fx0, fx1, fy0, fy1 = FIELD
    eps = 1e-12
    assert x0 <= fx0 - FIELD_MARGIN_M + eps and x1 >= fx1 + FIELD_MARGIN_M - eps
    assert y0 <= fy0 - FIELD_MARGIN_M + eps and y1 >= fy1 + FIELD_MARGIN_M - eps
    res = board.resolution_m
    assert x1 - x0 < P.board.field_size + 2 * FIELD_MARGIN_M + 2 * res  # no more than the margin
    bx0, bx1, by0, by1 = board.extent
    assert all(_on_pixel_grid(v, o, res) for v, o in zip(crop, (bx0, bx0, by0, by0), strict=True))


def test_ink_beyond_the_field_widens_the_crop_but_never_past_the_board(board):
    fx0, fx1, fy0, fy1 = FIELD
    board.draw_stroke([(fx1 + 0.03, fy0 - 0.02), (fx1 + 0.05, fy0 - 0.03)], jitter_mm=0.0)
    x0, x1, y0, y1 = crop_region(board)
    assert x1 >= fx1 + 0.05 and y0 <= fy0 - 0.03  # the stray stroke is in the picture
    board.draw_stroke([(board.extent[1] - 0.001, fy1), (board.extent[1] - 0.001, fy1 + 0.01)], jitter_mm=0.0)
    assert crop_region(board)[1] <= board.extent[1] + 1e-12


def test_the_picture_is_the_board_seen_from_above_in_millimetres_with_a_scale_bar(board):
    fig = board_figure(board, "an O in (2, 4)")
    (ax,) = fig.axes
    (image,) = ax.images
    x0, x1, y0, y1 = crop_region(board)
    assert image.get_extent() == pytest.approx([x0 * 1e3, x1 * 1e3, y0 * 1e3, y1 * 1e3])
    rows, cols = image.get_array().shape[:2]
    assert cols == round((x1 - x0) * 1e3 * PX_PER_MM) and rows == round((y1 - y0) * 1e3 * PX_PER_MM)
    # the scale bar is SCALE_BAR_MM of the board, and as many picture pixels as the image gives them
    (bar,) = [ln for ln in ax.lines if ln.get_gid() == "scale_bar"]
    xs = bar.get_xdata()
    assert xs[1] - xs[0] == pytest.approx(SCALE_BAR_MM)
    fig.canvas.draw()
    px = ax.transData.transform([[xs[0], 0.0], [xs[1], 0.0]])
    img_px = ax.transData.transform([[x0 * 1e3, 0.0], [x1 * 1e3, 0.0]])
    assert (px[1, 0] - px[0, 0]) / (img_px[1, 0] - img_px[0, 0]) == pytest.approx(SCALE_BAR_MM / ((x1 - x0) * 1e3))
    assert px[1, 0] - px[0, 0] == pytest.approx(SCALE_BAR_MM * PX_PER_MM, rel=0.02)
    assert any(t.get_text() == f"{SCALE_BAR_MM:g} mm" for t in ax.texts)


def test_every_cell_is_labelled_row_column_inside_itself_and_1_1_is_at_the_top_right(board):
    fig = board_figure(board, "cells")
    (ax,) = fig.axes
    labels = {t.get_gid(): t for t in ax.texts if (t.get_gid() or "").startswith("cell_")}
    assert len(labels) == 25
    for row in range(1, 6):
        for column in range(1, 6):
            t = labels[f"cell_{row}_{column}"]
            assert t.get_text() == f"({row}, {column})"
            x, y = t.get_position()
            cx0, cx1, cy0, cy1 = (v * 1e3 for v in board.cell_bounds(row, column))
            assert cx0 < x < cx1 and cy0 < y < cy1
    fig.canvas.draw()

    def shown(row: int, column: int) -> np.ndarray:
        return ax.transData.transform([labels[f"cell_{row}_{column}"].get_position()])[0]

    # thesis fig. 3.26: (1, 1) at the upper right corner, rows downwards, columns right to left
    assert shown(1, 1)[0] > shown(1, 5)[0] and shown(1, 1)[1] > shown(5, 1)[1]
    # the field's 4 + 4 lines, at the cell edges
    _, fx1, _, fy1 = (v * 1e3 for v in FIELD)
    L = P.board.cell_size * 1e3
    along_x = sorted(ln.get_ydata()[0] for ln in ax.lines
                     if len(ln.get_ydata()) == 2 and ln.get_ydata()[0] == ln.get_ydata()[1]
                     and ln.get_gid() != "scale_bar")
    along_y = sorted(ln.get_xdata()[0] for ln in ax.lines
                     if len(ln.get_xdata()) == 2 and ln.get_xdata()[0] == ln.get_xdata()[1])
    assert along_x == pytest.approx([fy1 - k * L for k in (4, 3, 2, 1)])
    assert along_y == pytest.approx([fx1 - k * L for k in (4, 3, 2, 1)])


def test_the_ink_lies_where_it_was_drawn_and_nowhere_else(board):
    fig = board_figure(board, "O")
    (ax,) = fig.axes
    (image,) = ax.images
    rgba = image.get_array()
    x0, x1, y0, y1 = image.get_extent()  # mm
    rows, cols = rgba.shape[:2]

    def alpha_at(x_mm: float, y_mm: float) -> float:
        col = int((x_mm - x0) / (x1 - x0) * cols)
        row = int((y1 - y_mm) / (y1 - y0) * rows)  # row 0 is the top: the largest y
        return float(rgba[row, col, 3])

    (o,) = board.strokes
    on = [alpha_at(x * 1e3, y * 1e3) for x, y in o.points[::25]]
    assert min(on) > 0.8  # opaque ink on the O
    cx0, cx1, cy0, cy1 = board.cell_bounds(2, 4)
    assert alpha_at((cx0 + cx1) / 2 * 1e3, (cy0 + cy1) / 2 * 1e3) == 0.0  # the O's middle is clean board
    assert alpha_at(*(v * 1e3 for v in board.cell_bounds(4, 2)[::2])) == 0.0
    # and as much of it as the board holds
    share = board.ink_area_mm2(crop_region(board)) / ((x1 - x0) * (y1 - y0))
    assert float(np.mean(rgba[:, :, 3] > 0.5)) == pytest.approx(share, rel=0.25)


def test_the_picture_is_written_as_a_small_png(board, tmp_path):
    path = save_board_picture(board, tmp_path / "sub" / "board.png", "an O", "seed 3")
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) < 150_000
