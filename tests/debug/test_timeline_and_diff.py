"""The debugger's timeline (when each state was entered and left) and its data diff (the tick before)."""

from __future__ import annotations

import re

import pytest

from ttt_sm.debug import DebugError, Debugger
from ttt_sm.debug.shell import DebugShell
from ttt_sm.debug.timeline import Timeline


@pytest.fixture
def at_turn_back(dbg: Debugger) -> Debugger:
    dbg.add_breakpoint("enter DriveInit1.turn_back")
    stop = dbg.run(20.0)
    assert stop.kind == "breakpoint"
    return dbg


def test_the_timeline_holds_each_state_with_the_ticks_it_was_entered_and_left(at_turn_back: Debugger):
    dbg = at_turn_back
    now = dbg.robot.chart_ticks
    window = dbg.timeline("DriveInit1")
    spans = {iv.state: (iv.entered, iv.left) for iv in window.intervals}
    # the trace's two transitions, power_on -> turn_fwd in tick 1 and turn_fwd -> turn_back now
    assert [(r.tick, r.source, r.target) for r in dbg.trace.records] == \
        [(1, "power_on", "turn_fwd"), (now, "turn_fwd", "turn_back")]
    assert spans == {"run": (0, None), "initialise": (0, None), "power_on": (0, 1), "turn_fwd": (1, now),
                     "turn_back": (now, None)}
    turn_fwd = next(iv for iv in window.intervals if iv.state == "turn_fwd")
    assert turn_fwd.ticks(now) == now - 1
    assert window.seconds(now) == pytest.approx(dbg.trace.records[-1].time_s)
    # the last half second only: power_on is left out, turn_fwd is cut by the window
    recent = dbg.timeline("DriveInit1", 0.5)
    assert recent.first == now - 250 and "power_on" not in {iv.state for iv in recent.intervals}


def test_show_timeline_draws_bars_and_a_table(at_turn_back: Debugger, capsys):
    shell = DebugShell(at_turn_back)
    now = at_turn_back.robot.chart_ticks
    shell.run_script(["show timeline DriveInit1", "show timeline DriveInit1 0.1", "show timeline Nope",
                      "show timeline DriveInit1 -3"])
    out = capsys.readouterr().out
    assert f"DriveInit1: chart ticks 0..{now} (chart time 0.000..{now * 0.002:.3f} s)" in out
    bars = dict(re.findall(r"^ +(\w+) +\|([# ]{60})\|$", out, re.M))
    assert bars["turn_fwd"].strip() == "#" * len(bars["turn_fwd"].strip())  # one unbroken bar ...
    assert bars["power_on"].startswith("#") and bars["turn_back"].endswith("#")  # ... between these
    assert re.search(rf"turn_fwd +tick 1 \(0.002 s\) +tick {now} \({now * 0.002:.3f} s\) +"
                     rf"{(now - 1) * 0.002:.3f} s \({now - 1} ticks\)", out)
    assert re.search(r"turn_back +tick \d+ \([\d.]+ s\) +\(active\) +0.000 s so far \(0 ticks\)", out)
    assert f"DriveInit1: chart ticks {now - 50}..{now}" in out
    assert "error: no chart 'Nope'" in out
    assert "error: timeline: the time must be a positive number of seconds, got -3.0" in out


def test_the_timeline_history_is_bounded_and_says_what_it_dropped(params):
    dbg = Debugger.build(params, seed=0)
    small = Timeline(keep=2).observe(dbg.robot.charts.values())
    dbg.add_breakpoint("enter DriveInit1.go_park")
    dbg.run(20.0)
    window = small.window("DriveInit1", dbg.robot.chart_ticks, 0.002)
    closed = [iv for iv in window.intervals if iv.left is not None]
    assert [iv.state for iv in closed] == ["turn_fwd", "turn_back"] and window.dropped == 1  # power_on


def test_data_diff_shows_the_values_one_tick_earlier(at_turn_back: Debugger):
    dbg = at_turn_back
    tick = dbg.robot.chart_ticks
    diff = dbg.data_diff("DriveInit1")
    assert diff is not None and diff.tick == tick
    changed = {c.name: (c.before, c.after) for c in diff.changes}
    # the reverse action put the setpoint back on the encoder: before, it ran a few hundredths ahead
    before, after = changed["pos_out"]
    encoder = dbg.robot.value("DriveInit1", "pos_Encoder")
    assert after == encoder and 0.01 < before - after < 0.1
    assert changed["direction"] == (1, -1)
    assert all(c.chart == "DriveInit1" for c in diff.changes)
    # the same values as a replay to the tick before shows
    dbg.replay(tick - 1)
    chart = dbg.robot.chart("DriveInit1")
    assert chart.pos_out == before and chart.direction == 1


def test_data_diff_before_any_tick_and_after_a_set(dbg: Debugger, capsys):
    assert dbg.data_diff() is None
    dbg.tick(3)
    dbg.set_input("DriveInit1", "stop", "1")
    diff = dbg.data_diff()
    assert diff is not None
    assert ("DriveInit1", "stop", False, True) in [(c.chart, c.name, c.before, c.after) for c in diff.changes]
    with pytest.raises(DebugError, match="no chart 'Drive'"):
        dbg.data_diff("Drive")
    shell = DebugShell(Debugger.build(dbg.robot.params, seed=0))
    shell.run_script(["show data --diff", "tick 2", "show data DriveInit1 --diff", "show data a b"])
    out = capsys.readouterr().out
    assert "no chart tick has run yet" in out
    # tick 2 is turn_fwd's first during action: the setpoint moves on by inc
    assert "DriveInit1 data changed since just before chart tick 2 (before -> now):" in out
    assert re.search(r"output +pos_out +[-\d.e]+ rad \([-\d.]+ deg\) -> [-\d.e]+ rad", out)
    assert "error: show data: expected [CHART] [--diff], got 'a b'" in out
