"""The pictures of what the detector saw: the overlay says what its colours are, without hiding the field."""

from __future__ import annotations

import numpy as np

from ttt_sm.vision import detect
from ttt_sm.vision.bench import photo
from ttt_sm.vision.pictures import OVERLAY_LEGEND, legend_box, overlay


def test_the_overlay_carries_a_legend_beside_the_field(params):
    _, cam = photo(params, 1003)
    image = cam.frame()
    det = detect(image)
    with_legend, without = overlay(image, det), overlay(image, det, legend=False)
    assert with_legend.shape == image.shape
    x0, y0, x1, y1 = legend_box(image.shape, det.grid.corners)
    fx0, fy0 = det.grid.corners.min(axis=0)
    fx1, fy1 = det.grid.corners.max(axis=0)
    assert x1 <= fx0 or x0 >= fx1 or y1 <= fy0 or y0 >= fy1  # it hides none of the field
    # the legend is the only difference, and it is a white box with a line of text per colour
    changed = np.any(with_legend != without, axis=2)
    ys, xs = np.nonzero(changed)
    assert ys.min() >= y0 and ys.max() <= y1 and xs.min() >= x0 and xs.max() <= x1
    box = with_legend[y0 + 2:y1 - 1, x0 + 2:x1 - 1]
    assert np.mean(np.all(box == 255, axis=2)) > 0.7
    rows_with_ink = np.flatnonzero(np.any(np.any(box != 255, axis=2), axis=1))
    runs = np.count_nonzero(np.diff(rows_with_ink) > 1) + 1  # bands of text, one per line
    assert runs == len(OVERLAY_LEGEND)
    # each colour of the legend is drawn in it
    for colour, _, _ in OVERLAY_LEGEND:
        assert np.any(np.all(box == colour, axis=2)), colour


def test_the_legend_moves_to_the_corner_the_field_leaves_free():
    corners_top_left = np.array([[10.0, 10.0], [300.0, 10.0], [300.0, 200.0], [10.0, 200.0]])
    x0, y0, _, _ = legend_box((480, 640, 3), corners_top_left)
    assert x0 > 300 or y0 > 200
