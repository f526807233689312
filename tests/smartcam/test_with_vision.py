"""The game's path, end to end: simulated photo -> detector -> emulated camera -> pty -> reader ->
board order -> percent-process finds the person's move (thesis 3.6.3, figs. 3.21-3.22)."""

from __future__ import annotations

import pytest

vision = pytest.importorskip("ttt_sm.vision")

from ttt_sm.params import load_params  # noqa: E402
from ttt_sm.smartcam import CameraEmulator, detection_source  # noqa: E402
from ttt_sm.vision.scenes import random_scene  # noqa: E402
from ttt_sm.vision.simulated import SimulatedCamera  # noqa: E402


class StillCamera:
    """One photo, taken once: the scene does not change while the frames are sent (and rendering is slow)."""

    def __init__(self, image) -> None:
        self.image = image

    def frame(self):
        return self.image


def test_the_persons_move_arrives_through_the_serial_link(tmp_path, open_reader, read_until):
    params = load_params()
    scene = random_scene(params, 3, max_symbols=4)
    assert scene.person_cells, "the scene needs a person's move"
    camera = SimulatedCamera(scene.board, params, seed=3)
    image = camera.frame()
    detection = vision.detect(image)

    with CameraEmulator(detection_source(StillCamera(image), vision.detect), rate_hz=20,
                        link=tmp_path / "camera") as cam:
        reader = open_reader(cam.port)
        read_until(reader, lambda: reader.stats.frames_ok >= 2)
        frame = reader.latest()

    # the wire carries one decimal of what the detector measured, in its (image) order
    assert all(abs(a - b) <= 0.05 + 1e-9 for a, b in zip(frame.percentages, detection.percentages, strict=True))
    board = vision.board_values(frame.percentages, camera.view())
    *earlier, last = scene.person_cells
    moves = vision.percent_process(board, scene.robot_cells, earlier)
    assert moves.new == last and set(moves.cells) == set(scene.person_cells)
