"""Issue 28 in a game: a person's move read through a camera that may be mirrored or turned is not a fact.

The game keeps the ways the camera's picture may have been changed that the robot's marks allow
(:class:`ttt_sm.app.game_orientation.OpenWays`); while more than the photo as it is remain, the person's
moves are unconfirmed and the robot plays only cells empty under every reading (docs/vision.md, "What a single
photo can tell").
"""

import json

import numpy as np
import pytest

from ttt_sm.app.game_orientation import OpenWays
from ttt_sm.app.game_outcome import GameError
from ttt_sm.cli import main
from ttt_sm.vision.orientation import AS_IS


def _square(cell):
    """The eight images of a board cell under the square's turns and mirrors."""
    r, c = cell
    out = set()
    for _ in range(4):
        r, c = c, 6 - r
        out |= {(r, c), (c, r)}
    return out


def _play(monkeypatch, tmp_path, camera, change=None):
    from ttt_sm.vision.simulated import SimulatedCamera

    if change is not None:
        frame = SimulatedCamera.frame
        monkeypatch.setattr(SimulatedCamera, "frame", lambda self: np.ascontiguousarray(change(frame(self))))
    code = main(["play", "--opponent", "simulated", "--camera", camera, "--seed", "2", "--json",
                 "--out", str(tmp_path)])
    events = [json.loads(line) for line in (tmp_path / "game.jsonl").read_text().splitlines()]
    return code, [e for e in events if e["event"] != "transition"]


def test_the_ways_a_direct_camera_leaves_open_are_narrowed_by_the_robot_s_marks():
    ways = OpenWays("direct", "far_edge")
    assert ways.ways == [AS_IS, "mirrored left-right"]  # its perspective tells every turn
    assert len(OpenWays("serial", "far_edge").ways) == 8  # no corners: nothing is told
    board = "....." "....." "..O.." "....." "X...."  # robot (3, 3), person (5, 1)
    pct = [30.0 if ch != "." else 0.0 for ch in board]
    assert ways.prune(pct, [(3, 3)]) == []  # a mark on the mirror's axis tells nothing
    readings = ways.readings(board, [(3, 3)], "O", "X")
    assert readings[AS_IS] == board and readings["mirrored left-right"][24] == "X"
    assert ways.robot_move(readings, lambda b, s: (5, 5), "O") != (5, 5)  # (5, 5) holds X read mirrored
    pct[13] = 30.0  # the robot drew (3, 4); the photo shows it there: the mirror would put it at (3, 2)
    assert ways.prune(pct, [(3, 3), (3, 4)]) == ["mirrored left-right"] and ways.open == []


def test_a_result_that_another_reading_would_not_declare_is_refused():
    ways = OpenWays("direct", "far_edge")
    # the person's four read in column 4; mirrored, its (2, 4) is the robot's (2, 2) and no four is left
    board = "..O.." ".O.X." "..OX." "...X." "..OX."
    readings = ways.readings(board, [(1, 3), (2, 2), (3, 3), (5, 3)], "O", "X")
    assert readings[AS_IS] == board and readings["mirrored left-right"] == "..O.." ".O.X." ".XO.." ".X..." ".XO.."
    with pytest.raises(GameError, match="result cannot be told.*mirrored left-right"):
        ways.result(readings)


def test_an_unmirrored_direct_camera_confirms_the_person_s_moves_at_the_robot_s_first_mark_off_its_axis(
        monkeypatch, tmp_path):
    code, events = _play(monkeypatch, tmp_path, "direct")
    assert code == 0 and events[-1]["event"] == "finished" and events[-1]["outcome"] in ("O", "draw")
    kinds = [e["event"] for e in events]
    robot = [i for i, e in enumerate(events) if e["event"] == "robot_move"]
    off_axis = next(i for i in robot if events[i]["column"] != 3)
    confirmed = kinds.index("moves_confirmed")
    assert robot[robot.index(off_axis) - 1] < off_axis < confirmed  # at the photo right after that mark ...
    assert "detected" not in kinds[off_axis:confirmed]
    event = events[confirmed]
    assert event["mark"] == [events[off_axis]["row"], events[off_axis]["column"]]
    assert event["ruled_out"] == ["mirrored left-right"]
    before = [e for e in events[:off_axis] if e["event"] == "detected"]
    assert event["moves"] == [[e["row"], e["column"]] for e in before] and before
    assert all(e["confirmed"] is False for e in before)
    after = [e for e in events[confirmed:] if e["event"] == "detected"]
    assert after and all("confirmed" not in e and e["correct"] for e in after)  # ... and the game goes on


@pytest.mark.parametrize("change", [np.rot90, lambda p: p[:, ::-1]], ids=["turned", "mirrored"])
def test_a_serial_camera_turned_or_mirrored_acts_on_no_move_read_and_is_refused_at_the_robot_s_telling_mark(
        monkeypatch, tmp_path, change):
    code, events = _play(monkeypatch, tmp_path, "serial", change)
    kinds = [e["event"] for e in events]
    assert code != 0 and kinds[-2:] == ["detection_rejected", "error"]
    assert "My marks appear where a turned or mirrored" in events[-1]["message"]
    detected = [e for e in events if e["event"] == "detected"]
    assert detected and all(e["confirmed"] is False and len(e["open"]) >= 1 for e in detected)
    drawn = {(e["row"], e["column"]) for e in events if e["event"] == "person_drew"}
    read = {(e["row"], e["column"]) for e in detected}
    assert drawn != read
    robot = [(e["row"], e["column"]) for e in events if e["event"] == "robot_move"]
    # every robot move is empty however the person's marks are read (any turn or mirror of them)
    assert not set(robot) & set().union(*(_square(c) for c in read))
    assert "moves_confirmed" not in kinds
    last_robot = len(kinds) - 1 - kinds[::-1].index("robot_move")
    assert "person_drew" not in kinds[last_robot:]  # refused at the photo right after it
