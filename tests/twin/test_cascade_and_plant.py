"""The controller's step and the plant's step, each on its own, and their fusion in the simulated arm.

The simulated arm runs the cascade controller (``_cascade.cascade_step``:
encoder counts in, actuator commands out) and the plant
(``_plant.plant_step``: actuator commands in, motion and counts out) in one
compiled loop.  Here each runs alone: fed what the other produced inside
the fused loop, each reproduces the fused run bit for bit; and each does on
its own what it is for.
"""

from __future__ import annotations

import numpy as np
import pytest

from ttt_sm.twin import _cascade as C
from ttt_sm.twin import _plant as P
from ttt_sm.twin import layout
from ttt_sm.twin.cascade import CascadeController
from ttt_sm.twin.plant import Plant
from ttt_sm.twin.sim import ArmSim

POSE = (0.3, 0.6, -1.0, 0.1)
STEPS = 1500


def _moving(params, gains) -> ArmSim:
    """A homed twin with a move of every joint commanded (slow filters on for drive moves)."""
    sim = ArmSim(params, gains, seed=7, q0=POSE)
    sim.assume_initialised()
    q = sim.encoder_angles()
    sim.set_setpoints([q[0] + 0.4, q[1] - 0.2, q[2] + 0.3, 0.5], fr_sw=True)
    return sim


def test_the_controller_step_alone_reproduces_the_fused_loop(params, gains):
    fused = _moving(params, gains)
    trace = fused.run(STEPS)
    # the encoder counts the controller read before each fused step, from a twin stepped one at a time
    twin = _moving(params, gains)
    counts = []
    for _ in range(STEPS):
        counts.append(twin.plant.counts.copy())
        twin.step(1)
    # the controller alone, given the same setpoints and offsets, fed those counts
    ctrl = CascadeController(params, gains, servo_angle=POSE[3])
    for d, off in enumerate(twin.truth.offsets):
        ctrl.set_offset_estimate(d + 1, float(off))
    q = _moving(params, gains).encoder_angles()
    ctrl.set_setpoints([q[0] + 0.4, q[1] - 0.2, q[2] + 0.3, 0.5], fr_sw=True)
    duty, w_ref, r_f = [], [], []
    for c in counts:
        ctrl.step(c)
        duty.append([*ctrl.duty, ctrl.servo_duty])
        w_ref.append(ctrl.cs[:, layout.CS_W_REF].copy())
        r_f.append(ctrl.cs[:, layout.CS_R_F].copy())
    assert np.array_equal(np.array(duty), trace.duty)
    assert np.array_equal(np.array(w_ref), trace.speed_ref)
    assert np.array_equal(np.array(r_f), trace.setpoint_filtered[:, :3])
    assert np.abs(trace.duty[:, :3]).max() > 0.3  # it really drove the arm


def test_the_plant_step_alone_reproduces_the_fused_loop_from_its_duties(params, gains):
    fused = _moving(params, gains)
    trace = fused.run(STEPS)
    plant = Plant(params, np.array(POSE), np.random.default_rng(7))
    act = np.zeros(layout.N_ACT)
    act[layout.ACT_BRIDGE:layout.ACT_BRIDGE + 3] = 1.0
    q, counts = [], []
    for k in range(STEPS):
        act[layout.ACT_DUTY:layout.ACT_DUTY + 3] = trace.duty[k, :3]
        act[layout.ACT_SV_DUTY] = trace.duty[k, 3]
        plant.step(act)
        q.append([*plant.ps[:, layout.PS_Q], plant.pgs[layout.PGS_SV_Q]])
        counts.append(plant.counts.copy())
    assert np.array_equal(np.array(q), trace.q_true)
    assert plant.sensors() == fused.sensors()
    assert np.array_equal(plant.ints, fused.plant.ints)


def test_the_plant_alone_turns_a_duty_into_motion(params):
    d1 = params.drives[0]
    plant = Plant(params, np.array((0.0, 0.04, -0.08, 0.0)), np.random.default_rng(0))
    act = np.zeros(layout.N_ACT)
    act[layout.ACT_BRIDGE:layout.ACT_BRIDGE + 3] = 1.0  # bridges on at duty 0: drives 2 and 3 brake
    act[layout.ACT_DUTY] = 0.5
    act[layout.ACT_SV_DUTY] = params.servo.duty_for_angle(0.3)
    q0, c0 = float(plant.ps[0, layout.PS_Q]), int(plant.counts[0])
    for _ in range(1000):
        plant.step(act)
    # half the supply: the joint runs near half the no-load speed, less friction
    no_load_half = 0.5 * d1.supply_v / (d1.torque_constant * d1.gear_ratio)
    assert 0.8 * no_load_half < plant.ps[0, layout.PS_WQ] < no_load_half
    moved = float(plant.ps[0, layout.PS_Q]) - q0
    assert moved > 0.5 * no_load_half
    # the encoder counted the motor's turn (it sits on the motor side: within the clearance)
    assert (int(plant.counts[0]) - c0) * d1.rad_per_count == pytest.approx(moved, abs=d1.gear_clearance)
    # the servo went where its duty points, within its play
    assert plant.pgs[layout.PGS_SV_Q] == pytest.approx(0.3, abs=params.servo.clearance_rad)
    assert plant.t == pytest.approx(1.0)
    # bridge off: the current dies out and the drive coasts to a stop
    act[layout.ACT_BRIDGE] = 0.0
    for _ in range(2000):
        plant.step(act)
    assert plant.ps[0, layout.PS_I] == 0.0 and plant.ps[0, layout.PS_WQ] == pytest.approx(0.0, abs=1e-3)


def test_the_controller_alone_closes_no_loop_it_commands_with_a_step_of_delay(params, gains):
    ctrl = CascadeController(params, gains, servo_angle=0.0)
    still = np.zeros(3, dtype=np.int64)  # the arm does not move: counts stay 0
    ctrl.set_setpoints([0.2, 0.0, -0.2, 0.4])
    ctrl.step(still)
    # the duty computed in a step reaches the bridges in the next one
    assert np.array_equal(ctrl.duty, np.zeros(3))
    ctrl.step(still)
    assert ctrl.duty[0] > 0.0 and ctrl.duty[1] == 0.0 and ctrl.duty[2] < 0.0
    assert ctrl.servo_duty == params.servo.duty_for_angle(0.4)  # compiled and Python agree exactly
    for _ in range(300):
        ctrl.step(still)
    # the position error stays: the duty saturates, and anti-windup holds the integrators there
    assert ctrl.duty[0] == 1.0 and ctrl.duty[2] == -1.0
    held = ctrl.cs[:, [layout.CS_INT_POS, layout.CS_INT_SPD]].copy()
    for _ in range(300):
        ctrl.step(still)
    assert np.array_equal(ctrl.cs[:, [layout.CS_INT_POS, layout.CS_INT_SPD]], held)
    # bridge off: duty 0 and the off flag; closing again holds where the drive is
    ctrl.set_mode(1, layout.MODE_OFF)
    ctrl.step(still)
    ctrl.step(still)
    assert ctrl.act[layout.ACT_BRIDGE] == 0.0 and ctrl.duty[0] == 0.0 and ctrl.act[layout.ACT_BRIDGE + 1] == 1.0
    ctrl.set_mode(1, layout.MODE_CLOSED, hold_rad=0.0)
    ctrl.step(still)
    ctrl.step(still)
    assert ctrl.duty[0] == 0.0  # holding where it stands: nothing to correct
    assert ctrl.enabled() == (True, True, True)


def test_the_controller_and_the_plant_keep_their_own_memory(params, gains):
    sim = ArmSim(params, gains)
    cf, cm, pf, pi = sim.state_arrays()
    assert cf is sim.controller.buffer and pf is sim.plant.buffer
    # the controller's and the plant's memories are apart: no block of one is a view of the other
    assert not np.shares_memory(cf, pf) and not np.shares_memory(cm, pi)
    assert cf.shape == (layout.N_CR, layout.CONTROLLER_WIDTH) and pf.shape == (layout.N_PR, layout.PLANT_WIDTH)
    assert pi.shape == (3, layout.N_PI)


def test_the_fused_loop_is_compiled_for_the_steps_sources_it_runs():
    # numba's disk cache checks only the fused loop's own file; the loop closes over a
    # fingerprint of both steps' files, their layout and the servo's formula (params/values.py),
    # so an edit of any of them compiles the loop afresh
    import hashlib
    from pathlib import Path

    from ttt_sm.params import values
    from ttt_sm.twin import _kernel as K

    expected = hashlib.sha256(b"".join(Path(m.__file__).read_bytes() for m in (C, P, layout, values))).hexdigest()
    cells = [c.cell_contents for c in K.run_steps.py_func.__closure__]
    assert cells == [expected]
