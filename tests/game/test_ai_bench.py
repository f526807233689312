"""bench_ai reports the targets' keys, and the strong engine loses none of the bench games."""

from __future__ import annotations

import math

import pytest

from ttt_sm.game.bench import bench_ai, opponents


def test_the_bench_reports_the_targets():
    result = bench_ai(seed=0, games=10)
    for key in ("ai_strong_startup_s", "ai_strong_move_ms_p95", "ai_thesis_move_ms_p95"):
        assert result[key] > 0 and math.isfinite(result[key]), key
    assert result["ai_games"] == 11 and result["ai_strong_losses"] == 0
    assert result["ai_strong_wins"] + result["ai_strong_draws"] == 10
    assert result["ai_strong_vs_strong"] == "draw"


def test_the_opponents_are_reproducible_and_mixed():
    kinds = [k for k, _ in opponents(10, seed=3)]
    assert [kinds.count(k) for k in ("random", "greedy", "thesis", "perfect")] == [3, 3, 2, 2]
    a = [e.move("." * 25, "X") for _, e in opponents(10, seed=3)]
    assert a == [e.move("." * 25, "X") for _, e in opponents(10, seed=3)]


@pytest.mark.soak
def test_the_full_bench_loses_no_game():
    result = bench_ai(seed=0)
    assert result["ai_games"] == 101 and result["ai_strong_losses"] == 0
