"""Breakpoints hit at the exact chart tick, through the charts' listeners."""

from __future__ import annotations

import math
from typing import Any

import pytest

from ttt_sm.debug import DebugError, Debugger
from ttt_sm.debug.expr import parse_condition


def q1_deg(d: Debugger) -> float:
    return math.degrees(float(d.robot.truth.q[0]))


def test_break_on_entering_turn_back_stops_at_the_tick_the_hard_stop_was_detected(dbg: Debugger, params):
    bp = dbg.add_breakpoint("enter DriveInit1.turn_back")
    stop = dbg.run(20.0)

    chart = dbg.robot.chart("DriveInit1")
    assert stop.kind == "breakpoint"
    assert stop.breakpoint is not None and stop.breakpoint.breakpoint == bp.id
    assert stop.breakpoint.detail == "entered turn_back"
    # Exactly the tick that took the transition: no tick ran after it.
    record = dbg.trace.records[-1]
    assert (record.chart, record.source, record.target) == ("DriveInit1", "turn_fwd", "turn_back")
    assert record.tick == stop.breakpoint.tick == chart.tick_count == dbg.robot.chart_ticks
    assert chart.ticks_in("turn_back") == 0
    assert dbg.robot.steps == dbg.steps_of_tick(record.tick)  # right after the tick's control step
    assert "turn_back" in dbg.where()["DriveInit1"]
    # The drive stalled on its +170 deg hard stop: the twin's true angle is there.
    assert math.degrees(params.drives[0].limit_max_rad) == pytest.approx(170.0)
    assert q1_deg(dbg) == pytest.approx(170.0, abs=0.5)
    assert bp.hits == 1


def test_the_stop_is_the_first_control_step_at_which_the_state_is_active(dbg: Debugger, params):
    from ttt_sm.app.robot import Robot

    dbg.add_breakpoint("enter DriveInit1.turn_back")
    dbg.run(20.0)
    plain = Robot(params, seed=0)
    while "turn_back" not in plain.active("DriveInit1"):
        plain.control_step()
    assert plain.steps == dbg.robot.steps
    assert plain.truth.q.tolist() == dbg.robot.truth.q.tolist()


def test_exit_and_transition_breakpoints_hit_in_the_same_tick(dbg: Debugger):
    exit_bp = dbg.add_breakpoint("exit DriveInit1.turn_fwd")
    trans_bp = dbg.add_breakpoint("transition DriveInit1 turn_fwd->turn_back")
    any_bp = dbg.add_breakpoint("transition DriveInit1 *->go_park")
    stop = dbg.run(20.0)
    assert [h.breakpoint for h in stop.hits] == [exit_bp.id, trans_bp.id]
    assert {h.tick for h in stop.hits} == {dbg.robot.chart_ticks}
    assert stop.hits[1].detail == "turn_fwd -> turn_back"
    stop = dbg.run(20.0)  # on to the index: turn_back -> go_park
    assert [h.breakpoint for h in stop.hits] == [any_bp.id]
    assert dbg.trace.records[-1].target == "go_park"


def test_disabled_breakpoints_do_not_hit_and_deleted_ones_are_gone(dbg: Debugger):
    bp = dbg.add_breakpoint("enter DriveInit1.turn_back")
    dbg.disable(bp.id)
    assert dbg.run(4.0).kind == "timeout"
    assert "turn_back" in dbg.where()["DriveInit1"]  # passed it without stopping
    dbg.enable(bp.id)
    dbg.delete(bp.id)
    assert dbg.breakpoints == []
    with pytest.raises(DebugError, match="no breakpoint 1; breakpoints: none"):
        dbg.enable(1)


def test_condition_on_chart_data_hits_when_it_becomes_true(dbg: Debugger):
    bp = dbg.add_breakpoint("when DriveInit1.pos_Encoder > 1.0")
    stop = dbg.run(20.0)
    assert stop.kind == "breakpoint" and stop.hits[0].detail == "became true"
    tick = dbg.robot.chart_ticks
    assert dbg.robot.value("DriveInit1", "pos_Encoder") > 1.0
    # Still true, so it does not hit again: the run goes on to the timeout.
    assert dbg.run(0.2).kind == "timeout" and bp.hits == 1
    # One tick earlier it was not true yet.
    dbg.replay(tick - 1)
    assert dbg.robot.value("DriveInit1", "pos_Encoder") <= 1.0


def test_condition_on_signals_with_units_and_boolean_operators(dbg: Debugger):
    dbg.add_breakpoint("when q_true[1] > 90deg and not (DriveInit1.stop or t < 0.5)")
    stop = dbg.run(20.0)
    assert stop.kind == "breakpoint"
    assert q1_deg(dbg) > 90.0
    assert dbg.robot.t >= 0.5 and dbg.robot.value("DriveInit1", "index")


def test_event_breakpoint_on_tick_transitions_as_the_trace_names_them(dbg: Debugger):
    dbg.add_breakpoint("event DriveInit2.tick")
    stop = dbg.run(30.0)
    assert stop.kind == "breakpoint" and stop.hits[0].chart == "DriveInit2"
    last = [r for r in dbg.trace.records if r.chart == "DriveInit2"]
    assert len(last) == 1 and last[0].trigger == "tick" and last[0].tick == dbg.robot.chart_ticks
    assert last[0].source == "wait_ini1"


def test_event_breakpoint_on_a_posted_event_taken_or_not(lamp_dbg: Debugger):
    bp = lamp_dbg.add_breakpoint("event Lamp.reset")
    press = lamp_dbg.add_breakpoint("event Lamp.press")
    lamp_dbg.step(5)
    lamp_dbg.post("Lamp", "press")
    assert lamp_dbg.where()["Lamp"] == ["off"]  # handled at the next tick, not now
    stop = lamp_dbg.run(1.0)
    assert stop.kind == "breakpoint" and [h.breakpoint for h in stop.hits] == [press.id]
    assert stop.hits[0].detail == "press: off -> lit"
    assert lamp_dbg.where()["Lamp"] == ["lit"]
    lamp_dbg.tick(3)  # the lamp went out by itself
    assert lamp_dbg.where()["Lamp"] == ["off"]
    lamp_dbg.post("Lamp", "reset")  # nothing handles reset in `off`: it hits all the same
    stop = lamp_dbg.run(1.0)
    assert stop.kind == "breakpoint" and stop.hits[0].breakpoint == bp.id
    assert stop.hits[0].detail == "reset handled"
    assert len(stop.hits) == 1


@pytest.mark.parametrize("spec, message", [
    ("enter DriveInit1.turn_bak", "DriveInit1 has no state 'turn_bak' (did you mean 'turn_back'?)"),
    ("exit DriveInit9.turn_back", "no chart 'DriveInit9'"),
    ("enter DriveInit1", "break enter: expected Chart.state, got 'DriveInit1'"),
    ("transition DriveInit1 turn_fwd->pass_pos", "DriveInit1 has no transition turn_fwd->pass_pos"),
    ("transition DriveInit1 turn_fwd", "expected 'Chart source->target'"),
    ("event DriveInit1.stop", "DriveInit1 handles no event 'stop'"),
    ("when DriveInit1.pos_encoder > 1",
     "DriveInit1 has no datum 'pos_encoder' (did you mean 'pos_Encoder'?)"),
    ("when DriveInit1.pos_Encoder[1] > 1",
     "DriveInit1.pos_Encoder is a datum, not a list: write it without [1] (at column 1 of"),
    ("when DriveInit1.turn_back", "DriveInit1 has no datum 'turn_back'"),  # states are not data here
    ("when DriveInit1.pos_Encoder.x > 1",
     "one dot at most (Chart.name): DriveInit1.pos_Encoder is followed by '.' at column 23"),
    ("when DriveInit1.pos_Encoder >", "expected a number, a name or '(', found the end at column 25"),
    ("when DriveInit1.pos_Encoder > 1 )", "unexpected ')'; expected 'and', 'or', an operator or the end"
                                          " at column 28"),
    ("when DriveInit1.pos_Encoder > 1 ; 2", "unexpected character ';' at column 28"),
    ("when q_true > 1", "signal 'q_true' has 4 elements: pick one"),
    ("when q_true[0] > 1", "q_true[0] does not exist"),
    ("when pos_Encoder > 1", "no signal 'pos_Encoder' (chart data are written Chart.datum)"),
    ("when q_true[1] < 1 and q_tru[2] > 0",
     "no signal 'q_tru' (did you mean 'q_true'?); signals: t, "),
    ("when q_true[1] < 1 and q_tru[2] > 0", "(at column 19 of 'q_true[1] < 1 and q_tru[2] > 0')"),
    ("when __import__('os') > 1", "unknown function '__import__'; functions: abs, min, max at column 1"),
    ("when 1 < 2 furlongs", "unknown unit 'furlongs'"),
    ("when", "break when: what?"),
    ("watch x", "unknown breakpoint kind 'watch'"),
])
def test_bad_breakpoints_are_one_line_errors_naming_what_was_wrong(dbg: Debugger, spec, message):
    with pytest.raises(DebugError) as info:
        dbg.add_breakpoint(spec)
    assert message in str(info.value)
    assert "\n" not in str(info.value)
    assert dbg.breakpoints == []


class _Values:
    def __init__(self, **values):
        self.values = values

    def check_datum(self, chart, name):
        if f"{chart}.{name}" not in self.values:
            raise DebugError(f"no {chart}.{name}")

    def check_signal(self, name, index):
        if name not in self.values:
            raise DebugError(f"no {name}")

    def datum(self, chart, name):
        return self.values[f"{chart}.{name}"]

    def signal(self, name, index):
        value = self.values[name]
        return value if index is None else value[index - 1]


@pytest.mark.parametrize("text, expected", [
    ("C.x > 1", True), ("C.x > 1 and C.flag", False), ("C.x > 1 and not C.flag", True),
    ("C.flag or v[2] == -3", True), ("0 < C.x <= 2", True), ("0 < C.x < 1.5", False),
    ("C.x >= 2000mm", True), ("a == 90 deg", True), ("a > 89.9deg and a < 90.1deg", True),
    ("not (C.x > 1 or C.flag)", False), ("true and not false", True), ("C.flag == false", True),
    ("t < 5ms", True),
    # The scenario language's arithmetic, functions and constants mean the same here.
    ("-C.x < -1", True), ("C.x - 2 * v[1] == 0", True), ("abs(v[2]) == 3", True),
    ("max(v[1], v[2]) < min(C.x, 3)", True), ("C.flag == False or True", True),
])
def test_condition_grammar(text, expected):
    names = _Values(**{"C.x": 2.0, "C.flag": False, "v": [1, -3], "a": math.pi / 2, "t": 0.004})
    assert parse_condition(text, names).evaluate(names) is expected
    assert parse_condition(text, names).evaluate() is expected  # the names it was checked against


def test_a_condition_reads_the_names_it_is_given():
    condition = parse_condition("  C.x > 1  ", _Values(**{"C.x": 2.0}))
    assert condition.text == "C.x > 1"
    assert condition.evaluate() is True
    assert condition.evaluate(_Values(**{"C.x": 0.5})) is False


@pytest.mark.parametrize("text, message", [
    ("C.x < 1", "condition 'C.x < 1' cannot be evaluated: cannot compare: '<' not supported"),
    ("C.x + 1 > 0", "condition 'C.x + 1 > 0' cannot be evaluated: cannot compute '+'"),
    ("1 / C.zero > 0", "condition '1 / C.zero > 0' cannot be evaluated: cannot compute '/': division by zero"),
])
def test_values_that_cannot_be_compared_are_debug_errors(text, message):
    names = _Values(**{"C.x": [1, 2], "C.zero": 0})
    with pytest.raises(DebugError) as info:
        parse_condition(text, names).evaluate(names)
    assert message in str(info.value)


def test_an_empty_condition_says_what_to_write():
    with pytest.raises(DebugError, match="empty condition: write e.g. 'DriveInit1.pos_Encoder > 1.0'"):
        parse_condition("  ", _Values())


def test_breakpoints_on_a_junction_segment_and_on_a_local_event_hit_where_they_happen():
    """A transition breakpoint names a junction as the source of one way out of a decision; an event
    breakpoint hits on a local event an action broadcasts (it takes no transition of its own here)."""
    from statemachine import State

    from ttt_sm.debug.breakpoints import BreakListener, ChartIndex, parse_breakpoint
    from ttt_sm.runtime import Data, Junction, TickChart

    class Sorter(TickChart):
        inputs = (Data("size", "1", 0, "size of the request"),)
        idle = State(initial=True)
        small = State()
        large = State()
        j = Junction()
        request = idle.to(j)
        j.to(large, cond="size > 10", on="tell")
        j.to(small)
        back = small.to(idle) | large.to(idle)
        noted = idle.to(idle)  # handled only while idle: the broadcast from large finds no taker

        def tell(self) -> None:
            self.send("noted")

    chart = Sorter(chart_name="Sorter")
    index = ChartIndex({"Sorter": chart})
    names: Any = None  # only a `when` breakpoint reads names
    bps = [parse_breakpoint(1, "transition Sorter j->large", index, names),
           parse_breakpoint(2, "event Sorter.noted", index, names),
           parse_breakpoint(3, "transition Sorter j->small", index, names)]
    listener = BreakListener(bps)
    chart.add_listener(listener)
    chart.size = 3
    chart.send("request")
    assert [h.breakpoint for h in listener.hits] == [3]
    chart.send("back")
    chart.size = 12
    chart.send("request")
    assert [h.breakpoint for h in listener.hits] == [3, 2, 1]
    assert listener.hits[1].detail == "local event noted sent from idle"
    assert listener.hits[2].detail == "j -> large"
