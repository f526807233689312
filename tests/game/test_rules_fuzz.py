"""Board strings under fuzz: any text is a board some game reaches, or a BoardError saying why."""

from __future__ import annotations

from hypothesis import strategies as st

from fuzzing import fuzz, one_line
from ttt_sm.cli.ai import ai_move
from ttt_sm.game.rules import BoardError, GameError, parse_board

_CELLS = st.text(alphabet=st.sampled_from(list(".XOxo ./|\n\t") + ["é", "\x00", "0", "#"]), max_size=40)
_ANY = st.one_of(_CELLS, st.text(max_size=60), st.none(), st.integers(), st.binary(max_size=10))


def board_or_error(text: object) -> None:
    try:
        board = parse_board(text)  # type: ignore[arg-type]
    except BoardError as exc:
        one_line(str(exc), "")
        return
    assert parse_board(str(board)) == board  # what was read is a board, and reads back the same


def thesis_move(text: str, symbol: str) -> None:
    try:
        out = ai_move(text, symbol, engine="thesis")
    except GameError as exc:
        one_line(str(exc), "")
        return
    assert out["game_over"] or (1 <= out["row"] <= 5 and 1 <= out["column"] <= 5)


test_any_text_is_a_board_or_a_board_error, test_any_text_is_a_board_or_a_board_error_soak = fuzz(_ANY)(
    board_or_error)
test_the_engine_answers_any_board_text_or_refuses_it, test_the_engine_answers_any_board_text_or_refuses_it_soak = \
    fuzz(_CELLS, st.sampled_from(["X", "O", "x", "", "XO", "?"]), quick=100, soak=2000)(thesis_move)
