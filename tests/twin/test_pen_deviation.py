"""The pen's deviation in its holder, eqs. 3.1-3.13 of thesis section 3.3.2, computed and checked."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest

from ttt_sm.twin.whiteboard import TIP_DEVIATION_PER_CLEARANCE
from ttt_sm.twin.whiteboard.pen_deviation import THESIS_CLEARANCE_M, THESIS_HOLDER, pen_deviation


def test_the_thesis_holder_gives_the_printed_alpha_and_deviation():
    d = pen_deviation(THESIS_HOLDER)
    assert d.alpha_rad == pytest.approx(6.179e-3, abs=1e-8)  # eq. 3.11
    assert d.deviation_m == pytest.approx(0.35e-3, abs=1e-9)  # eq. 3.13
    # eq. 3.10 as printed (L3 where L2 belongs, small angle): the typo costs 2e-7 rad
    assert d.alpha_eq_3_10_rad == pytest.approx(d.alpha_rad, abs=1e-6)
    assert d.alpha_eq_3_10_rad != d.alpha_rad


def test_the_tilt_touches_the_bore_at_both_ends():
    h = THESIS_HOLDER
    a = pen_deviation(h).alpha_rad
    # eq. 3.4, the geometry before any squaring
    assert h.length_m / 2 * math.sin(a) == pytest.approx(h.bore_radius_m * math.cos(a) - h.pen_radius_m, abs=1e-15)


def test_more_clearance_lets_the_pen_deviate_more_and_none_is_refused():
    h = THESIS_HOLDER
    wider = replace(h, bore_radius_m=h.bore_radius_m + 0.1e-3)
    assert pen_deviation(wider).deviation_m > pen_deviation(h).deviation_m
    with pytest.raises(ValueError, match="narrower than the bore"):
        pen_deviation(replace(h, bore_radius_m=h.pen_radius_m))


def test_the_whiteboard_drags_the_tip_by_the_computed_deviation():
    assert TIP_DEVIATION_PER_CLEARANCE * THESIS_CLEARANCE_M == pen_deviation(THESIS_HOLDER).deviation_m
