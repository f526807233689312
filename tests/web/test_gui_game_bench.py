"""``gui_game_realtime_factor``: a whole game as fast as it goes with the /game page open in Chromium.

Only what the bench reports is checked here, not how fast it was (speed is
read from ``ttt-sm bench --json``, never asserted by a test).
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import pytest

from browser_fixtures import chromium_executable
from ttt_sm.params import load_params
from ttt_sm.web.bench import bench_gui_game


@pytest.mark.soak  # two whole games (30-80 s); test_game_page plays one by clicks in the default run
def test_the_gui_game_bench_plays_the_same_whole_game_headless_and_in_the_page() -> None:
    # In a thread of its own: the bench starts Playwright's sync API, which refuses a thread where another
    # test's browser (the session's `browser` fixture) already runs its loop.
    with ThreadPoolExecutor(1) as pool:
        result = pool.submit(bench_gui_game, load_params(), 0, chromium_executable()).result(timeout=1800)
    # The same game (one seed, a simulated person) both times: it ends at the same simulated time, to within
    # the bench's look at the session every 0.05 s of wall time.
    assert result["gui_game_sim_s"] > 60.0
    assert result["gui_game_sim_s"] == pytest.approx(result["gui_game_headless_sim_s"], abs=3.0)
    assert result["gui_game_outcome"] in ("X", "O", "draw")
    for prefix in ("gui_game", "gui_game_headless"):
        sim, wall = result[f"{prefix}_sim_s"], result[f"{prefix}_wall_s"]
        assert result[f"{prefix}_realtime_factor"] == pytest.approx(sim / wall, abs=0.05 + 0.1 * sim / wall ** 2)
    assert result["gui_game_messages_received"] > 20  # the page was attached and got frames all along
