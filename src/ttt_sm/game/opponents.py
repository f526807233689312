"""Opponents for testing and benchmarking the engines: random, greedy and perfect-but-aimless players.

All are seeded, so a game against them is reproducible from the seed.
"""

from __future__ import annotations

import random

from .bitboard import bits, canonical, cell_of, win_cells
from .book import Book, load_book
from .engine import Engine, GameOver, Move, prepare
from .rules import Board, Symbol, other
from .solver import Solver


class _SeededEngine:
    """An engine whose choices come from a generator seeded by ``seed``.

    :meth:`move` says why a finished game is over; a subclass fills in
    :meth:`choose`, which is asked only while the game goes on.
    """

    def __init__(self, seed: int = 0) -> None:
        self.rng = random.Random(seed)

    def move(self, board: Board | str, symbol: Symbol) -> Move | GameOver:
        """The engine's cell (:meth:`choose`), or why the game is over."""
        b, me, over = prepare(board, symbol)
        return over if over is not None else self.choose(b, me)

    def choose(self, b: Board, me: Symbol) -> Move:
        """The cell to play on a board where the game goes on, `me` to move."""
        raise NotImplementedError


class RandomEngine(_SeededEngine):
    """Plays a uniformly random empty cell."""

    name = "random"

    def choose(self, b: Board, me: Symbol) -> Move:
        """A random empty cell."""
        return Move(*cell_of(self.rng.choice(bits(b.empty_cells))))


class GreedyEngine(_SeededEngine):
    """Wins when it can, blocks when it must, else plays a random empty cell."""

    name = "greedy"

    def choose(self, b: Board, me: Symbol) -> Move:
        """A winning cell, else a blocking cell, else a random one."""
        mine, theirs = b.marks(me), b.marks(other(me))
        for cells in (win_cells(mine, theirs), win_cells(theirs, mine), b.empty_cells):
            if cells:
                return Move(*cell_of(self.rng.choice(bits(cells))))
        raise AssertionError("prepare() returned a full field as not over")  # pragma: no cover


class RandomOpening:
    """Another engine that plays its first ``plies`` moves at random (to vary deterministic engines)."""

    def __init__(self, engine: Engine, plies: int = 1, seed: int = 0) -> None:
        self.engine = engine
        self.plies = plies
        self.random = RandomEngine(seed)
        self.name = engine.name

    def move(self, board: Board | str, symbol: Symbol) -> Move | GameOver:
        """A random cell while this side has fewer than ``plies`` marks, then the engine's."""
        b, me, over = prepare(board, symbol)
        if over is None and b.count(me) < self.plies:
            return self.random.move(b, me)
        return self.engine.move(b, me)


class PerfectEngine(_SeededEngine):
    """Plays a random move among those that do not lose: a perfect but aimless player.

    A move loses if it leaves the other side a forced win: the opening book
    says so for the first few marks, the solver after.
    """

    name = "perfect"

    def __init__(self, seed: int = 0, book: Book | None = None) -> None:
        super().__init__(seed)
        self.book = load_book() if book is None else book
        self.solver = Solver()

    def choose(self, b: Board, me: Symbol) -> Move:
        """A random cell after which the opponent cannot force a win (any cell if all lose)."""
        mine, theirs = b.marks(me), b.marks(other(me))
        for cells in (win_cells(mine, theirs), win_cells(theirs, mine)):
            if cells:
                return Move(*cell_of(self.rng.choice(bits(cells))))
        candidates = bits(b.empty_cells)
        self.rng.shuffle(candidates)
        for c in candidates:
            after = mine | 1 << c
            entry = self.book.get(canonical(theirs, after)[0])
            opponent_wins = entry[1] == "win" if entry is not None else \
                self.solver.attacker_wins(theirs, after, attacker_to_move=True)
            if not opponent_wins:
                return Move(*cell_of(c))
        return Move(*cell_of(candidates[0]))
