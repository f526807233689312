"""The parameter file: loads, converts units, and rejects bad files clearly."""

import math
import tomllib
from importlib import resources

import pytest

from ttt_sm.params import ParameterError, load_params, parse_params


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
