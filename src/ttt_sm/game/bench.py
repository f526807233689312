"""Speed and strength of the engines over a reproducible set of games: :func:`bench_ai`.

The strong engine plays both symbols against random players, greedy players
(win if possible, block if needed), the thesis engine (its first move at
random, so the games differ), perfect-but-aimless players (never a losing
move) and itself; the numbers are the targets of the
issue: the strong engine's start-up time and its 95th-percentile move time,
the thesis engine's move time, and the strong engine's losses (always 0).
"""

from __future__ import annotations

import random
import time
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np

from .book import Book, load_book
from .engine import Engine
from .match import GameRecord, play_game
from .opponents import GreedyEngine, PerfectEngine, RandomEngine, RandomOpening
from .rules import Board
from .strong_engine import StrongEngine
from .thesis_engine import ThesisEngine

KINDS = ("random", "greedy", "thesis", "perfect", "random", "greedy", "thesis", "perfect", "random", "greedy")
"""The opponents in turn: 30 % random, 30 % greedy, 20 % thesis, 20 % perfect."""


def opponents(games: int, seed: int, book: Book | None = None) -> Iterator[tuple[str, Engine]]:
    """``games`` seeded opponents for the strong engine, of the :data:`KINDS` in turn.

    ``thesis`` plays its first move at random (else every game against it
    would be the same); ``perfect`` never makes a losing move but aims at
    nothing (the longest games); ``book`` is the one it reads (default: the
    packaged one, loaded once).
    """
    rng = random.Random(seed)
    book = load_book() if book is None else book
    for i in range(games):
        s = rng.randrange(1 << 30)
        kind = KINDS[i % len(KINDS)]
        if kind == "random":
            yield kind, RandomEngine(s)
        elif kind == "greedy":
            yield kind, GreedyEngine(s)
        elif kind == "perfect":
            yield kind, PerfectEngine(s, book)
        else:
            yield kind, RandomOpening(ThesisEngine(), plies=1, seed=s)


def strength_games(strong: Engine, games: int, seed: int = 0,
                   progress: Callable[[str], None] | None = None) -> Iterator[tuple[str, GameRecord]]:
    """Play ``strong`` against :func:`opponents`, alternating who has X (X starts); then strong vs strong."""
    for i, (kind, opponent) in enumerate(opponents(games, seed)):
        record = play_game(strong, opponent) if i % 2 == 0 else play_game(opponent, strong)
        if progress and (i + 1) % 20 == 0:
            progress(f"ai: {i + 1}/{games} games")
        yield kind, record
    yield "strong", play_game(strong, strong)


def _p95(values: list[float]) -> float:
    return float(np.percentile(values, 95)) if values else float("nan")


def bench_ai(seed: int = 0, games: int = 100, progress: Callable[[str], None] | None = None) -> dict[str, Any]:
    """Play ``games`` + 1 games and report the engines' timing and the strong engine's results.

    Keys: ``ai_strong_startup_s`` (building the engine: loading the opening
    book), ``ai_strong_move_ms_p95``/``_mean``/``_max``,
    ``ai_thesis_move_ms_p95``/``_max``, ``ai_games``, ``ai_strong_wins``,
    ``ai_strong_draws``, ``ai_strong_losses`` and losses per opponent kind.
    """
    t0 = time.perf_counter()
    strong = StrongEngine()
    startup_s = time.perf_counter() - t0
    strong_ms: list[float] = []
    thesis_ms: list[float] = []
    wins = draws = losses = 0
    losses_by: dict[str, int] = {"random": 0, "greedy": 0, "thesis": 0, "perfect": 0}
    n = 0
    self_play = "not played"
    for kind, record in strength_games(strong, games, seed, progress):
        n += 1
        strong_ms += [t.time_ms for t in record.turns if t.engine == "strong"]
        # The thesis' first move in each game is the random opening, not the algorithm: left out.
        thesis_ms += [t.time_ms for t in record.turns if t.engine == "thesis"][1:]
        if kind == "strong":
            self_play = "draw" if record.winner is None else f"{record.winner} won"
            continue
        strong_symbol = "X" if record.engines["X"] == "strong" else "O"
        if record.winner is None:
            draws += 1
        elif record.winner == strong_symbol:
            wins += 1
        else:
            losses += 1
            losses_by[kind] += 1
    fresh = StrongEngine()
    t1 = time.perf_counter()
    fresh.move(Board.empty(), "X")  # what a new engine does first: a book look-up
    first_ms = (time.perf_counter() - t1) * 1000.0
    return {
        "ai_strong_startup_s": round(startup_s, 4),
        "ai_strong_first_move_ms": round(first_ms, 2),
        "ai_strong_move_ms_p95": round(_p95(strong_ms), 2),
        "ai_strong_move_ms_mean": round(float(np.mean(strong_ms)), 2),
        "ai_strong_move_ms_max": round(max(strong_ms), 2),
        "ai_thesis_move_ms_p95": round(_p95(thesis_ms), 2),
        "ai_thesis_move_ms_max": round(max(thesis_ms), 2) if thesis_ms else float("nan"),
        "ai_games": n,
        "ai_strong_moves": len(strong_ms),
        "ai_strong_wins": wins,
        "ai_strong_draws": draws,
        "ai_strong_losses": losses,
        **{f"ai_strong_losses_vs_{k}": v for k, v in losses_by.items() if k != "strong"},
        "ai_strong_vs_strong": self_play,
    }
