"""The rules: 28 winning lines, boards as 25 characters, and every illegal board named."""

from __future__ import annotations

import pytest

from ttt_sm.game.bitboard import LINE_MASKS, LINES, SYMMETRIES, canonical, pack, transform
from ttt_sm.game.rules import (
    Board,
    BoardError,
    GameError,
    MoveError,
    apply_move,
    check_board,
    format_board,
    is_draw,
    is_full,
    is_over,
    legal_moves,
    parse_board,
    whose_turn,
    winner,
    winning_line,
)

# A full field with no four anywhere (rows alternate in pairs: X X O O X / O O X X O ...).
DRAWN = "XXOOX" "OOXXO" "XXOOX" "OOXXO" "XXOOX"


def board(*rows: str) -> Board:
    return parse_board("".join(rows))


def test_there_are_28_winning_lines_of_four():
    assert len(LINES) == 28 and len(set(LINE_MASKS)) == 28
    rows = [line for line in LINES if len({i // 5 for i in line}) == 1]
    columns = [line for line in LINES if len({i % 5 for i in line}) == 1]
    assert len(rows) == 10 and len(columns) == 10  # two fours in each row and column; 8 diagonals
    assert all(len(line) == 4 for line in LINES)


def test_the_eight_symmetries_map_winning_lines_to_winning_lines():
    masks = set(LINE_MASKS)
    for perm in SYMMETRIES:
        assert sorted(perm) == list(range(25))
        assert {sum(1 << perm[i] for i in line) for line in LINES} == masks


def test_symmetric_positions_have_one_canonical_key():
    a, b = 0b1000000000000000000000011, 0b0000000000001000000000100
    keys = {canonical(transform(a, b, s) & (2**25 - 1), transform(a, b, s) >> 25)[0] for s in range(8)}
    assert len(keys) == 1 and keys.pop() <= pack(a, b)


def test_a_board_reads_and_prints_as_25_characters_row_by_row():
    b = parse_board("X...." ".O..." "....." "....." ".....")
    assert b.at(1, 1) == "X" and b.at(2, 2) == "O" and b.at(5, 5) == "."
    assert str(b) == "X.....O.................."
    assert format_board(b, grid=True).splitlines() == ["X....", ".O...", ".....", ".....", "....."]
    assert parse_board("x..../.o.../...../...../.....") == b  # lower case and separators read too
    assert parse_board(format_board(b, grid=True)) == b


@pytest.mark.parametrize("text, words", [
    ("X" * 24, "25 cells"),
    ("." * 26, "25 cells"),
    ("X....O...A...............", "character 10 (row 2, column 5) is 'A'"),
    ("XXX......................", "X has 3 marks and O 0"),
    ("OOO..X...................", "X has 1 marks and O 3"),
])
def test_a_malformed_board_is_named(text, words):
    with pytest.raises(BoardError) as info:
        parse_board(text)
    assert words in str(info.value)


def test_the_counts_follow_who_started():
    b = board("X....", ".....", ".....", ".....", ".....")
    assert whose_turn(b) == "O"
    with pytest.raises(BoardError, match="O started"):
        parse_board(str(b), first="O")
    o_first = board("O....", ".....", ".....", ".....", ".....")
    assert whose_turn(o_first, first="O") == "X"
    assert whose_turn(Board.empty(), first="O") == "O" and whose_turn(Board.empty()) == "X"


def test_two_winners_are_illegal():
    with pytest.raises(BoardError, match="both X and O"):
        board("XXXX.", "OOOO.", ".....", ".....", ".....")


def test_play_after_a_win_is_illegal():
    # X started and completed the row; O's fourth mark came after the win.
    after = "XXXX." "OOO.." "O...." "....." "....."
    with pytest.raises(BoardError, match="played after it"):
        parse_board(after, first="X")
    assert winner(parse_board(after)) == "X"  # legal if O started: then X's fourth mark was the last move
    with pytest.raises(BoardError, match="played after it"):
        parse_board("XXXX." "OOO.O" "O...." "....." ".....")  # O has more marks: O moved last
    with pytest.raises(BoardError, match="two separate fours"):
        parse_board("XXXX." "OOO.O" "O...O" "XXXX." "O....")


def test_five_in_a_row_is_one_win():
    # The middle mark completes both fours of the row, so one move made them.
    b = parse_board("XX.XX" "OO.O." "..O.." "....." ".....")
    five = apply_move(b, 1, 3, "X")
    check_board(five, first="X")
    assert winner(five) == "X"


def test_winner_draw_and_full():
    assert winner(Board.empty()) is None and not is_over(Board.empty())
    d = parse_board(DRAWN)
    assert is_full(d) and is_draw(d) and is_over(d) and winner(d) is None and legal_moves(d) == []
    diag = board("X....", ".X...", "..X..", "...X.", "OOO.O")
    assert winner(diag) == "X" and winning_line(diag) == ((1, 1), (2, 2), (3, 3), (4, 4))
    anti = board("....O", "...O.", "..O..", ".O...", "XXX.X")
    assert winner(anti) == "O" and whose_turn(anti, first="X") is None


def test_moves_are_applied_only_when_legal():
    b = apply_move(Board.empty(), 3, 3, "X")
    assert legal_moves(b)[:3] == [(1, 1), (1, 2), (1, 3)] and len(legal_moves(b)) == 24
    with pytest.raises(MoveError, match=r"\(3, 3\) already holds X"):
        apply_move(b, 3, 3, "O")
    with pytest.raises(MoveError, match="off the field"):
        apply_move(b, 6, 1, "O")
    with pytest.raises(MoveError, match="not X's turn"):
        apply_move(b, 1, 1, "X")
    with pytest.raises(GameError, match="X or O"):
        apply_move(b, 1, 1, "Z")  # type: ignore[arg-type]
    won = board("XXXX.", "OOO..", ".....", ".....", ".....")
    with pytest.raises(MoveError, match="game is over"):
        apply_move(won, 5, 5, "O")


def test_game_errors_are_value_errors():
    assert issubclass(GameError, ValueError)
    assert issubclass(BoardError, GameError) and issubclass(MoveError, GameError)
    with pytest.raises(BoardError):
        check_board(Board(1, 1))
