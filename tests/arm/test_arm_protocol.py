"""The Arm protocol: the simulated arm satisfies it, and the code typed on it reads nothing else.

The scheduler, the init charts' and the Control chart's wiring are typed on
:class:`ttt_sm.arm.Arm`.  Here they run on a wrapper that forwards the
protocol's members and raises on anything else (ground truth above all): the
robot still initialises and draws, bit for bit as on the bare simulated arm.
"""

from __future__ import annotations

import inspect
import math

import numpy as np
import pytest

from ttt_sm.app.robot import Robot
from ttt_sm.arm import Arm, Sensors
from ttt_sm.params import load_params
from ttt_sm.twin.sim import ArmSim

P = load_params()

#: Every member the protocol declares: methods, properties and the `dt` attribute.
MEMBERS = frozenset([n for n in vars(Arm) if not n.startswith("_")] + list(Arm.__annotations__))


class NotInProtocol(AttributeError):
    """Code typed on Arm reached for something the protocol does not offer."""


class ProtocolOnly:
    """An Arm that forwards the protocol's members to a simulated arm and refuses anything else."""

    def __init__(self, arm: ArmSim) -> None:
        self._arm = arm
        self.used: set[str] = set()

    def __getattr__(self, name: str) -> object:
        if name not in MEMBERS:
            raise NotInProtocol(f"{name!r} is not part of the Arm protocol")
        self.used.add(name)
        return getattr(self._arm, name)


def test_the_protocol_declares_what_the_scheduler_and_the_wiring_may_use():
    assert MEMBERS == {"dt", "t", "step", "set_setpoints", "servo_setpoint", "sensors", "encoder_angles",
                       "offset_estimates", "set_offset_estimate", "enabled", "set_enabled"}
    assert not MEMBERS & {"truth", "q_true", "true_angles", "true_offset", "assume_initialised"}


def _parameters(f: object) -> list[tuple[str, object, object]]:
    return [(p.name, p.kind, p.default) for p in inspect.signature(f).parameters.values()]  # type: ignore[arg-type]


def test_the_simulated_arm_satisfies_the_protocol_member_by_member():
    sim = ArmSim(P, seed=0)
    assert isinstance(sim, Arm)
    for name in MEMBERS - {"dt"}:
        declared = inspect.getattr_static(Arm, name)
        offered = inspect.getattr_static(ArmSim, name)
        assert isinstance(offered, property) == isinstance(declared, property), name
        if not isinstance(declared, property):  # names, kinds and defaults (mypy checks the types)
            assert _parameters(offered) == _parameters(declared), name
    assert sim.dt == P.control.dt


def test_the_accessors_return_plain_numbers():
    sim = ArmSim(P, seed=2)
    sim.set_offset_estimate(3, -0.25)
    sim.set_setpoints([0.1, 0.2, -0.4, 0.3], fr_sw=True)
    sim.step(150)
    values = (sim.t, *sim.encoder_angles(), *sim.offset_estimates(), sim.servo_setpoint)
    assert all(type(v) is float for v in values)
    assert sim.offset_estimates()[2] == -0.25 and sim.servo_setpoint == 0.3
    assert sim.enabled() == (True, True, True)
    sim.set_enabled(2, False)
    assert sim.enabled() == (True, False, True)
    s = sim.sensors()
    assert isinstance(s, Sensors) and s.t == sim.t
    assert all(type(c) is int for c in s.counts) and all(type(i) is bool for i in s.index)


def test_the_wrapper_refuses_ground_truth():
    arm = ProtocolOnly(ArmSim(P, seed=0))
    assert isinstance(arm, Arm)
    for name in ("truth", "q_true", "true_angles", "assume_initialised", "q_encoder", "settle_unpowered"):
        with pytest.raises(NotInProtocol, match="not part of the Arm protocol"):
            getattr(arm, name)


def _robot_session(robot: Robot) -> list[float]:
    """Initialise, go to wait_1 with the field held back, draw an X in cell (3, 3); time marks."""
    marks = []
    assert robot.run_until(lambda: robot.initialised, 40.0)
    marks.append(robot.t)
    robot.control.Pl_fld = True
    assert robot.run_until(lambda: "wait_1" in robot.control.active_ids, 40.0)
    marks.append(robot.t)
    robot.control.row, robot.control.column, robot.control.symbol = 3, 3, 1
    robot.post("Control", "button")
    robot.chart_step()
    robot.chart_step()
    assert robot.run_until(lambda: "wait_1" in robot.control.active_ids, 120.0)
    marks.append(robot.t)
    return marks


def test_the_robot_initialises_and_draws_through_the_protocol_alone_bit_for_bit():
    bare = Robot(P, seed=4)
    sim = ArmSim(P, seed=4)
    wrapped = ProtocolOnly(sim)
    robot = Robot(P, seed=4, arm=wrapped, truth=sim.truth)  # the whiteboard alone sees the truth
    assert robot.sim is None and robot.arm is wrapped
    marks = _robot_session(robot)
    assert marks == _robot_session(bare)
    # the X is on the board, and both runs reached the very same state
    assert robot.board.cell_ink_fraction(3, 3) > 0.02
    assert robot.board.cell_ink_fraction(3, 3) == bare.board.cell_ink_fraction(3, 3)
    assert sim.truth.q.tolist() == bare.truth.q.tolist()
    assert sim.sensors() == bare.arm.sensors()
    # what the scheduler and the wiring used: the protocol's members, exercised
    assert {"t", "step", "set_setpoints", "sensors", "encoder_angles", "offset_estimates",
            "set_offset_estimate", "servo_setpoint"} <= wrapped.used


def test_without_ground_truth_the_robot_still_initialises_and_says_truth_is_unknown():
    sim = ArmSim(P, seed=1)
    robot = Robot(P, arm=ProtocolOnly(sim))
    assert robot.truth is None
    assert robot.run_until(lambda: robot.initialised, 40.0)
    signals = robot.signal_values()
    assert all(math.isnan(v) for v in signals["q_true"] + signals["tool_true"])
    assert signals["q_encoder"] == list(sim.encoder_angles())
    # the encoders now read the true joint angles (within the gear play): the init charts worked
    assert np.abs(np.array(signals["q_encoder"]) - sim.truth.q[:3]).max() < 0.01
    assert robot.board.ink_area_mm2() == 0.0  # nothing inks a board the robot cannot see
