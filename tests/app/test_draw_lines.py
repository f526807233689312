"""Fig. 3.19: two lines parallel to X on millimetre paper, their parallelism and spacing measured on the ink."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from ttt_sm.app.drawing import DrawError, DrawSession, _lines_geometry, check_request
from ttt_sm.params import load_params

P = load_params()


@pytest.fixture(scope="module")
def lines(tmp_path_factory):
    session = DrawSession(P, seed=0)
    session.start()
    out = tmp_path_factory.mktemp("lines")
    return session.draw("lines", spacing=0.04, out_dir=out)


def test_the_two_lines_are_parallel_to_x_and_as_far_apart_as_asked(lines):
    assert lines.kind == "lines" and lines.ink_points > 500
    assert lines.rms_error_mm <= 0.3 and lines.longest_tail_mm <= 1.0
    assert all(abs(a) < 0.3 for a in lines.lines_angle_deg)
    assert lines.lines_parallel_deg < 0.05
    assert lines.lines_spacing_mm == pytest.approx(40.0, abs=0.3)
    # section 3.5's first comparison, point by point in time: the encoders trail the desired pen along the
    # line by the setpoint filters' delay (critically damped at 8 Hz: 2 / (2 pi 8 Hz) = 40 ms, 0.8 mm at 20 mm/s)
    lag_mm = lines.speed_mm_s * 2 / (2 * math.pi * P.control.setpoint_cutoff_hz)
    assert 0.5 * lag_mm < lines.desired_vs_fk_max_mm < 2 * lag_mm


def test_the_board_picture_is_on_millimetre_paper(lines):
    image = cv2.imread(lines.board_png)
    assert image is not None
    # the paper's lines: many pixels neither white nor the robot's dark ink, in a stripe without ink
    stripe = image[100:140, 100:-40]  # inside the axes, above the lines: paper only
    tinted = (stripe.min(axis=2) < 245) & (stripe.max(axis=2) > 150)
    assert tinted.mean() > 0.2  # a board picture without the paper: 0.01 (the field's dashed lines)


def test_the_measurement_reads_a_known_slope_and_spacing():
    x = np.linspace(-0.05, 0.05, 400)
    slope = math.tan(math.radians(0.5))
    ink = np.vstack([np.column_stack([x, 0.23 + slope * x]), np.column_stack([x, 0.27 + 1.5 * slope * x])])
    m = _lines_geometry(ink, 0.0, 0.25)
    assert m is not None
    assert m["lines_angle_deg"] == pytest.approx((0.5, math.degrees(math.atan(1.5 * slope))), abs=1e-3)
    assert m["lines_parallel_deg"] == pytest.approx(0.25, abs=1e-3)
    assert m["lines_spacing_mm"] == pytest.approx(40.0 * math.cos(math.radians(0.625)), abs=1e-3)
    assert _lines_geometry(ink[:5], 0.0, 0.25) is None  # no ink, no line


@pytest.mark.parametrize("kind, spacing, named", [("X", 0.05, "spacing is for"), ("lines", 0.2, "spacing 200.0 mm"),
                                                  ("lines", 0.001, "spacing 1.0 mm")])
def test_a_bad_spacing_is_refused_naming_it(kind, spacing, named):
    with pytest.raises(DrawError, match=named):
        check_request(P, kind, 3, 3, None, None, spacing)
