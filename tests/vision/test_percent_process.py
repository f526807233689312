"""Percent-process (thesis 3.6.3): the person's moves, and the moves that are not legal."""

from __future__ import annotations

import pytest

from ttt_sm.vision import (
    MoveError,
    RobotCellMarkedError,
    SymbolVanishedError,
    TooManyMovesError,
    VisionError,
    board_text,
    detect,
    percent_process,
    read_moves,
    robot_ink_after_move,
)
from ttt_sm.vision.scenes import draw_robot_symbol, scene_from_text
from ttt_sm.vision.simulated import SimulatedCamera

EMPTY = [0.0] * 25


def pct(**cells: float) -> list[float]:
    """25 percentages with the given cells set, e.g. pct(c11=20.0, c34=9.0)."""
    out = list(EMPTY)
    for name, value in cells.items():
        r, c = int(name[1]), int(name[2])
        out[(r - 1) * 5 + c - 1] = value
    return out


def test_the_persons_new_symbol_is_the_occupied_cell_that_is_nobodys_yet():
    moves = percent_process(pct(c33=9.0, c21=18.0), robot_cells=[(3, 3)])
    assert moves.new == (2, 1) and moves.cells == ((2, 1),)
    later = percent_process(pct(c33=9.0, c21=18.0, c11=8.5, c45=17.0), [(3, 3), (1, 1)], moves.cells)
    assert later.new == (4, 5) and later.cells == ((2, 1), (4, 5))


def test_no_new_symbol_is_no_move():
    moves = percent_process(pct(c33=9.0, c21=18.0), [(3, 3)], [(2, 1)])
    assert moves.new is None and moves.cells == ((2, 1),)
    assert percent_process(EMPTY, []).new is None


def test_two_new_symbols_at_once_are_reported():
    with pytest.raises(TooManyMovesError) as err:
        percent_process(pct(c33=9.0, c21=18.0, c55=20.0), [(3, 3)])
    assert err.value.cells == ((2, 1), (5, 5))
    assert "one per turn" in err.value.message_for_person
    assert "2 new symbols" in str(err.value)


def test_a_symbol_drawn_over_the_robots_is_reported_by_its_ink():
    with pytest.raises(RobotCellMarkedError) as err:
        percent_process(pct(c33=27.0), [(3, 3)], robot_ink={(3, 3): 9.0})
    assert err.value.cells == ((3, 3),)
    assert "already mine" in err.value.message_for_person
    # a little noise on the robot's symbol is not a mark
    assert percent_process(pct(c33=10.5), [(3, 3)], robot_ink={(3, 3): 9.0}).new is None


def test_a_symbol_drawn_over_the_robots_is_reported_by_its_shape():
    symbols = "." * 12 + "O" + "." * 12
    with pytest.raises(RobotCellMarkedError):
        percent_process(pct(c33=20.0), [(3, 3)], symbols=symbols, robot_symbol="X")
    same = "." * 12 + "X" + "." * 12
    assert percent_process(pct(c33=20.0), [(3, 3)], symbols=same, robot_symbol="X").new is None


def test_a_symbol_that_disappears_is_reported():
    with pytest.raises(SymbolVanishedError) as err:
        percent_process(pct(c33=9.0), [(3, 3)], [(2, 1)])  # the person's O in (2, 1) is gone
    assert err.value.cells == ((2, 1),)
    with pytest.raises(SymbolVanishedError):
        percent_process(pct(c21=18.0), [(3, 3)], [(2, 1)])  # the robot's X is gone
    assert issubclass(SymbolVanishedError, MoveError) and issubclass(MoveError, ValueError)


def test_inconsistent_inputs_are_refused():
    with pytest.raises(VisionError, match="25 percentages"):
        percent_process([1.0] * 24, [])
    with pytest.raises(VisionError, match="both the robot's and the person's"):
        percent_process(EMPTY, [(1, 1)], [(1, 1)])
    with pytest.raises(VisionError, match="off the 5x5"):
        percent_process(EMPTY, [(6, 1)])


def test_a_game_seen_through_the_camera(params):
    """The robot plays X, the person O; each photo is read and the person's move extracted."""
    scene = scene_from_text(params, "." * 25, seed=8)
    board = scene.board
    cam = SimulatedCamera(board, params, seed=8)
    view = cam.view()
    robot, person, ink = [], (), {}
    for robot_move, person_move in (((3, 3), (2, 2)), ((1, 5), (4, 1)), ((5, 5), (2, 4))):
        draw_robot_symbol(board, "X", *robot_move)
        robot.append(robot_move)
        det = detect(cam.frame())
        ink[robot_move] = robot_ink_after_move(det, robot_move, view)
        assert read_moves(det, robot, person, view=view, robot_ink=ink, robot_symbol="X").new is None
        board.draw_symbol("O", *person_move)
        moves = read_moves(detect(cam.frame()), robot, person, view=view, robot_ink=ink, robot_symbol="X")
        assert moves.new == person_move
        person = moves.cells
    # the person cheats: an O over the robot's X in (3, 3)
    board.draw_symbol("O", 3, 3)
    with pytest.raises(RobotCellMarkedError) as err:
        read_moves(detect(cam.frame()), robot, person, view=view, robot_ink=ink, robot_symbol="X")
    assert err.value.cells == ((3, 3),)
    # two symbols at once
    board2 = scene_from_text(params, "." * 25, seed=9).board
    draw_robot_symbol(board2, "X", 3, 3)
    board2.draw_symbol("O", 1, 1)
    board2.draw_symbol("O", 5, 2)
    cam2 = SimulatedCamera(board2, params, seed=9)
    det2 = detect(cam2.frame())
    assert board_text(det2.cells, view).count("O") == 2
    with pytest.raises(TooManyMovesError):
        read_moves(det2, [(3, 3)], view=view)
