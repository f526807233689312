"""The issue's strength target: at least 200 games against the thesis engine and randomised opponents."""

import pytest

from ttt_sm.game.bench import bench_ai


@pytest.mark.soak
def test_two_hundred_games_and_the_strong_engine_loses_none():
    result = bench_ai(seed=7, games=200)
    assert result["ai_games"] == 201
    assert result["ai_strong_losses"] == 0
    assert result["ai_strong_losses_vs_thesis"] == 0
    assert result["ai_strong_vs_strong"] == "draw"
    assert result["ai_strong_wins"] + result["ai_strong_draws"] == 200
