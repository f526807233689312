"""``ttt-sm vision``: detect, render, bench through a parser like ttt-sm's (register(subparsers))."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import cv2
import pytest

from ttt_sm.cli.vision import register


def run(argv: list[str]) -> int:
    p = argparse.ArgumentParser(prog="ttt-sm")
    p.add_argument("--params", default=None)
    register(p.add_subparsers(dest="command", required=True))
    args = p.parse_args(argv)
    return int(args.func(args))


def test_render_then_detect_as_json(tmp_path: Path, capsys):
    photo = tmp_path / "photo.png"
    board = "X...O" ".O..." "..X.." "....." "O...X"
    assert run(["vision", "render", str(photo), "--board", board, "--robot", "X", "--seed", "3",
                "--shadow", "--dim", "0.3", "--json"]) == 0
    rendered = json.loads(capsys.readouterr().out)
    assert rendered["board"] == board and rendered["view"] == "far_edge" and rendered["dim"] == 0.3
    assert cv2.imread(str(photo)).shape == (480, 640, 3)
    overlay = tmp_path / "overlay.png"
    assert run(["vision", "detect", str(photo), "--overlay", str(overlay),
                "--robot-marks", "X..../...../..X../...../....X", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["board"] == board
    assert len(data["cells"]) == 25 and len(data["percentages"]) == 25 and len(data["corners_px"]) == 4
    assert data["rows"][4] == "X...O"  # far_edge: board row 1 at the bottom of the image
    assert cv2.imread(str(overlay)).shape == (480, 640, 3)


def test_a_board_may_be_written_in_rows_as_the_other_commands_take_it(tmp_path: Path, capsys):
    # `camera serve --board` and `ai move --board` take rows split by '/' (or spaces, '|'): so does vision
    photo = tmp_path / "photo.png"
    assert run(["vision", "render", str(photo), "--board", "X...O/.O.../..X../...../O...X", "--seed", "3",
                "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["board"] == "X...O.O.....X.......O...X"
    assert run(["vision", "detect", str(photo), "--robot-marks", "x.... | ..... | ..x.. | ..... | ....x",
                "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["board"] == "X...O.O.....X.......O...X"


def test_detect_prints_the_cells_both_ways(tmp_path: Path, capsys):
    photo = tmp_path / "p.png"
    assert run(["vision", "render", str(photo), "--seed", "5", "--json"]) == 0
    rendered = json.loads(capsys.readouterr().out)
    truth = [rendered["board"][5 * k:5 * k + 5] for k in range(5)]
    marks = "".join(ch if ch == rendered["robot_symbol"] else "." for ch in rendered["board"])
    assert run(["vision", "detect", str(photo)]) == 2  # without the robot's marks a mirror cannot be told
    assert "cannot tell whether the photo is mirrored left-right" in capsys.readouterr().err
    assert run(["vision", "detect", str(photo), "--robot-marks", marks]) == 0
    out = capsys.readouterr().out
    assert "field found" in out
    rows = [line.split()[-1] for line in out.splitlines()[2:7]]
    assert rows == truth


@pytest.mark.parametrize("make, message", [
    (lambda p: p.write_text("hello"), "not an image"),
    (lambda p: cv2.imwrite(str(p), __import__("numpy").full((480, 640, 3), 240, "uint8")), "no ink"),
    (lambda p: None, "no such file"),
])
def test_detect_errors_are_one_line_and_status_2(tmp_path: Path, capsys, make, message):
    path = tmp_path / "x.png"
    make(path)
    assert run(["vision", "detect", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("ttt-sm vision: error:") and message in err and err.count("\n") == 1


def test_render_refuses_a_bad_board_and_dim(tmp_path: Path, capsys):
    assert run(["vision", "render", str(tmp_path / "a.png"), "--board", "XO"]) == 2
    assert "25 characters" in capsys.readouterr().err
    assert run(["vision", "render", str(tmp_path / "a.png"), "--dim", "3"]) == 2
    assert "--dim" in capsys.readouterr().err


def test_bench_on_a_few_photos(capsys):
    assert run(["vision", "bench", "--photos", "3", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["vision_photos"] == 3 and data["vision_accuracy"] == 1.0
    assert 0 < data["vision_detect_ms_median"] <= data["vision_detect_ms_single_max"]
