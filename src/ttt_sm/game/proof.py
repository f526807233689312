"""Prove that an engine never loses: walk every game an opponent can play against it.

At the opponent's turns every empty cell is tried; at the engine's turns the
engine is asked (``engine.move``), so what is checked is the engine itself,
book, symmetry mapping and search included.  A line of play ends when
someone has four in a row, the field is full, or the opponent has no line
left that the engine has not entered (it can no longer win).  Positions are
visited once per symmetry class, which is sound because the strong engine
answers symmetric positions symmetrically (it decides on a canonical image).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

from .bitboard import LINE_MASKS, bits, canonical, cell_index, has_four
from .engine import Engine, GameOver
from .rules import Board, Symbol, other


@dataclass(frozen=True)
class ProofReport:
    """What :func:`prove_no_loss` walked: positions, how the lines of play ended, and any loss found."""

    engine_symbol: Symbol
    first: Symbol
    positions: int
    """Distinct positions (up to symmetry) with the opponent to move."""
    engine_moves: int
    wins: int
    draws: int
    safe: int
    """Lines cut because the opponent had no open line left."""
    losses: list[str] = field(default_factory=list)
    """Boards (25 characters) where the opponent completed four: empty if the proof holds."""
    seconds: float = 0.0


def prove_no_loss(engine: Engine, engine_symbol: Symbol, first: Symbol = "X", start: Board | None = None,
                  progress: Callable[[str], None] | None = None) -> ProofReport:
    """Play every opponent move against ``engine`` from ``start`` (the empty field) and count the outcomes."""
    me, opp = engine_symbol, other(engine_symbol)
    visited: set[int] = set()
    counts = {"moves": 0, "wins": 0, "draws": 0, "safe": 0}
    losses: list[str] = []
    t0 = time.perf_counter()

    def engine_turn(b: Board) -> None:
        result = engine.move(b, me)
        if isinstance(result, GameOver):
            raise AssertionError(f"{engine.name} says the game is over on a live board {b}: {result.reason}")
        counts["moves"] += 1
        bit = 1 << cell_index(result.row, result.column)
        b = Board(b.x | bit, b.o) if me == "X" else Board(b.x, b.o | bit)
        if has_four(b.marks(me)):
            counts["wins"] += 1
        elif not b.empty_cells:
            counts["draws"] += 1
        elif all(b.marks(me) & m for m in LINE_MASKS):
            counts["safe"] += 1
        else:
            opponent_turn(b)

    def opponent_turn(b: Board) -> None:
        key = canonical(b.marks(opp), b.marks(me))[0]
        if key in visited:
            return
        visited.add(key)
        if progress and len(visited) % 5000 == 0:
            progress(f"proof: {len(visited)} positions, {time.perf_counter() - t0:.0f} s")
        for c in bits(b.empty_cells):
            nb = Board(b.x | 1 << c, b.o) if opp == "X" else Board(b.x, b.o | 1 << c)
            if has_four(nb.marks(opp)):
                losses.append(str(nb))
            elif not nb.empty_cells:
                counts["draws"] += 1
            else:
                engine_turn(nb)

    b0 = start if start is not None else Board.empty()
    to_move = first if b0.count(first) == b0.count(other(first)) else other(first)
    if to_move == me:
        engine_turn(b0)
    else:
        opponent_turn(b0)
    return ProofReport(me, first, len(visited), counts["moves"], counts["wins"], counts["draws"], counts["safe"],
                       losses, time.perf_counter() - t0)
