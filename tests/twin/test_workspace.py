"""The reach check: a parameter file whose field the arm cannot work is refused where it is used.

The parameter file itself knows no kinematics (tests/test_params.py checks
its limits); :func:`ttt_sm.twin.workspace.load_arm`, which every ``ttt-sm``
command loads with, and the robot when it is built, check the field.
"""

from __future__ import annotations

import copy
import math
import re
import tomllib
from importlib import resources

import numpy as np
import pytest
from hypothesis import strategies as st

from fuzzing import fuzz
from ttt_sm.params import ParameterError, load_params, parse_params
from ttt_sm.twin.kinematics import UnreachableTargetError, ik_closed_form
from ttt_sm.twin.workspace import check_reach, load_arm, reach_problem


def write_variant(tmp_path, old: str, new: str, name: str = "arm.toml"):
    text = resources.files("ttt_sm.data").joinpath("arm.toml").read_text()
    assert old in text
    f = tmp_path / name
    f.write_text(text.replace(old, new, 1))
    return f


def test_the_packaged_field_is_within_reach():
    assert reach_problem(load_params()) is None
    check_reach(load_arm())


def test_a_field_out_of_reach_is_refused_at_load_naming_corner_tool_and_distance(tmp_path):
    f = write_variant(tmp_path, "field_center_y = 0.25", "field_center_y = 0.6")
    load_params(f)  # the numbers are fine: the parameter file knows no kinematics
    with pytest.raises(ParameterError) as info:
        load_arm(f)
    message = str(info.value)
    assert message.startswith(f"{f}: ")
    assert "the field's corner at cell (1, 1)" in message
    assert "with the pen vertical (phi = 0)" in message
    assert re.search(r": \d+ mm beyond what links L2 and L3 reach", message)
    assert "field_center_y" in message


def test_a_field_the_pen_reaches_but_the_sponge_does_not_is_refused(tmp_path):
    # the near edge at y = 45 mm: the pen reaches it, the sponge would need the servo past 150 deg
    f = write_variant(tmp_path, "field_center_y = 0.25", "field_center_y = 0.12")
    with pytest.raises(ParameterError, match=r"with the sponge down \(phi = 90 deg\): it needs q4 = 1[5-6]\d\.\d deg,"
                                             r" \d+\.\d deg beyond \[servo\] max_deg = 150\.0"):
        load_arm(f)


def test_every_command_loads_with_the_reach_check_and_the_robot_checks_it_too(tmp_path, capsys):
    from ttt_sm.app.robot import Robot
    from ttt_sm.cli import main

    f = write_variant(tmp_path, "field_center_y = 0.25", "field_center_y = 0.6")
    for argv in (["params"], ["draw", "X", "--json"], ["ik", "0", "250", "0"], ["tune"], ["init", "--starts", "1"]):
        assert main(["--params", str(f), *argv]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "is out of reach with the pen vertical" in err, err
    with pytest.raises(ParameterError, match="out of reach"):
        Robot(load_params(f))




# -- fuzz: what passes the check, the arm reaches ------------------------------------------


DOC = tomllib.loads(resources.files("ttt_sm.data").joinpath("arm.toml").read_text())
_KEYS = [("board", "field_center_x"), ("board", "field_center_y"), ("board", "field_size"), ("board", "surface_z"),
         ("geometry", "L2"), ("geometry", "L3"), ("geometry", "L4"), ("geometry", "l_f"), ("sponge", "offset"),
         ("servo", "max_deg"), ("servo", "min_deg")]
#: Slack of the promise between the grid points the check solves for (15 mm apart), rad.
BETWEEN_GRID_POINTS_RAD = math.radians(1.0)


def checked_arm_reaches_its_field(changes, point) -> None:
    doc = copy.deepcopy(DOC)
    for (table, key), factor in changes:
        doc[table][key] = doc[table][key] * factor
    try:
        params = parse_params(doc, "fuzz.toml")
        check_reach(params)
    except ParameterError as exc:
        assert exc.args[0].startswith("fuzz.toml") and "\n" not in str(exc)
        return
    u, v, lift, sponge = point
    x0, x1, y0, y1 = params.board.field_bounds()
    phi, z0 = (math.pi / 2, params.board.surface_z + params.sponge.offset) if sponge else (0.0, params.board.surface_z)
    try:
        q = ik_closed_form((x0 + u * (x1 - x0), y0 + v * (y1 - y0), z0 + lift, phi), params.geometry)
    except UnreachableTargetError as exc:
        raise AssertionError(f"the check passed, but {exc}") from None
    slack = BETWEEN_GRID_POINTS_RAD
    assert np.all(q >= np.array(params.joint_min) - slack) and np.all(q <= np.array(params.joint_max) + slack)


test_what_passes_the_check_the_arm_reaches, test_what_passes_the_check_the_arm_reaches_soak = fuzz(
    st.lists(st.tuples(st.sampled_from(_KEYS), st.floats(0.5, 1.6)), min_size=1, max_size=3),
    st.tuples(st.floats(0, 1), st.floats(0, 1), st.floats(0, 0.05), st.booleans()), quick=150, soak=5000)(
        checked_arm_reaches_its_field)
