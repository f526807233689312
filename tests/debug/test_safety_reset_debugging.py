"""The Safety chart's reset under the debugger: the new init and Control charts are watched as the old ones were.

:meth:`Robot.reinitialise` puts new drive-initialisation charts and a new
Control chart in the old ones' place.  The debugger (and through it the
cockpit) must go on seeing them: their transitions in the trace with the run's
chart ticks, breakpoints on them, the timeline, and the session's taps.
"""

from __future__ import annotations

from typing import Any

import pytest

from ttt_sm.debug.debugger import Debugger
from ttt_sm.faults.twin import FaultyArm
from ttt_sm.params import load_params
from ttt_sm.runtime.errors import TemporalLogicError
from ttt_sm.twin.sim import ArmSim


class Counter:
    """A listener a view adds (as the cockpit's session does): transitions per chart."""

    def __init__(self) -> None:
        self.taken: dict[str, int] = {}

    def after_transition(self, machine: Any) -> None:
        self.taken[machine.chart_name] = self.taken.get(machine.chart_name, 0) + 1


def test_after_a_reset_the_new_charts_are_traced_on_the_runs_clock_and_break() -> None:
    params = load_params()
    sim = ArmSim(params, seed=0)
    arm = FaultyArm(sim)
    dbg = Debugger.build(params, seed=0, arm=arm, truth=sim.truth)
    robot = dbg.robot
    counter = Counter()
    dbg.add_listener(counter)
    dbg.add_breakpoint("enter Control.field_pen_down")
    assert dbg.run(60).kind == "breakpoint"
    dbg.delete(None)
    dbg.step(300)
    arm.inject("motor_blocked", 2)
    assert dbg.run(1.0).kind == "timeout" and robot.tripped
    arm.clear()
    old_init = robot.charts["DriveInit1"]
    tick_reset = robot.chart_ticks
    counter.taken.clear()
    dbg.post("Safety", "reset")
    dbg.tick(2)
    new_init = robot.charts["DriveInit1"]
    assert new_init is not old_init and robot.safety.reinit
    # the new chart's clock goes on from the old one's
    assert abs(new_init.tick_count - robot.chart_ticks) <= 1
    # a breakpoint set on the Control chart now is one on the new Control chart: it hits
    bp = dbg.add_breakpoint("enter Control.wait_1")
    stop = dbg.run(60)
    assert stop.kind == "breakpoint" and stop.hits[0].breakpoint == bp.id
    assert robot.initialised and not robot.tripped
    after = [r for r in dbg.trace.records if r.tick is not None and r.tick > tick_reset]
    assert {r.chart for r in after} == {"DriveInit1", "DriveInit2", "DriveInit3", "Control", "Safety"}
    assert all(r.tick <= robot.chart_ticks for r in after)
    assert {"DriveInit1", "DriveInit2", "DriveInit3", "Control"} <= set(counter.taken)
    # the timeline: the old chart's state was left at the reset, the new chart's are on the run's ticks
    window = dbg.state_history.window("DriveInit1", robot.chart_ticks, params.control.chart_dt)
    assert all(iv.left is not None for iv in window.intervals if iv.entered < tick_reset)
    assert any(iv.entered > tick_reset and iv.state == "pass_pos" for iv in window.intervals)
    # the data watch reads the new charts
    assert dbg.chart("Control") is robot.control


def test_a_chart_clock_is_started_once_before_its_first_tick() -> None:
    params = load_params()
    dbg = Debugger.build(params, seed=0)
    chart = dbg.robot.charts["DriveInit1"]
    dbg.tick(3)
    with pytest.raises(TemporalLogicError, match="DriveInit1: its clock has run 3 ticks already"):
        chart.start_clock_at(100)
