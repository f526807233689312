"""Weak opponents for testing and benchmarking the engines: random and greedy players.

Both are seeded, so a game against them is reproducible from the seed.
"""

from __future__ import annotations

import random

from .bitboard import bits, cell_of, win_cells
from .engine import Engine, GameOver, Move, prepare
from .rules import Board, Symbol, other


class RandomEngine:
    """Plays a uniformly random empty cell."""

    name = "random"

    def __init__(self, seed: int = 0) -> None:
        self.rng = random.Random(seed)

    def move(self, board: Board | str, symbol: Symbol) -> Move | GameOver:
        """A random empty cell, or why the game is over."""
        b, _, over = prepare(board, symbol)
        if over is not None:
            return over
        return Move(*cell_of(self.rng.choice(bits(b.empty_cells))))


class GreedyEngine:
    """Wins when it can, blocks when it must, else plays a random empty cell."""

    name = "greedy"

    def __init__(self, seed: int = 0) -> None:
        self.rng = random.Random(seed)

    def move(self, board: Board | str, symbol: Symbol) -> Move | GameOver:
        """A winning cell, else a blocking cell, else a random one; or why the game is over."""
        b, me, over = prepare(board, symbol)
        if over is not None:
            return over
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
