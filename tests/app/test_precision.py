"""The staircase of thesis section 3.5 on the twin: the thesis' findings and ours, asserted (docs/precision.md).

Short staircases (one or two stairs) keep the default tier cheap; the full
staircases of figs. 3.15-3.18 run under ``soak``.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from ttt_sm.app.precision import (
    AXES,
    PrecisionError,
    StaircaseSpec,
    run_staircase,
    staircase_poses,
)
from ttt_sm.cli import main
from ttt_sm.twin.sensor import SensorMount


@pytest.fixture(scope="module")
def thesis_big(params):
    """The thesis preset's big staircases along Z and X, two stairs each."""
    return {axis: run_staircase(params, axis, "big", "thesis", count=2) for axis in ("z", "x")}


def test_the_staircase_holds_each_stair_for_its_time_after_an_approach():
    spec = StaircaseSpec.of("z", "small", count=3, hold_s=1.0)
    poses, first, ticks = staircase_poses(spec, (0.16, 0.12, 0.06, 0.0), 0.002)
    assert np.allclose(poses[first - 1, :3], spec.start)
    assert ticks[1] - ticks[0] == 500
    levels = poses[ticks, 2]
    assert np.allclose(np.diff(levels), 0.0005)
    step = np.linalg.norm(np.diff(poses[:first, :3], axis=0), axis=1)
    assert step.max() <= 0.05 * 0.002 + 1e-12  # the approach moves at 5 cm/s at most


def test_a_staircase_that_leaves_the_sensors_range_is_refused():
    with pytest.raises(PrecisionError, match="range"):
        StaircaseSpec.of("x", "big", count=9)


def test_with_the_thesis_tuning_fk_and_sensor_are_nearly_identical(thesis_big):
    for r in thesis_big.values():
        assert r.sensor_out_of_range == 0
        for total, lengths, rest in zip(*(r.errors[k] for k in ("fk_vs_sensor", "lengths", "clearance")),
                                        strict=True):
            assert abs(rest.static_mm) <= r.clearance_bound_mm
            assert abs(total.static_mm) <= r.clearance_bound_mm + abs(lengths.static_mm)
            assert total.static_mm == pytest.approx(lengths.static_mm + rest.static_mm, abs=2e-4)
        # the differences come from the clearance and the deflection: not nothing either
        assert r.summary["clearance"]["max_static_mm"] > 0.01


def test_the_link_lengths_as_built_show_apart_from_the_clearance(params, thesis_big):
    # the packaged arm is built 0.1 mm off its measured lengths: FK of the encoders misses by that much
    assert params.as_built is not None and params.as_built != params.geometry
    for r in thesis_big.values():
        assert 0.001 < r.summary["lengths"]["max_static_mm"] < 0.3
    exact = run_staircase(replace(params, as_built=None), "z", "big", "thesis", count=1, hold_s=1.0)
    assert exact.summary["lengths"]["max_static_mm"] == 0.0
    assert exact.summary["clearance"]["max_static_mm"] == pytest.approx(
        thesis_big["z"].summary["clearance"]["max_static_mm"], abs=0.01)


def test_with_the_thesis_tuning_big_steps_leave_a_big_dynamic_and_a_small_static_error(thesis_big):
    for r in thesis_big.values():
        for e in r.errors["desired_vs_fk"]:
            assert e.dynamic_mm > 1.0  # of a 10 mm stair: the controllers lag
            assert abs(e.static_mm) < 0.02  # the controllers and IK leave micrometres at rest
            assert e.dynamic_mm > 50 * abs(e.static_mm)


def test_with_the_thesis_tuning_the_dynamic_error_is_larger_along_x_than_along_z(thesis_big):
    z, x = (thesis_big[a].summary["desired_vs_fk"]["max_dynamic_mm"] for a in ("z", "x"))
    assert x > 1.1 * z


@pytest.mark.parametrize("axis", AXES)
def test_with_our_tuning_the_static_error_against_the_sensor_is_below_a_tenth_of_a_millimetre(params, axis):
    r = run_staircase(params, axis, "big", "ours", count=1, hold_s=1.0)
    (e,) = r.errors["desired_vs_sensor"]
    assert e.static_mm is not None and abs(e.static_mm) <= 0.1


def test_a_sensor_out_of_range_reads_null_not_a_clipped_value(params):
    far = SensorMount(origin=(0.0, 0.25, -0.5), beam=(0.0, 0.0, 1.0))  # the tool is 53 cm away
    r = run_staircase(params, "z", "small", "ours", count=1, hold_s=0.6, mount=far)
    assert r.sensor_out_of_range == r.samples
    assert np.isnan(r.series["sensor"]).all()
    rep = r.report()
    assert rep["errors"]["fk_vs_sensor"][0]["static_mm"] is None
    assert rep["errors"]["desired_vs_fk"][0]["static_mm"] is not None


def test_the_command_prints_the_three_comparisons_and_writes_the_figure(capsys, tmp_path):
    code = main(["precision", "staircase", "--axis", "y", "--steps", "small", "--count", "1", "--hold", "0.8",
                 "--json", "--out", str(tmp_path)])
    assert code == 0
    rep = json.loads(capsys.readouterr().out)
    assert set(rep["errors"]) == {"desired_vs_fk", "fk_vs_sensor", "desired_vs_sensor", "lengths", "clearance"}
    assert rep["thesis_figure"] is None and rep["tuning"] == "ours"
    png = tmp_path / "staircase_y_small_ours.png"
    assert rep["plot"] == str(png) and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    samples = json.loads((tmp_path / "staircase_y_small_ours.json").read_text())
    assert len(samples["sensor_m"]) == len(samples["t_s"]) == rep["samples"]
    assert all(v is None or math.isfinite(v) for v in samples["sensor_m"])


def test_the_command_refuses_too_many_stairs_in_one_line(capsys, tmp_path):
    assert main(["precision", "staircase", "--steps", "big", "--count", "12", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--count" in err[0]


@pytest.mark.soak
@pytest.mark.parametrize("axis", ("z", "x"))
@pytest.mark.parametrize("steps", ("small", "big"))
def test_the_full_staircases_of_figs_3_15_to_3_18_keep_the_findings(params, axis, steps):
    thesis = run_staircase(params, axis, steps, "thesis")
    ours = run_staircase(params, axis, steps, "ours")
    for e in thesis.errors["clearance"]:
        assert abs(e.static_mm) <= thesis.clearance_bound_mm
    for e in ours.errors["desired_vs_sensor"]:
        assert abs(e.static_mm) <= 0.1
    # overall, our loops follow the stairs more closely (desired vs FK also holds ours' gear-play feed-forward)
    assert thesis.summary["desired_vs_sensor"]["max_dynamic_mm"] > ours.summary["desired_vs_sensor"]["max_dynamic_mm"]
