"""Whole games on the simulated robot: camera behind a real pseudo-terminal, charts, engine, erasing."""

import io
import json

import cv2
import numpy as np
import pytest

from ttt_sm.app.game import GameSession
from ttt_sm.app.game_outcome import result_of
from ttt_sm.app.person import SimulatedPerson, TerminalPerson
from ttt_sm.charts.game import MSG_DRAWING, MSG_ERASING, MSG_TURNING_OFF, MSG_YOUR_TURN
from ttt_sm.cli import main
from ttt_sm.params import load_params

P = load_params()


def test_result_of_reads_wins_draws_and_games_on():
    assert result_of("XXXX.OOO.................") == "X"
    assert result_of("O....O....O....O....XXX..") == "O"
    assert result_of("." * 25) is None
    assert result_of("XXOOX" "OOXXO" "XXOOX" "OOXXO" "XXOOX") == "draw"


def test_the_simulated_person_wins_when_it_can_and_blocks_when_it_must():
    p = SimulatedPerson(seed=0)
    assert p.choose("XXX.." "OO..." + "." * 15, "X") == (1, 4)  # wins
    assert p.choose("XXX.." "OO..." + "." * 15, "O") == (1, 4)  # blocks


@pytest.fixture(scope="module")
def serial_game(tmp_path_factory):
    """One whole game: simulated person (X) against the strong engine (O), camera on a pty."""
    out = tmp_path_factory.mktemp("game")
    session = GameSession(P, seed=4, robot_symbol="O", engine="strong", camera="serial")
    try:
        report = session.play()
        files = session.save(out)
    finally:
        session.close()
    return session, report, files


def test_a_whole_game_reads_every_move_right_through_the_serial_camera(serial_game):
    session, report, _ = serial_game
    person_moves = [m for m in report["moves"] if m["by"] == "person"]
    assert person_moves and report["detections_wrong"] == 0
    assert report["detections_correct"] == len(person_moves)
    assert all(m["detected"] == [m["row"], m["column"]] for m in person_moves)
    link = report["camera_link"]
    # one fresh frame at least per move (after each drawing, the person's and the robot's)
    assert link["frames_ok"] >= len(report["moves"]) and not link["rejected"]


def test_the_camera_link_photographs_once_per_reading_and_asks_again_for_a_lost_photo():
    from ttt_sm.app.camera_link import CameraLink
    from ttt_sm.smartcam import Fault
    from ttt_sm.twin.whiteboard import Whiteboard
    from ttt_sm.vision.scenes import draw_field

    board = Whiteboard(P, seed=2)
    draw_field(board)
    link = CameraLink(P, board, seed=2, mode="serial")
    try:
        first, _ = link.read()
        # the photo for the second or the third reading is garbled on the line
        link._emulator.inject(Fault.corrupt_checksum())
        link.read()
        board.draw_symbol("X", 2, 3)
        percentages, symbols = link.read()
        stats = link.stats()
        assert link._emulator.faults_pending == 0
    finally:
        link.close()
    # one photo per reading (none while the simulation had the board), one more for the lost one
    assert sum(stats["rejected"].values()) == 1 and stats["frames_ok"] == 3
    cell = 1 * 5 + 2  # row 2, column 3 in board order
    assert percentages[cell] > first[cell] + 5 and symbols is not None and symbols[cell] == "X"


def test_the_strong_engine_does_not_lose_and_the_board_is_erased(serial_game):
    session, report, _ = serial_game
    assert report["winner"] in ("robot", "draw")
    assert report["erased"] is True and session.robot.board.ink_area_mm2() == 0.0
    # the thesis' two rules (docs/thesis_map.md, section 3.6.1): a full board erases at once, a won game at its end
    assert report["erase_cause"] == ("full board" if len(report["moves"]) == 25 else "game over")
    assert "finished" in session.robot.active("Control")
    # the robot drew every move it announced, in the cells it chose, with its own symbol
    robot_cells = [(m["row"], m["column"]) for m in report["moves"] if m["by"] == "robot"]
    assert robot_cells == session.robot_cells


def test_the_game_chart_showed_the_thesis_messages_in_order(serial_game):
    session, _, _ = serial_game
    texts = [e["text"] for e in session.record.events if e["event"] == "message"]
    firsts = [texts.index(m) for m in (MSG_YOUR_TURN, MSG_DRAWING, MSG_ERASING, MSG_TURNING_OFF)]
    assert firsts == sorted(firsts)
    assert any(t in ("The manipulator wins.", "Draw: the board is full.") for t in texts)


def test_the_record_and_the_board_picture_are_written(serial_game):
    _, report, files = serial_game
    lines = [json.loads(line) for line in open(files["record"])]
    kinds = {e["event"] for e in lines}
    assert {"field_drawn", "person_drew", "detected", "robot_move", "result", "transition"} <= kinds
    robot_moves = [e for e in lines if e["event"] == "robot_move"]
    assert len(robot_moves) == sum(m["by"] == "robot" for m in report["moves"])
    assert cv2.imread(files["board_png"]) is not None


def test_a_person_at_the_terminal_is_asked_again_after_a_bad_cell():
    typed = io.StringIO("7 7\nnonsense\n3 3\n2 2\nq\n")
    shown = io.StringIO()
    person = TerminalPerson(stdin=typed, stdout=shown)
    session = GameSession(P, seed=2, robot_symbol="O", person=person, engine="thesis", camera="direct",
                          record_trace=False)
    try:
        report = session.play()
    finally:
        session.close()
    text = shown.getvalue()
    assert "cell (7, 7) is not a free cell of the 5x5 field" in text
    assert "not a cell: 'nonsense'" in text
    person_moves = [(m["row"], m["column"]) for m in report["moves"] if m["by"] == "person"]
    assert person_moves[:1] == [(3, 3)]
    assert report["winner"] == "robot" and report["outcome"] == "given_up" and report["erased"] is True
    assert MSG_YOUR_TURN in text


def test_play_json_reports_the_promised_keys(capsys, tmp_path):
    code = main(["play", "--opponent", "simulated", "--camera", "direct", "--seed", "5", "--json",
                 "--out", str(tmp_path)])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    for key in ("winner", "moves", "robot_symbol", "detections_correct", "detections_wrong", "sim_time_s",
                "wall_time_s", "realtime_factor", "erased"):
        assert key in data
    assert data["detections_wrong"] == 0 and data["erased"] is True


def test_the_game_bench_plays_whole_games_and_reports_their_pace():
    from ttt_sm.bench import bench_game

    result = bench_game(P, seed=11, games=1)
    assert result["game_games"] == 1 and result["game_winners"][0] in ("robot", "draw")
    assert result["game_detections_wrong"] == 0 and result["game_detections_correct"] >= 3
    assert result["game_erased"] is True
    sim, wall = result["game_sim_time_s"], result["game_wall_time_s"]
    # the factor is rounded to 0.1 and sim, wall to 1 ms: it equals sim / wall within what that rounding allows
    rounding = 0.05 + (sim / wall) * 0.0005 / wall + 1e-9
    assert sim > 60.0 and result["game_realtime_factor"] == pytest.approx(sim / wall, abs=rounding)
    # two numbers rounded to 0.1 each from slightly different sums: 0.1 apart at most, plus the floats' own error
    assert result["game_realtime_factor_min"] == pytest.approx(result["game_realtime_factor"], abs=0.1 + 1e-9)


def test_two_symbols_at_once_end_the_game_with_a_clear_error_and_the_record_kept(monkeypatch, capsys, tmp_path):
    from ttt_sm.twin.whiteboard import Whiteboard

    draw = Whiteboard.draw_symbol

    def two_at_once(self, kind, row, column, **kw):  # the person's hand draws a second symbol too
        draw(self, kind, row, column, **kw)
        draw(self, kind, *((1, 1) if (row, column) != (1, 1) else (5, 5)), **kw)

    monkeypatch.setattr(Whiteboard, "draw_symbol", two_at_once)
    code = main(["play", "--opponent", "simulated", "--camera", "direct", "--seed", "2", "--json",
                 "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code != 0
    assert "the camera's view was refused" in err and "2 new symbols" in err and "game.jsonl" in err
    events = [json.loads(line) for line in (tmp_path / "game.jsonl").read_text().splitlines()]
    kinds = [e["event"] for e in events]
    assert "field_drawn" in kinds and kinds.count("person_drew") == 1
    rejected = [e for e in events if e["event"] == "detection_rejected"]
    assert len(rejected) == 1 and "only one per turn" in rejected[0]["message"]
    assert (tmp_path / "board_final.png").stat().st_size > 0


def test_the_camera_link_is_silent_between_readings_without_a_silence_warning(caplog):
    """The person thinks for longer than the watchdog's limit: the camera was not asked, no warning."""
    import logging
    import time

    from ttt_sm.app.camera_link import CameraLink
    from ttt_sm.twin.whiteboard import Whiteboard
    from ttt_sm.vision.scenes import draw_field

    caplog.set_level(logging.WARNING, logger="ttt_sm.smartcam")
    board = Whiteboard(P, seed=2)
    draw_field(board)
    # the limit must exceed one reading (a photo and its detection: ~0.1 s, more on a loaded machine)
    link = CameraLink(P, board, seed=2, mode="serial", silence_s=1.0)
    try:
        link.read()
        time.sleep(2.5)  # the person at the terminal, typing; the camera is idle by design
        board.draw_symbol("X", 2, 3)
        link.read()
        stats = link.stats()
    finally:
        link.close()
    assert stats["silences"] == 0 and stats["frames_ok"] == 2
    assert not [r.getMessage() for r in caplog.records if "no valid frame" in r.getMessage()]


@pytest.mark.parametrize(("turn", "reason"), [
    (lambda photo: np.ascontiguousarray(np.rot90(photo)), "turn it 90 deg"),  # the camera turned on its stand
    (lambda photo: np.ascontiguousarray(photo[::-1, ::-1]), "turn it 180 deg"),
])
def test_a_turned_camera_is_refused_by_its_perspective_and_never_read_as_a_board(monkeypatch, capsys, tmp_path, turn,
                                                                                  reason):
    """Issue 28 (no silent wrong board) in a game: the direct camera's photos are checked as ttt-sm vision's are."""
    from ttt_sm.vision.simulated import SimulatedCamera

    frame = SimulatedCamera.frame
    monkeypatch.setattr(SimulatedCamera, "frame", lambda self: turn(frame(self)))
    code = main(["play", "--opponent", "simulated", "--camera", "direct", "--seed", "2", "--json",
                 "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code != 0
    assert "the camera's view was refused" in err and reason in err, err[-600:]
    events = [json.loads(line) for line in (tmp_path / "game.jsonl").read_text().splitlines()]
    assert not [e for e in events if e["event"] == "detected"]  # nothing was read from a turned photo
    assert len([e for e in events if e["event"] == "detection_rejected"]) == 1


def test_a_mirrored_camera_is_refused_right_after_the_robot_draws_off_the_mirrors_axis(monkeypatch, capsys,
                                                                                       tmp_path):
    """A left-right mirror keeps the perspective of a camera on the field's axis; the robot's own marks tell it.

    The game photographs the board after each robot move: a mark off column 3 (the mirror's axis) seen in the
    mirrored cell ends the game naming the mirror.  The person's moves read before it cannot be checked by any
    photo (docs/vision.md, "What a single photo can tell"): none is taken as a fact (each is recorded unconfirmed,
    the mirror still open) and every robot move is a cell empty read either way."""
    from ttt_sm.vision.simulated import SimulatedCamera

    frame = SimulatedCamera.frame
    monkeypatch.setattr(SimulatedCamera, "frame", lambda self: np.ascontiguousarray(frame(self)[:, ::-1]))
    code = main(["play", "--opponent", "simulated", "--camera", "direct", "--seed", "2", "--json",
                 "--out", str(tmp_path)])
    err = capsys.readouterr().err
    assert code != 0 and "the camera's view was refused: My marks appear where a turned or mirrored" in err, err[-600:]
    events = [json.loads(line) for line in (tmp_path / "game.jsonl").read_text().splitlines()]
    kinds = [e["event"] for e in events]
    robot_cells = [(e["row"], e["column"]) for e in events if e["event"] == "robot_move"]
    # refused at the photo right after the robot's first move off the axis: no move of the person after it
    assert kinds[-2:] == ["detection_rejected", "error"]
    last_robot = len(kinds) - 1 - kinds[::-1].index("robot_move")
    assert "person_drew" not in kinds[last_robot:]
    assert robot_cells[-1][1] != 3 and all(c == 3 for _, c in robot_cells[:-1])
    detected = [e for e in events if e["event"] == "detected"]
    assert detected and all(e["confirmed"] is False and e["open"] == ["mirrored left-right"] for e in detected)
    drawn = {(e["row"], e["column"]) for e in events if e["event"] == "person_drew"}
    read = {(e["row"], e["column"]) for e in detected}
    assert drawn != read  # the person's moves were read mirrored ...
    assert not set(robot_cells) & (drawn | read)  # ... and the robot played only cells empty under both readings
    assert "moves_confirmed" not in kinds
