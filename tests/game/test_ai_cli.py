"""``ttt-sm ai move``: the cell and time as JSON, a clear game-over result, one-line errors with status 2."""

from __future__ import annotations

import json

import pytest

from ttt_sm.cli import main
from ttt_sm.cli.ai import ai_move


def run(capsys, *argv: str) -> tuple[int, str, str]:
    code = main(["ai", "move", *argv])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.mark.parametrize("engine", ["strong", "thesis"])
def test_it_prints_the_cell_and_the_time_as_json(capsys, engine):
    code, out, _ = run(capsys, "--board", "............X............", "--symbol", "O", "--engine", engine, "--json")
    data = json.loads(out)
    assert code == 0 and data["game_over"] is False
    assert 1 <= data["row"] <= 5 and 1 <= data["column"] <= 5 and data["time_ms"] >= 0
    assert (data["row"], data["column"]) != (3, 3)


def test_the_text_form_names_the_cell(capsys):
    code, out, _ = run(capsys, "--board", "." * 25, "--symbol", "X")
    assert code == 0 and out.startswith("strong plays X at row 3, column 3")


def test_a_won_game_is_a_game_over_result(capsys):
    board = "XXXX." "OOO.." "....." "....." "....."
    code, out, _ = run(capsys, "--board", board, "--symbol", "O", "--engine", "thesis", "--json")
    data = json.loads(out)
    assert code == 0 and data["game_over"] is True and data["winner"] == "X"
    assert data["thesis_output"] == [6, 6] and "row" not in data
    code, out, _ = run(capsys, "--board", board, "--symbol", "O")
    assert code == 0 and out.startswith("game over: X")


@pytest.mark.parametrize("board, symbol, words", [
    ("XX.", "O", "--board: a board has 25 cells"),
    ("X....O...A...............", "O", "--board: board character 10 (row 2, column 5) is 'A'"),
    ("XXX......................", "O", "impossible move counts"),
    ("X........................", "X", "not X's turn"),
    ("X........................", "Y", "--symbol must be X or O"),
])
def test_a_bad_board_is_one_line_and_exit_2(capsys, board, symbol, words):
    code, out, err = run(capsys, "--board", board, "--symbol", symbol)
    assert code == 2 and out == ""
    assert err.startswith("ttt-sm ai: error: ") and err.count("\n") == 1 and words in err, err


def test_the_function_behind_the_command():
    out = ai_move("." * 25, "x", "strong")
    assert out["symbol"] == "X" and (out["row"], out["column"]) == (3, 3) and out["source"] == "book"


def test_the_main_cli_runs_it(capsys):
    from ttt_sm import cli

    assert cli.main(["ai", "move", "--board", "Z" * 25, "--symbol", "X"]) == 2
    assert cli.main(["ai", "move", "--board", "." * 25, "--symbol", "X", "--json"]) == 0
