"""No silent wrong board: photos turned, mirrored and transposed all eight ways are read right or refused.

Real photos through OpenCV: the simulated camera photographs each board, OpenCV turns and mirrors the
picture, and :func:`establish_orientation` (what ``ttt-sm vision detect`` runs) reads it or refuses it;
docs/vision.md, "What a single photo can tell".
"""

from __future__ import annotations

import cv2
import pytest

from ttt_sm.vision import OrientationError, detect, establish_orientation
from ttt_sm.vision.bench import orientation_probe
from ttt_sm.vision.scenes import scene_from_text
from ttt_sm.vision.simulated import SimulatedCamera


def test_four_boards_all_eight_ways_in_two_views_give_no_wrong_board(params):
    result = orientation_probe(boards=4, seed=1, params=params)
    assert result["wrong"] == [] and result["silent_wrong"] == 0
    assert result["grid_failures"] == 0 and result["readings"] == 4 * 2 * 8 * 2
    assert result["upright_with_marks_read"] >= 2  # not a reader that refuses everything


@pytest.mark.soak
def test_fifty_boards_all_eight_ways_give_no_wrong_board(params):
    result = orientation_probe(boards=50, seed=0, params=params)
    assert result["wrong"] == [] and result["silent_wrong"] == 0
    assert result["grid_failures"] == 0


@pytest.fixture(scope="module")
def centre_photo(params):
    """The robot's O in the centre only (symmetric under every mirror), the person's X at (2, 1)."""
    scene = scene_from_text(params, "....." "X...." "..O.." "....." ".....", "O", seed=4)
    return SimulatedCamera(scene.board, params, seed=4).frame()


CENTRE = "." * 12 + "O" + "." * 12


def test_a_mirrored_photo_with_symmetric_marks_is_refused_not_read(centre_photo):
    det = detect(cv2.flip(centre_photo, 1))
    with pytest.raises(OrientationError, match="cannot tell whether the photo is mirrored left-right"):
        establish_orientation(det.grid, det.cells, "far_edge", CENTRE, "m.png")
    with pytest.raises(OrientationError, match="no robot marks were given"):
        establish_orientation(det.grid, det.cells, "far_edge", None, "m.png")
    # the upright photo is as ambiguous: one photo cannot tell it from its mirror
    det = detect(centre_photo)
    with pytest.raises(OrientationError, match="cannot tell whether the photo is mirrored left-right"):
        establish_orientation(det.grid, det.cells, "far_edge", CENTRE, "p.png")


def test_a_board_that_reads_the_same_either_way_is_read(params):
    scene = scene_from_text(params, "." * 12 + "X" + "." * 12, "X", seed=5)
    det = detect(cv2.flip(SimulatedCamera(scene.board, params, seed=5).frame(), 1))
    note = establish_orientation(det.grid, det.cells, "far_edge", None, "p.png")
    assert "mirrored left-right, it would read the same board" in note


def test_a_turned_photo_in_view_field_with_diagonal_marks_is_refused(params):
    # the case: rot90 --view field with the robot's marks on the diagonal read the transposed board
    board = "X...." ".X..O" "..X.." "...X." "O...X"
    scene = scene_from_text(params, board, "X", seed=6)
    field = cv2.flip(SimulatedCamera(scene.board, params, seed=6).frame(), 0)
    det = detect(cv2.rotate(field, cv2.ROTATE_90_CLOCKWISE))
    marks = "".join(ch if ch == "X" else "." for ch in board)
    with pytest.raises(OrientationError, match="the robot's marks show the photo"):
        establish_orientation(det.grid, det.cells, "field", marks, "t.png")
    det = detect(cv2.transpose(field))
    with pytest.raises(OrientationError, match="cannot tell whether the photo is"):
        establish_orientation(det.grid, det.cells, "field", marks, "t.png")
