"""The parameter file: loads, converts units, and rejects bad files clearly."""

import math
import re
import tomllib
from importlib import resources
from pathlib import Path

import pytest

from ttt_sm.params import LIMITS, ParameterError, load_params, parse_params


def default_doc() -> dict:
    return tomllib.loads(resources.files("ttt_sm.data").joinpath("arm.toml").read_text())


def test_default_file_loads_in_si_units():
    p = load_params()
    assert p.control.dt == pytest.approx(0.001)
    assert p.control.chart_dt == pytest.approx(0.002)
    assert p.board.cell_size == pytest.approx(0.03)
    # degrees in the file, radians inside
    assert p.drives[0].limit_max_rad == pytest.approx(math.radians(170.0))
    assert p.servo.rate_rad_s == pytest.approx(math.radians(400.0))
    assert p.joint_min[3] == p.servo.min_rad


def test_the_arm_is_built_a_tenth_of_a_millimetre_off_its_measured_lengths():
    p = load_params()
    assert p.as_built is not None and p.true_geometry == p.as_built
    for name in ("L1", "L2", "L3", "L4", "l_f"):
        assert abs(getattr(p.as_built, name) - getattr(p.geometry, name)) == pytest.approx(1e-4)
    doc = default_doc()
    del doc["as_built"]
    exact = parse_params(doc, "exact.toml")
    assert exact.as_built is None and exact.true_geometry == exact.geometry


def test_encoder_resolution_follows_gear_and_counts():
    d = load_params().drives[0]
    assert d.rad_per_count == pytest.approx(2 * math.pi / (d.encoder_counts * d.gear_ratio))


def test_servo_duty_round_trip_and_clipping():
    s = load_params().servo
    for a in (s.min_rad, 0.0, 1.0, s.max_rad):
        assert s.angle_for_duty(s.duty_for_angle(a)) == pytest.approx(a)
    assert s.angle_for_duty(0.0) == s.min_rad
    assert s.angle_for_duty(1.0) == s.max_rad


def test_board_zone():
    b = load_params().board
    assert b.in_zone(b.field_center_x, b.field_center_y, b.surface_z + 0.01)
    assert not b.in_zone(b.field_center_x, b.field_center_y, b.surface_z + b.zone_clearance + 0.01)
    assert not b.in_zone(b.field_center_x, -0.2, b.surface_z)


@pytest.mark.parametrize("mutate, message", [
    (lambda d: d["geometry"].pop("L2"), r"\[geometry\] is missing L2"),
    (lambda d: d["geometry"].update(L2="long"), r"\[geometry\] L2 must be a number"),
    (lambda d: d["geometry"].update(L2=-0.1), r"\[geometry\] L2 must be positive"),
    (lambda d: d["drive"]["2"].update(gear_ratio=0), r"\[drive.2\] gear_ratio must be positive"),
    (lambda d: d["drive"]["3"].update(index_deg=90.0), r"\[drive.3\] index_deg must lie between"),
    (lambda d: d["drive"].pop("3"), r"exactly the tables \[drive.1\]"),
    (lambda d: d["servo"].update(wobble=1), r"\[servo\] has an unknown key 'wobble'"),
    (lambda d: d.update(extra={}), r"unknown section\(s\) extra"),
    (lambda d: d["control"].update(chart_divider=2.5), r"chart_divider must be an integer"),
    (lambda d: d["as_built"].update(L3=0.21), r"\[as_built\] L3 = 0.21 m lies 10.0 mm from \[geometry\] L3"),
    (lambda d: d["as_built"].pop("l_f"), r"\[as_built\] is missing l_f"),
    (lambda d: d["tuning"].update(preset="fast"), r"\[tuning\] preset must be one of ours, thesis"),
])
def test_bad_documents_name_section_and_key(mutate, message):
    doc = default_doc()
    mutate(doc)
    with pytest.raises(ParameterError, match=message):
        parse_params(doc, "my.toml")


def test_bad_files_name_the_file(tmp_path):
    missing = tmp_path / "nope.toml"
    with pytest.raises(ParameterError, match="nope.toml: cannot read"):
        load_params(missing)
    broken = tmp_path / "broken.toml"
    broken.write_text("[geometry\nL1 = ")
    with pytest.raises(ParameterError, match="broken.toml: not valid TOML"):
        load_params(broken)


def test_a_copy_of_the_default_file_loads_from_disk(tmp_path):
    f = tmp_path / "arm.toml"
    f.write_text(resources.files("ttt_sm.data").joinpath("arm.toml").read_text())
    p = load_params(f)
    assert p.source == str(f)
    assert p.geometry == load_params().geometry


# --------------------------------------------------------------------------- physics, not only types
# Each of these files used to load; a run with it then drew nothing, overflowed or divided by zero.

def write_variant(tmp_path, old: str, new: str, name: str = "arm.toml"):
    text = resources.files("ttt_sm.data").joinpath("arm.toml").read_text()
    assert old in text
    f = tmp_path / name
    f.write_text(text.replace(old, new, 1))
    return f


def line_of(path, start: str) -> int:
    return next(n for n, line in enumerate(path.read_text().splitlines(), 1) if line.startswith(start))


def test_every_documented_limit_is_checked_and_named_with_its_line(tmp_path):
    f = write_variant(tmp_path, "gear_play_compensation = 1.0", "gear_play_compensation = 5")
    with pytest.raises(ParameterError) as info:
        load_params(f)
    line = line_of(f, "gear_play_compensation")
    assert str(info.value).startswith(f"{f}:{line}: [control] gear_play_compensation = 5: outside 0..1")


@pytest.mark.parametrize("old, new, message", [
    ("L2 = 0.22", "L2 = 1e308", r"\[geometry\] L2 = 1e\+308: outside 0.01..2"),
    ("L2 = 0.22", "L2 = 1" + "0" * 400, r"\[geometry\] L2 must be finite, got 1000000000"),
    ("L2 = 0.22", "L2 = inf", r"\[geometry\] L2 must be finite, got inf"),
    ("pulse_max_s = 0.0025", "pulse_max_s = 0.0005", r"\[servo\] needs pulse_min_s < pulse_max_s <= period_s"),
    ("rate_hz = 1000.0", "rate_hz = 10", r"\[control\] rate_hz = 10: outside 700..1250"),
    ("speed_filter_hz = 150.0", "speed_filter_hz = 500.0", r"speed_filter_hz = 500 Hz must lie below the Nyquist"
                                                          r" frequency of rate_hz = 1000 Hz"),
    ("outer_crossover_hz = 6.0", "outer_crossover_hz = 60.0", r"outer_crossover_hz \(60 Hz\) must lie below"),
    ("min_deg = -120.0", "min_deg = -1000.0", r"\[servo\] min_deg = -1000: outside -360..360 deg"),
    ("cells = 5", "cells = 6", r"\[board\] cells = 6: outside 5..5"),
    ("width = 0.30", "width = 0.10", r"\[board\] width \(0.1 m\) is smaller than the field"),
    ("encoder_counts = 2000     # counts", "encoder_counts = 0     # counts",
     r"\[drive.1\] encoder_counts must be positive, got 0: outside"),
])
def test_values_that_would_overflow_or_divide_by_zero_are_refused(tmp_path, old, new, message):
    f = write_variant(tmp_path, old, new)
    with pytest.raises(ParameterError, match=message) as info:
        load_params(f)
    assert str(info.value).startswith(f"{f}:")
    assert len(str(info.value)) < 300 and "\n" not in str(info.value)


def test_the_tuner_s_error_is_a_parameter_error_naming_the_file(tmp_path):
    from ttt_sm.twin.tuning import TuningError, design_gains

    # within every limit, but no speed loop keeps its margins at 400 Hz behind a 1 Hz speed filter
    f = write_variant(tmp_path, "inner_crossover_hz = 40.0", "inner_crossover_hz = 400.0")
    f.write_text(f.read_text().replace("speed_filter_hz = 150.0", "speed_filter_hz = 1.0"))
    params = load_params(f)
    with pytest.raises(ParameterError, match=rf"^{re.escape(str(f))}: drive 1: no speed PI keeps") as info:
        design_gains(params)
    assert isinstance(info.value, TuningError)


@pytest.mark.parametrize("content, message", [
    (b"\x00\xff\xfe\x01binary", r":1: not UTF-8 text \(byte 0xff at column 2\)"),
    ("[geometry]\nL1 = 0.3 # café\n".encode("latin-1"), r":2: not UTF-8 text \(byte 0xe9 at column 15\)"),
    (b"[geometry]\nL1 = 0.3\x00\n", r": not valid TOML"),
    (b"a = " + b"[" * 5000 + b"]" * 5000, r": not valid TOML \(arrays or tables nested too deeply\)"),
    (b"# " + b"x" * 1_000_001, r": more than 1000000 bytes: not a parameter file"),
])
def test_files_that_are_not_parameter_files_get_one_line(tmp_path, content, message):
    f = tmp_path / "p.toml"
    f.write_bytes(content)
    with pytest.raises(ParameterError, match=message) as info:
        load_params(f)
    assert str(info.value).startswith(str(f))


def test_a_device_that_never_ends_is_read_no_further_than_the_limit():
    with pytest.raises(ParameterError, match=r"^/dev/zero: (more than|not valid)"):
        load_params("/dev/zero")


def test_a_huge_unknown_key_is_not_formatted_whole():
    doc = default_doc()
    doc["servo"]["w" * 100_000] = 1
    with pytest.raises(ParameterError) as info:
        parse_params(doc, "my.toml")
    assert len(str(info.value)) < 200


def test_docs_parameters_md_lists_exactly_the_limits_the_loader_checks():
    doc = (Path(__file__).resolve().parents[1] / "docs" / "parameters.md").read_text()
    section = doc.split("## Limits checked at load", 1)[1]
    documented: dict[str, tuple[float, float]] = {}
    for row in re.findall(r"^\| (`\[.+?)\|(.+?)\|", section, re.M):
        names, limits = row
        table = re.match(r"`\[(\S+)\]", names).group(1).replace("drive.N", "drive")
        lo, hi = (float(v) for v in limits.split(".."))
        for key in re.findall(r"(\w+)`", names):
            if key.endswith("_deg") or key.endswith("_deg_s"):
                key, lo_si, hi_si = key.replace("_deg", "_rad"), math.radians(lo), math.radians(hi)
            else:
                lo_si, hi_si = lo, hi
            documented[f"{table}.{key}"] = (lo_si, hi_si)
    assert documented.keys() == LIMITS.keys()
    for name, (lo, hi) in LIMITS.items():
        assert documented[name] == (pytest.approx(lo), pytest.approx(hi)), name
