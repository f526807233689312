"""The solver's yes/no answers agree with a plain minimax of the whole game tree."""

from __future__ import annotations

import functools
import random

import pytest

from ttt_sm.game.bitboard import FULL, N_CELLS, has_four, transform, win_cells
from ttt_sm.game.solver import Solver, ordered_moves


@functools.cache
def minimax(mover: int, other: int) -> int:
    """+1 if the side to move wins, 0 draw, -1 loss: every move, no pruning but the first win."""
    empty = FULL & ~(mover | other)
    if not empty:
        return 0
    best = -1
    for c in range(N_CELLS):
        b = 1 << c
        if empty & b:
            if has_four(mover | b):
                return 1
            best = max(best, -minimax(other, mover | b))
            if best == 1:
                return 1
    return best


def random_position(rng: random.Random, stones: int) -> tuple[int, int]:
    """(mover, other) with ``stones`` marks, no four, the mover having no more marks than the other."""
    while True:
        cells = rng.sample(range(N_CELLS), stones)
        first, second = sum(1 << c for c in cells[0::2]), sum(1 << c for c in cells[1::2])
        if not has_four(first) and not has_four(second):
            return (first, second) if stones % 2 == 0 else (second, first)


@pytest.mark.parametrize("stones", [13, 14, 15, 16])
def test_the_solver_agrees_with_minimax(stones):
    rng = random.Random(stones)
    for _ in range(12):
        mover, other = random_position(rng, stones)
        value = minimax(mover, other)
        assert Solver().attacker_wins(mover, other, attacker_to_move=True) == (value == 1)
        assert Solver().attacker_wins(other, mover, attacker_to_move=False) == (value == -1)


def test_answers_do_not_depend_on_symmetry_or_the_table():
    rng = random.Random(7)
    shared = Solver()
    for _ in range(20):
        mover, other = random_position(rng, 8)
        answers = set()
        for s in range(8):
            k = transform(mover, other, s)
            answers.add(shared.attacker_wins(k & FULL, k >> N_CELLS, True))
        assert answers == {Solver().attacker_wins(mover, other, True)}


def test_threats_and_ordering():
    row = 0b111  # three in row 1: (1,4) completes four, (1,5) does not
    assert win_cells(row, 0) == 1 << 3
    assert win_cells(row, 1 << 3) == 0
    first = ordered_moves(0, 0)[0]
    assert first == 1 << 12  # the centre lies on the most lines


def test_the_opening_reply_decides_the_game():
    """After X takes the centre, only the four diagonal neighbours hold the draw for O."""
    centre, solver = 1 << 12, Solver()
    holding = {c for c in range(N_CELLS) if c != 12
               and not solver.attacker_wins(centre, 1 << c, attacker_to_move=True)}
    assert holding == {6, 8, 16, 18}


@pytest.mark.soak
def test_the_empty_field_is_a_draw():
    """(5,5,4) is a draw: neither side can force four in a row from the empty field."""
    assert not Solver().attacker_wins(0, 0, attacker_to_move=True)
    assert not Solver().attacker_wins(0, 0, attacker_to_move=False)


def test_a_finished_game_is_answered_directly():
    four, three = 0b1111, 0b111 << 5
    assert Solver().attacker_wins(four, three, attacker_to_move=False)
    assert not Solver().attacker_wins(three, four, attacker_to_move=True)
