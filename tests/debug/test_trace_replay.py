"""Trace to JSON Lines, diagrams of the active configuration, inputs, and replay from the seed."""

from __future__ import annotations

import json

import numpy as np
import pytest

from ttt_sm.app.robot import Robot
from ttt_sm.debug import DebugError, Debugger
from ttt_sm.debug.replay import differences
from ttt_sm.runtime.jsonable import jsonable
from ttt_sm.runtime.listeners import Trace


def _twin_arrays(d: Debugger) -> list[np.ndarray]:
    sim = d.robot.sim  # the whole memory of both compiled steps, to check "bit for bit" past the public API
    return [a.copy() for a in sim.state_arrays()]


def test_trace_round_trips_through_json_lines(dbg: Debugger, tmp_path):
    dbg.add_breakpoint("enter DriveInit1.go_park")
    dbg.run(20.0)
    path = dbg.save_trace(tmp_path / "trace.jsonl")
    lines = path.read_text().splitlines()
    assert len(lines) == len(dbg.trace.records) == 3
    first = json.loads(lines[0])
    assert {"tick", "time_s", "chart", "source", "target", "trigger", "data"} <= set(first)
    assert Trace.read_jsonl(path) == dbg.trace.records
    last = dbg.trace.records[-1]
    assert (last.source, last.target, last.trigger) == ("turn_back", "go_park", "tick")
    # The data snapshot is taken after the transition, in the tick the debugger stopped at.
    assert last.data == jsonable(dbg.robot.chart("DriveInit1").snapshot())


def test_replay_reaches_the_identical_state_bit_for_bit(dbg: Debugger):
    dbg.add_breakpoint("enter DriveInit1.turn_back")
    stop = dbg.run(20.0)
    tick = stop.chart_ticks
    before, arrays = dbg.fingerprint(), _twin_arrays(dbg)
    dbg.tick(400)
    result = dbg.replay(tick)
    assert result.identical is True and result.differences == ()
    assert list(differences(before, dbg.fingerprint())) == []
    assert all(np.array_equal(a, b) for a, b in zip(arrays, _twin_arrays(dbg), strict=True))
    # The trace was recorded anew, the same.
    assert [(r.tick, r.target) for r in dbg.trace.records] == [(1, "turn_fwd"), (tick, "turn_back")]


def test_replay_re_applies_inputs_at_their_step_and_drops_later_ones(dbg: Debugger):
    dbg.tick(200)
    dbg.set_input("DriveInit1", "stop", "1")  # the drive halts ...
    dbg.tick(100)
    dbg.set_input("DriveInit1", "stop", False)  # ... and resumes where it was (history)
    stop = dbg.tick(50)
    assert (stop.transitions[0].source, stop.transitions[0].target) == ("stopped", "h")
    assert dbg.where()["DriveInit1"][:2] == ["run", "initialise"]
    dbg.set_input("DriveInit2", "index", "1", force=True)
    dbg.step(6)  # an even count of steps: the position is again just after a tick
    here, arrays = dbg.fingerprint(), _twin_arrays(dbg)
    here_tick = dbg.robot.chart_ticks
    assert [a.kind for a in dbg.actions] == ["set", "set", "force"]

    result = dbg.replay(here_tick)
    assert result.applied == 3 and result.dropped == 0 and result.identical is True
    assert list(differences(here, dbg.fingerprint())) == []
    assert all(np.array_equal(a, b) for a, b in zip(arrays, _twin_arrays(dbg), strict=True))
    assert dbg.forced == {("DriveInit2", "index"): True}

    result = dbg.replay(250, drop=True)  # before the second set and the force: those are dropped
    assert (result.applied, result.dropped, result.identical) == (1, 2, None)
    assert dbg.where()["DriveInit1"] == ["stopped"] and dbg.forced == {}
    assert dbg.robot.value("DriveInit1", "stop") is True


def test_replay_to_a_step_between_two_ticks(dbg: Debugger):
    dbg.tick(20)
    dbg.step()
    here = dbg.fingerprint()
    dbg.tick(5)
    result = dbg.replay_to_step(here["steps"])
    assert result.identical is True and dbg.robot.steps == dbg.steps_of_tick(20) + 1
    assert list(differences(here, dbg.fingerprint())) == []


def test_replay_after_the_robot_ran_needs_a_recipe(params):
    robot = Robot(params, seed=0)
    robot.control_step()
    d = Debugger(robot)
    with pytest.raises(DebugError, match="replay needs the robot's recipe"):
        d.replay(0)


def test_a_debugger_on_a_fresh_robot_reads_its_recipe_back(params):
    robot = Robot(params, seed=4, q_start=[0.5, 0.3, -0.4, 0.0], settle_s=0.3)
    d = Debugger(robot)
    d.tick(300)
    here = d.fingerprint()
    assert d.replay(300).identical is True
    assert list(differences(here, d.fingerprint())) == [] and d.robot is not robot


def test_replay_with_posted_events(lamp_dbg: Debugger):
    lamp_dbg.tick(3)
    lamp_dbg.post("Lamp", "press")
    lamp_dbg.tick(2)
    here = lamp_dbg.fingerprint()
    assert here["charts"]["Lamp"]["active"] == ["lit"]
    result = lamp_dbg.replay(5)
    assert result.identical is True and list(differences(here, lamp_dbg.fingerprint())) == []
    lamp_dbg.replay(3)  # the press was at tick 3's position: still applied, not yet handled
    assert lamp_dbg.robot.chart("Lamp").pending_events == [("press", {})]


def test_inputs_errors(dbg: Debugger):
    with pytest.raises(DebugError, match="DriveInit1 has no datum 'stp' \\(did you mean 'stop'\\?\\)"):
        dbg.set_input("DriveInit1", "stp", "1")
    with pytest.raises(DebugError, match="DriveInit1.stop is a flag: give 1 or 0"):
        dbg.set_input("DriveInit1", "stop", "maybe")
    with pytest.raises(DebugError, match="DriveInit1 has no input 'pos_out'"):
        dbg.set_input("DriveInit1", "pos_out", "1")
    with pytest.raises(DebugError, match="no transition handles event 'stop'"):
        dbg.post("DriveInit1", "stop")
    with pytest.raises(DebugError, match="is not forced"):
        dbg.release("DriveInit1", "stop")
    assert dbg.actions == []
    assert dbg.set_input("DriveInit1", "pos_in", "90deg") == pytest.approx(np.pi / 2)


@pytest.mark.parametrize("suffix, marker", [
    (".dot", "filled"), (".svg", "<svg"), (".md", "class turn_back active")])
def test_diagram_of_the_active_configuration(dbg: Debugger, tmp_path, suffix, marker):
    dbg.add_breakpoint("enter DriveInit1.turn_back")
    dbg.run(20.0)
    path = dbg.diagram("DriveInit1", tmp_path / f"d1{suffix}")
    assert marker in path.read_text()
    with pytest.raises(DebugError, match="unknown extension '.txt'"):
        dbg.diagram("DriveInit1", tmp_path / "d1.txt")
