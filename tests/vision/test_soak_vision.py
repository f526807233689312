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


@pytest.mark.soak
def test_a_field_and_symbols_drawn_by_the_arm_through_the_control_chart_are_read(params, tmp_path):
    """Not synthetic ink: the twin's arm draws (holder drag, gear play), ten cameras read it."""
    from ttt_sm.app.drawing import DrawSession
    from ttt_sm.vision import board_text, detect
    from ttt_sm.vision.simulated import SimulatedCamera

    session = DrawSession(params, seed=0)
    session.start()
    session.draw("field", 3, 3, out_dir=tmp_path)
    session.draw("X", 2, 4, out_dir=tmp_path)
    session.draw("O", 4, 1, out_dir=tmp_path)
    board = session.robot.board
    board.draw_symbol("O", 5, 5)
    truth = ["."] * 25
    truth[1 * 5 + 3], truth[3 * 5 + 0], truth[4 * 5 + 4] = "X", "O", "O"
    for seed in range(10):
        cam = SimulatedCamera(board, params, seed=seed)
        assert board_text(detect(cam.frame()).cells, cam.view()) == "".join(truth), seed
