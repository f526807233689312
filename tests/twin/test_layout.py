"""The layout tables (twin/layout.py) and the formulas written once: what the compiled steps and plain Python share."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ttt_sm import params as params_module
from ttt_sm.app import _monitor_layout
from ttt_sm.params import load_params
from ttt_sm.twin import _cascade, _plant, layout
from ttt_sm.twin.gains import setpoint_filter_row
from ttt_sm.twin.plant import gravity_coefficients, gravity_torques

P = load_params()


@pytest.mark.parametrize("b", [*layout.BLOCKS, _monitor_layout.OUT, _monitor_layout.M, _monitor_layout.IX,
                               _monitor_layout.SRC], ids=lambda b: b.prefix)
def test_each_block_lays_its_fields_end_to_end_and_its_constants_are_plain_ints(b):
    module = _monitor_layout if b in (_monitor_layout.OUT, _monitor_layout.M, _monitor_layout.IX,
                                      _monitor_layout.SRC) else layout
    at = 0
    for f in b.fields:
        value = getattr(module, f"{b.prefix}_{f.name}")
        assert type(value) is int and value == at  # an int numba freezes, not an enum or a lookup
        at += f.width
    if b.counted:
        assert getattr(module, f"N_{b.prefix}") == at == b.size


def test_the_steps_index_with_the_tables_numbers():
    assert _cascade.CS_OFFSET == layout.CS_OFFSET and _plant.PS_Q == layout.PS_Q
    assert layout.CONTROLLER_WIDTH == max(layout.N_CP, layout.N_CS, layout.N_CG, layout.N_CGS, layout.N_ACT)
    # the servo's calibration is one run of fields, in the order of servo_duty's arguments, in cg and pg alike
    names = [n for n, _ in layout.SERVO_CALIBRATION]
    assert [layout.CONSTANTS[f"CG_{n}"] - layout.CG_SV_MIN for n in names] == list(range(len(names)))
    assert [layout.CONSTANTS[f"PG_{n}"] - layout.PG_SV_MIN for n in names] == list(range(len(names)))
    assert len(P.servo.calibration) == layout.SERVO_CALIBRATION_SIZE


def test_a_misspelt_or_doubled_name_is_an_error():
    with pytest.raises(AttributeError, match="no layout constant 'CS_OFSET'"):
        layout.CS_OFSET  # noqa: B018
    with pytest.raises(ValueError, match="CS_A defined twice"):
        layout.constants([layout.block("CS", "x", [("A", "")]), layout.block("CS", "y", [("A", "")])])
    with pytest.raises(ValueError, match="shadow"):
        layout.export({"CP_RPC": 0}, [layout.CP])


def test_changed_tables_drop_the_cached_machine_code_of_a_module(tmp_path):
    module = tmp_path / "_step.py"
    module.write_text("")
    cache = tmp_path / "__pycache__"
    cache.mkdir()
    stale = [cache / "_step.step-10.py311.nbi", cache / "_step.step-10.py311.1.nbc", cache / "_step.layout-0123"]
    other = cache / "_other.step-10.py311.nbi"
    for f in [*stale, other]:
        f.write_text("")
    layout.forget_stale_compilations(str(module))
    assert not any(f.exists() for f in stale) and other.exists()
    [mark] = cache.glob("_step.layout-*")
    fresh = cache / "_step.step-10.py311.nbi"  # compiled with these tables: kept from now on
    fresh.write_text("")
    layout.forget_stale_compilations(str(module))
    assert fresh.exists() and mark.exists()
    dep = tmp_path / "formula.py"
    dep.write_text("a = 1")
    layout.forget_stale_compilations(str(module), dep)  # another file it depends on: another mark
    assert not fresh.exists()


def test_the_setpoint_filter_is_one_function_compiled_and_plain():
    row = np.concatenate([[0.0], setpoint_filter_row(P.control.setpoint_cutoff_hz, P.control.dt)])
    rng = np.random.default_rng(1)
    for r, v, u in rng.normal(0.0, 1.0, (50, 3)):
        compiled = _cascade.setpoint_filter(row, 1, r, v, u)
        assert compiled == _cascade.setpoint_filter.py_func(row, 1, r, v, u)


def test_gravity_is_one_function_for_the_plant_step_and_python():
    g2, g23 = gravity_coefficients(P)
    rng = np.random.default_rng(2)
    for q2, q3 in rng.uniform(-2.0, 2.0, (50, 2)):
        compiled = _plant.gravity_torques(g2, g23, q2, q3)
        assert compiled == _plant.gravity_torques_py(g2, g23, q2, q3)
        assert tuple(gravity_torques(P, [0.0, q2, q3])[1:]) == compiled
    # the slopes are the torques' derivatives
    q2, q3, h = 0.4, -0.7, 1e-6
    c2, c23 = _plant.gravity_slopes(g2, g23, q2, q3)
    t2a, t3a = _plant.gravity_torques(g2, g23, q2 + h, q3)
    t2b, t3b = _plant.gravity_torques(g2, g23, q2 - h, q3)
    assert (t2a - t2b) / (2 * h) == pytest.approx(-c2 - c23, rel=1e-6)
    assert (t3a - t3b) / (2 * h) == pytest.approx(-c23, rel=1e-6)


def test_the_servo_calibration_compiled_is_params_own_formula():
    s = P.servo
    cg = np.zeros(layout.N_CG)
    cg[layout.CG_SV_MIN:layout.CG_SV_MIN + layout.SERVO_CALIBRATION_SIZE] = s.calibration
    pg = np.zeros(layout.N_PG)
    pg[layout.PG_SV_MIN:layout.PG_SV_MIN + layout.SERVO_CALIBRATION_SIZE] = s.calibration
    for a in np.linspace(s.min_rad - 0.3, s.max_rad + 0.3, 41):
        duty = _cascade.servo_duty_for_angle(a, cg)
        assert duty == s.duty_for_angle(a) == params_module.servo_duty(a, *s.calibration)
        assert _plant.servo_angle_for_duty(duty, pg) == s.angle_for_duty(duty)
    assert math.isnan(s.duty_for_angle(math.nan))
