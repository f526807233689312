"""Issue 27's debugger points: display after each stop, back / step -N, replay keeps later
inputs, run with units, Tab completion of state names, one clock in what a stop prints."""

from __future__ import annotations

import io

import pytest

from ttt_sm.debug import Debugger
from ttt_sm.debug.shell import DebugShell


def _shell(dbg: Debugger) -> tuple[DebugShell, io.StringIO]:
    out = io.StringIO()
    return DebugShell(dbg, stdout=out), out


def test_display_expressions_are_shown_after_each_stop(dbg: Debugger):
    shell, out = _shell(dbg)
    shell.run_script(["display DriveInit1.pos_out", "watch q_true[1]", "tick 5", "undisplay 1", "step"])
    text = out.getvalue()
    assert shell.errors == 0, text
    after_tick = text.split("(ttt-sm) tick 5", 1)[1].split("(ttt-sm) undisplay", 1)[0]
    assert "  1: DriveInit1.pos_out = " in after_tick and "  2: q_true[1] = " in after_tick
    after_step = text.split("(ttt-sm) step", 1)[1]
    assert "1: DriveInit1.pos_out" not in after_step and "  2: q_true[1] = " in after_step


def test_run_takes_seconds_milliseconds_and_ticks(dbg: Debugger):
    shell, out = _shell(dbg)
    shell.run_script(["run 0.01s", "run 10ms", "run 5 ticks", "next 4ms", "run 2x"])
    text = out.getvalue()
    assert "time is up at t = 0.010 s, step 10" in text
    assert "time is up at t = 0.020 s, step 20" in text
    assert "time is up at t = 0.030 s, step 30" in text  # 5 chart ticks of 2 ms
    assert shell.errors == 1 and "error: run: expected simulated time" in text


def test_back_and_step_minus_one_go_back_by_a_replay(dbg: Debugger):
    dbg.tick(10)
    assert (dbg.robot.steps, dbg.robot.chart_ticks) == (19, 10)
    dbg.back()
    assert (dbg.robot.steps, dbg.robot.chart_ticks) == (17, 9)
    dbg.step_back(1)
    assert dbg.robot.steps == 16
    shell, out = _shell(dbg)
    shell.run_script(["step -2", "back 3"])
    text = out.getvalue()
    assert "replayed to step 14 " in text and "replayed to step 9 (t = 0.009 s, chart tick 5)" in text


def test_replay_keeps_the_inputs_given_after_its_tick_and_a_run_applies_them(dbg: Debugger):
    dbg.tick(10)
    dbg.set_input("DriveInit1", "stop", True)
    dbg.tick(3)
    assert "stopped" in dbg.where()["DriveInit1"]
    result = dbg.replay(5)
    assert result.ahead == 1 and result.dropped == 0
    assert dbg.actions == [] and len(dbg.inputs.ahead) == 1
    dbg.tick(10)  # runs past step 19, where the stop was given
    assert "stopped" in dbg.where()["DriveInit1"]
    assert [a.steps for a in dbg.actions] == [19]
    assert dbg.replay(5, drop=True).dropped == 1 and not dbg.inputs.ahead


@pytest.mark.parametrize(("line", "text", "expected"), [
    ("break enter DriveInit1.turn_b", "DriveInit1.turn_b", ["DriveInit1.turn_back"]),
    ("break ex", "ex", ["exit"]),
    ("display DriveInit1.pos_E", "DriveInit1.pos_E", ["DriveInit1.pos_Encoder"]),
    ("set DriveInit1.st", "DriveInit1.st", ["DriveInit1.stop"]),
])
def test_tab_completes_state_and_data_names(dbg: Debugger, line, text, expected):
    shell, _ = _shell(dbg)
    command = line.split()[0]
    complete = getattr(shell, "complete_" + command)
    assert complete(text, line, len(line) - len(text), len(line)) == expected


def test_a_stop_and_its_transitions_print_one_clock(dbg: Debugger):
    shell, out = _shell(dbg)
    shell.run_script(["next"])
    text = out.getvalue()
    assert "chart time" not in text
    assert "  tick 1  DriveInit1: power_on -> turn_fwd  [tick]" in text
    assert "transition at t = 0.001 s, step 1, chart tick 1" in text
