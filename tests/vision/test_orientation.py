"""Image cells to board cells: the table of docs/vision.md, checked on photos."""

from __future__ import annotations

import pytest

from ttt_sm.vision import VisionError, board_cell, board_text, board_values, detect, image_cell, image_text
from ttt_sm.vision.scenes import scene_from_text
from ttt_sm.vision.simulated import SimulatedCamera

BOARD = "".join("ABCDEFGHIJKLMNOPQRSTUVWXY")  # board order: A is (1, 1), E is (1, 5), U is (5, 1)


@pytest.mark.parametrize("view, top_left, top_right, bottom_left", [
    ("far_edge", (5, 1), (5, 5), (1, 1)),
    ("above", (1, 5), (1, 1), (5, 5)),
    ("field", (1, 1), (1, 5), (5, 1)),
])
def test_the_image_corners_show_these_board_cells(view, top_left, top_right, bottom_left):
    assert board_cell(1, 1, view) == top_left
    assert board_cell(1, 5, view) == top_right
    assert board_cell(5, 1, view) == bottom_left


@pytest.mark.parametrize("view", ["far_edge", "above", "field"])
def test_mappings_are_their_own_inverse(view):
    for r in range(1, 6):
        for c in range(1, 6):
            assert image_cell(*board_cell(r, c, view), view) == (r, c)
    assert board_text(image_text(BOARD, view), view) == BOARD
    assert board_values(tuple(range(25)), view) == tuple(float(ord(ch) - 65) for ch in board_text(BOARD, view))


def test_far_edge_text_is_the_board_upside_down():
    assert board_text(BOARD, "far_edge") == "UVWXY" "PQRST" "KLMNO" "FGHIJ" "ABCDE"


def test_bad_views_and_cells_are_refused():
    with pytest.raises(VisionError, match="view must be one of"):
        board_cell(1, 1, "below")
    with pytest.raises(VisionError, match="off the 5x5"):
        board_cell(0, 3)
    with pytest.raises(VisionError, match="25"):
        board_text("X..")


def test_a_photo_from_beyond_the_far_edge_maps_back_to_the_board(params):
    # the example of docs/whiteboard.md: an O in (1, 5) and an X in (4, 2)
    text = ["."] * 25
    text[0 * 5 + 4] = "O"
    text[3 * 5 + 1] = "X"
    scene = scene_from_text(params, "".join(text), "X", seed=2)
    cam = SimulatedCamera(scene.board, params, seed=2)
    det = detect(cam.frame())
    assert cam.view() == "far_edge"
    assert det.cell(5, 5) == "O"  # board (1, 5): bottom right of the image
    assert det.cell(2, 2) == "X"  # board (4, 2)
    assert board_text(det.cells, cam.view()) == scene.text
