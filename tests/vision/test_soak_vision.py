"""The vision target in full: every cell of 200 simulated photos read right (soak: `make soak`)."""

from __future__ import annotations

import pytest

from ttt_sm.vision.bench import bench_vision


@pytest.mark.soak
def test_every_cell_of_200_simulated_photos_is_read_right(params):
    result = bench_vision(seed=0, photos=200, params=params)
    assert result["vision_wrong"] == []
    assert result["vision_accuracy"] == 1.0 and result["vision_grid_failures"] == 0
    assert result["vision_photos"] == 200
