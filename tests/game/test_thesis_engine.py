"""The thesis' algorithm (3.6.2) as written: three plies, f = n1 - n2, +/-inf, the out-of-range output."""

from __future__ import annotations

import math
import random

import pytest

from ttt_sm.game.bitboard import FULL, LINES, bits, has_four
from ttt_sm.game.engine import GameOver, Move
from ttt_sm.game.rules import Board, BoardError, MoveError, parse_board
from ttt_sm.game.thesis_engine import (
    OUT_OF_RANGE,
    ThesisEngine,
    _third_ply,
    first_ply_scores,
    static_evaluation,
    thesis_algorithm,
)


def reference_play_ps(field: str, me: str) -> tuple[int, int]:
    """Steps 3-13 spelled out on a 25-character field, nothing clever: the slow reference."""
    them = "O" if me == "X" else "X"

    def wins(f: str, s: str) -> bool:
        return any(all(f[i] == s for i in line) for line in LINES)

    def f_value(f: str) -> int:  # eq. 3.52 on text: lines free of the other side's symbol
        n1 = sum(all(f[i] != them for i in line) for line in LINES)
        n2 = sum(all(f[i] != me for i in line) for line in LINES)
        return n1 - n2

    def put(f: str, i: int, s: str) -> str:
        return f[:i] + s + f[i + 1:]

    best, best_cell = -math.inf, None
    for i in range(25):  # step 3
        if field[i] != ".":
            continue
        f1 = put(field, i, me)
        if wins(f1, me):  # step 4
            score = math.inf
        else:
            replies = []
            for j in range(25):  # step 5
                if f1[j] != ".":
                    continue
                f2 = put(f1, j, them)
                if wins(f2, them):  # step 6
                    replies.append(-math.inf)
                    continue
                thirds = []
                for k in range(25):  # step 7
                    if f2[k] != ".":
                        continue
                    f3 = put(f2, k, me)
                    thirds.append(math.inf if wins(f3, me) else f_value(f3))  # steps 8-9
                replies.append(max(thirds) if thirds else f_value(f2))  # step 10
            score = min(replies) if replies else f_value(f1)  # step 11
        if score > best:  # step 12: the first of equal scores
            best, best_cell = score, i
    assert best_cell is not None
    return best_cell // 5 + 1, best_cell % 5 + 1


def random_position(rng: random.Random, stones: int) -> Board:
    while True:
        cells = rng.sample(range(25), stones)
        x, o = sum(1 << c for c in cells[0::2]), sum(1 << c for c in cells[1::2])
        if not has_four(x) and not has_four(o):
            return Board(x, o)


def test_the_static_evaluation_counts_open_lines():
    assert static_evaluation(0, 0) == 0  # every line open to both
    centre = 1 << 12
    assert static_evaluation(centre, 0) == 8  # the centre closes 8 lines to the opponent
    assert static_evaluation(1, 0) == 3 and static_evaluation(0, centre) == -8


def test_the_third_ply_shortcut_is_the_maximum_of_the_leaves():
    rng = random.Random(3)
    for stones in range(0, 18, 2):
        for _ in range(5):
            b = random_position(rng, stones)
            mine, theirs = b.x, b.o
            leaves = [math.inf if has_four(mine | 1 << c) else static_evaluation(mine | 1 << c, theirs)
                      for c in bits(FULL & ~(mine | theirs))]
            assert _third_ply(mine, theirs) == max(leaves)


@pytest.mark.parametrize("stones", [2, 5, 8, 13])
def test_the_engine_plays_what_the_steps_say(stones):
    rng = random.Random(stones)
    b = random_position(rng, stones)
    me = "X" if b.count("X") == b.count("O") else "O"
    assert ThesisEngine().move(b, me) == Move(*reference_play_ps(str(b), me))


def test_the_first_move_is_the_centre():
    assert ThesisEngine().move(Board.empty(), "X") == Move(3, 3)
    assert thesis_algorithm([], []) == (3, 3)


def test_it_takes_a_win_and_blocks_a_loss():
    win = parse_board("XXX.." "OOO.." "....." "....." ".....")
    assert ThesisEngine().move(win, "X") == Move(1, 4)
    block = parse_board("XX..." "OOO.." "X...." "....." ".....")
    assert ThesisEngine().move(block, "X") == Move(2, 4)
    assert first_ply_scores(win.x, win.o)[3] == math.inf


def test_a_won_game_gives_the_out_of_range_coordinate():
    won = parse_board("XXXX." "OOO.." "....." "....." ".....")
    assert thesis_algorithm(o_pos=[(1, 1), (1, 2), (1, 3), (1, 4)], x_pos=[(2, 1), (2, 2), (2, 3)]) == OUT_OF_RANGE
    result = ThesisEngine().move(won, "O")
    assert isinstance(result, GameOver)
    assert result.winner == "X" and result.thesis_output == OUT_OF_RANGE == (6, 6)
    own = ThesisEngine().move(won, "X")
    assert isinstance(own, GameOver) and own.winner == "X" and own.thesis_output is None


def test_a_full_field_is_a_draw():
    full = parse_board("XXOOX" "OOXXO" "XXOOX" "OOXXO" "XXOOX")
    assert ThesisEngine().move(full, "O") == GameOver(None, "the field is full: a draw")
    with pytest.raises(MoveError, match="no empty cell"):
        thesis_algorithm([(r, c) for r in range(1, 6) for c in range(1, 6) if str(full)[5 * r + c - 6] == "O"],
                         [(r, c) for r in range(1, 6) for c in range(1, 6) if str(full)[5 * r + c - 6] == "X"])


def test_bad_coordinates_are_named():
    with pytest.raises(BoardError, match="o_pos: cell \\(0, 3\\) is off the field"):
        thesis_algorithm([(0, 3)], [])
    with pytest.raises(BoardError, match="share a cell"):
        thesis_algorithm([(1, 1)], [(1, 1)])
    with pytest.raises(MoveError, match="not O's turn"):
        ThesisEngine().move("OO...X...................", "O")
