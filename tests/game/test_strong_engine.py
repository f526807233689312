"""The strong engine never loses: immediate wins and blocks, every opening, whole games, exhaustive proofs."""

from __future__ import annotations

import random

import pytest

from ttt_sm.game.bench import strength_games
from ttt_sm.game.bitboard import N_CELLS, SYMMETRIES, bits, cell_index, has_four, win_cells
from ttt_sm.game.engine import GameOver, Move
from ttt_sm.game.match import play_game
from ttt_sm.game.opponents import GreedyEngine, RandomEngine
from ttt_sm.game.proof import prove_no_loss
from ttt_sm.game.rules import Board, apply_move, parse_board
from ttt_sm.game.solver import Solver
from ttt_sm.game.strong_engine import Analysis, StrongEngine


@pytest.fixture(scope="module")
def strong() -> StrongEngine:
    return StrongEngine()


def bit(move: Move | GameOver) -> int:
    assert isinstance(move, Move)
    return 1 << cell_index(move.row, move.column)


def positions_with(rng: random.Random, want, count: int = 25):
    """Random legal positions (X started) with the side to move, for which ``want(mine, theirs)`` holds."""
    found = 0
    while found < count:
        stones = rng.randint(5, 18)
        cells = rng.sample(range(N_CELLS), stones)
        x, o = sum(1 << c for c in cells[0::2]), sum(1 << c for c in cells[1::2])
        if has_four(x) or has_four(o):
            continue
        me = "X" if stones % 2 == 0 else "O"
        mine, theirs = (x, o) if me == "X" else (o, x)
        if want(mine, theirs):
            found += 1
            yield Board(x, o), me, mine, theirs


def test_it_takes_an_immediate_win(strong):
    for board, me, mine, theirs in positions_with(random.Random(1), lambda m, t: win_cells(m, t)):
        assert bit(strong.move(board, me)) & win_cells(mine, theirs)


def test_it_blocks_an_immediate_loss(strong):
    def one_threat_no_win(m: int, t: int) -> bool:
        th = win_cells(t, m)
        return not win_cells(m, t) and th != 0 and th & (th - 1) == 0

    for board, me, mine, theirs in positions_with(random.Random(2), one_threat_no_win):
        assert bit(strong.move(board, me)) == win_cells(theirs, mine)


def test_no_first_move_of_x_beats_it():
    """All 25 openings (6 up to symmetry): after the engine's reply X cannot force a win."""
    engine, solver = StrongEngine(), Solver()
    for c in range(N_CELLS):
        board = Board(1 << c, 0)
        reply = engine.analyse(board, "O")
        assert isinstance(reply, Analysis) and reply.outcome == "draw"
        assert not solver.attacker_wins(board.x, bit(reply.move), attacker_to_move=True)


def test_its_opening_as_x_cannot_be_beaten():
    first = StrongEngine().move(Board.empty(), "X")
    assert first == Move(3, 3)
    assert not Solver().attacker_wins(0, bit(first), attacker_to_move=True)


def test_as_x_it_never_loses_whatever_o_plays():
    """Exhaustive: every O move at every O turn, up to symmetry, against the engine's answers."""
    report = prove_no_loss(StrongEngine(), "X")
    assert report.losses == [] and report.positions > 1000
    assert report.wins > 0 and report.engine_moves > report.positions


def test_it_never_loses_in_40_games():
    strong = StrongEngine()
    results = [(kind, rec) for kind, rec in strength_games(strong, games=40, seed=1)]
    assert len(results) == 41
    for kind, record in results:
        assert record.loser_engine() != "strong" or kind == "strong", (kind, str(record.final))
    assert {kind for kind, _ in results} == {"random", "greedy", "thesis", "perfect", "strong"}


@pytest.mark.parametrize("first", ["X", "O"])
def test_strong_against_strong_is_a_draw(first):
    engine = StrongEngine()
    record = play_game(engine, engine, first=first)
    assert record.winner is None and not record.final.empty_cells


def test_it_wins_against_weak_play():
    strong = StrongEngine()
    wins = sum(play_game(strong, RandomEngine(s)).winner == "X" for s in range(5))
    wins += sum(play_game(GreedyEngine(s), strong).winner == "O" for s in range(5))
    assert wins == 10


def test_it_reports_the_game_over(strong):
    won = parse_board("XXXX." "OOO.." "....." "....." ".....")
    assert strong.move(won, "O") == GameOver("X", "X has four in a row: the opponent has won")
    full = parse_board("XXOOX" "OOXXO" "XXOOX" "OOXXO" "XXOOX")
    result = strong.move(full, "X")
    assert isinstance(result, GameOver) and result.winner is None


def test_the_book_answers_the_opening_and_the_search_the_rest(strong):
    opening = strong.analyse(Board.empty(), "X")
    assert isinstance(opening, Analysis) and opening.source == "book" and opening.outcome == "draw"
    b = Board.empty()
    for r, c, s in [(3, 3, "X"), (2, 2, "O"), (3, 4, "X"), (3, 2, "O"), (4, 3, "X"), (2, 4, "O")]:
        b = apply_move(b, r, c, s)
    later = strong.analyse(b, "X")
    assert isinstance(later, Analysis) and later.source == "search"


def test_symmetric_positions_get_symmetric_answers(strong):
    b = parse_board("....." ".X..." "..O.." "....X" ".....")
    cells = bits(b.x), bits(b.o)
    reply = bit(strong.move(b, "O"))
    for perm in SYMMETRIES:
        image = Board(sum(1 << perm[i] for i in cells[0]), sum(1 << perm[i] for i in cells[1]))
        image_reply = bit(strong.move(image, "O"))
        assert image_reply == 1 << perm[reply.bit_length() - 1]  # the position has no symmetry of its own


@pytest.mark.soak
def test_it_never_loses_in_240_games():
    strong = StrongEngine()
    lost = [(kind, str(r.final)) for kind, r in strength_games(strong, games=240, seed=2)
            if r.loser_engine() == "strong"]
    assert lost == []


@pytest.mark.soak
def test_as_o_it_never_loses_whatever_x_plays():
    """Exhaustive from the empty field: every X move at every X turn, up to symmetry (a few minutes)."""
    report = prove_no_loss(StrongEngine(), "O")
    assert report.losses == [] and report.positions > 10_000
