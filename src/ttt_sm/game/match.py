"""Play whole games between two engines and keep the record (what the tests and the bench run)."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass

from .engine import Engine, GameOver
from .rules import Board, Symbol, apply_move, is_over, other, winner


@dataclass(frozen=True)
class Turn:
    """One move of a game: who, where, which engine and how long it thought."""

    symbol: Symbol
    row: int
    column: int
    engine: str
    time_ms: float


@dataclass(frozen=True)
class GameRecord:
    """A finished game: its moves in order, the final board and the winner (``None``: a draw)."""

    turns: tuple[Turn, ...]
    final: Board
    winner: Symbol | None
    engines: dict[Symbol, str]

    def loser_engine(self) -> str | None:
        """The name of the engine that lost, if one did."""
        return None if self.winner is None else self.engines[other(self.winner)]


def play_game(x: Engine, o: Engine, first: Symbol = "X",
              opening: Sequence[tuple[int, int]] = ()) -> GameRecord:
    """Play ``x`` against ``o`` until someone has four in a row or the field is full.

    ``opening`` cells are played first, alternately from ``first``, before the
    engines take over (to start games from varied positions).
    """
    engines: dict[Symbol, Engine] = {"X": x, "O": o}
    board, to_move = Board.empty(), first
    turns: list[Turn] = []
    for row, column in opening:
        board = apply_move(board, row, column, to_move)
        turns.append(Turn(to_move, row, column, "opening", 0.0))
        to_move = other(to_move)
    while not is_over(board):
        engine = engines[to_move]
        t0 = time.perf_counter()
        move = engine.move(board, to_move)
        dt_ms = (time.perf_counter() - t0) * 1000.0
        if isinstance(move, GameOver):
            raise AssertionError(f"{engine.name} says the game is over on a live board: {move.reason}")
        board = apply_move(board, move.row, move.column, to_move)
        turns.append(Turn(to_move, move.row, move.column, engine.name, dt_ms))
        to_move = other(to_move)
    return GameRecord(tuple(turns), board, winner(board), {"X": x.name, "O": o.name})
