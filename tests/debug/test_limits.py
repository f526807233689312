"""Every run of the debugger is bounded in simulated time: `run 1e12` is refused, not run forever.

The bound (`DEFAULT_MAX_RUN_S`, `ttt-sm debug --max-run`) and the progress a
long run shows on a terminal; docs/debugger.md and docs/reliability.md.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from ttt_sm.cli import main
from ttt_sm.debug import DebugError, Debugger
from ttt_sm.debug.debugger import DEFAULT_MAX_RUN_S
from ttt_sm.params import ArmParams

BOUND = f"beyond {DEFAULT_MAX_RUN_S:g} s of simulated time, the longest one command runs"


@pytest.mark.parametrize("call", [
    lambda d: d.run(1e12), lambda d: d.next(1e12), lambda d: d.step(10**12), lambda d: d.tick(10**12),
    lambda d: d.run(DEFAULT_MAX_RUN_S * 1.01), lambda d: d.step(int(DEFAULT_MAX_RUN_S * 1000) + 1),
], ids=["run", "next", "step", "tick", "run just over", "step just over"])
def test_a_run_beyond_the_bound_is_refused_before_a_step_is_taken(dbg: Debugger, call):
    with pytest.raises(DebugError, match=re.escape(BOUND)) as info:
        call(dbg)
    assert "--max-run" in str(info.value)
    assert dbg.robot.steps == 0


def test_the_bound_is_overridable_and_a_long_run_still_stops_at_a_breakpoint(params: ArmParams):
    dbg = Debugger.build(params, seed=0, max_run_s=1e6)
    dbg.add_breakpoint("enter DriveInit1.turn_back")
    stop = dbg.run(1e5)
    assert stop.kind == "breakpoint" and 1.0 < stop.t < 10.0


def test_a_long_run_reports_its_progress_every_few_simulated_seconds(dbg: Debugger):
    seen: list[tuple[float, float]] = []
    dbg.progress = lambda t, end: seen.append((t, end))
    dbg.run(11.0)
    assert [round(t, 3) for t, _ in seen] == [5.0, 10.0]
    assert all(end == pytest.approx(11.0) for _, end in seen)


def test_replay_goes_back_only_as_far_forward_as_the_session_has_been(dbg: Debugger):
    dbg.run(0.1)
    with pytest.raises(DebugError, match=r"replay: chart tick 1000000000000 lies beyond where this session has"
                                         r" been \(chart tick 50\)"):
        dbg.replay(10**12)
    assert dbg.replay(20).tick == 20


def test_the_repl_refuses_run_1e12_in_one_line_and_goes_on(tmp_path: Path, capsys):
    commands = tmp_path / "c.txt"
    commands.write_text("run 1e12\nstep 1000000000000\nrun 0.01\nwhere\n")
    rc = main(["debug", "--commands", str(commands)])
    out = capsys.readouterr().out
    assert rc == 1
    assert f"error: run: 1e+12 s is {BOUND}" in out
    assert f"error: step: 1000000000000 control steps (1e+09 s) is {BOUND}" in out
    assert "time is up at t = 0.010 s, step 10" in out


def test_max_run_raises_the_bound_from_the_command_line(tmp_path: Path, capsys):
    commands = tmp_path / "c.txt"
    commands.write_text("run 700\n")
    assert main(["debug", "--max-run", "600", "--commands", str(commands)]) == 1
    assert "error: run: 700 s is beyond 600 s" in capsys.readouterr().out


@pytest.mark.parametrize("argv, message", [
    (["debug", "--settle", "1e12"], "--settle: 1e+12 s is beyond 600 s"),
    (["debug", "--settle", "nan"], "--settle must be >= 0 seconds"),
    (["debug", "--max-run", "0"], "--max-run must be a positive number of seconds"),
    (["debug", "--max-run", "inf"], "--max-run must be a positive number of seconds"),
])
def test_bad_time_options_are_one_line_before_anything_runs(capsys, argv, message):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1


def test_a_replay_is_bounded_by_its_work_from_power_on_as_one_commands_run_is(params: ArmParams):
    dbg = Debugger.build(params, seed=0, max_run_s=0.05)
    dbg.run(0.05)
    dbg.run(0.05)  # two commands: 0.1 s simulated, 50 chart ticks
    with pytest.raises(DebugError, match=re.escape(
            "replay: it would run 0.079 s of simulated time again from power-on (to control step 79), beyond the"
            " 0.05 s one command runs (start the debugger with --max-run SECONDS to allow more)")):
        dbg.replay(40)
    assert dbg.robot.steps == 100  # refused before the robot was rebuilt
    assert dbg.replay(25).tick == 25  # 0.05 s: within the bound
