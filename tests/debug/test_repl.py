"""The `ttt-sm debug` REPL, driven as a user would: a commands file, a pipe, bad input."""

from __future__ import annotations

import io
import re
import subprocess
import sys
from pathlib import Path

import pytest

from ttt_sm.cli import main
from ttt_sm.debug.shell import PROMPT

STUDENT = """\
# a student steps through the drive-1 chart until it finds the hard stop
where
break enter DriveInit1.turn_back
run 20
where
show data DriveInit1
show signals
trace
"""


def _run_cli(tmp_path: Path, capsys, text: str, *extra: str) -> tuple[int, str]:
    commands = tmp_path / "commands.txt"
    commands.write_text(text)
    rc = main(["debug", "--commands", str(commands), *extra])
    return rc, capsys.readouterr().out


def test_a_commands_file_drives_the_repl_to_the_hard_stop(tmp_path, capsys):
    rc, out = _run_cli(tmp_path, capsys, STUDENT)
    assert rc == 0
    assert out.startswith("ttt-sm debugger: seed 0, start rest pose; charts DriveInit1, DriveInit2,")
    assert f"{PROMPT}break enter DriveInit1.turn_back\nbreakpoint 1: enter DriveInit1.turn_back\n" in out
    stop = re.search(r"stopped at t = ([\d.]+) s, step (\d+), chart tick (\d+): breakpoint 1 "
                     r"\(enter DriveInit1.turn_back\): entered turn_back at chart tick (\d+)", out)
    assert stop is not None and stop.group(3) == stop.group(4)
    assert re.search(r"DriveInit1 +run > initialise > turn_back +\(0 ticks\)", out)
    # show data: units from the declarations, radians also in degrees
    assert re.search(r"input +pos_Encoder +[-\d.]+ rad \([-\d.]+ deg\) +-- drive angle from the encoder", out)
    assert re.search(r"local +inc +0.002 rad \(0.11 deg\)", out)
    # show signals: drive 1's true angle on the +170 deg hard stop
    q_true = re.search(r"q_true +\[[^]]*\] rad +\(\[([-\d.]+) ", out)
    assert q_true is not None and float(q_true.group(1)) == pytest.approx(170.0, abs=0.5)
    assert re.search(r"current_a +\[[^]]*\] A", out) and "tool_true" in out
    assert "DriveInit1: turn_fwd -> turn_back  [tick]" in out
    assert out.rstrip().endswith("(end of commands)")


def test_bad_commands_give_one_line_errors_and_the_session_goes_on(tmp_path, capsys):
    rc, out = _run_cli(tmp_path, capsys, """\
frobnicate
break enter DriveInit1.turn_bak
break when DriveInit1.pos_Encoder > > 1
show data NoSuchChart
set DriveInit1.stp 1
set DriveInit1.stop maybe
post DriveInit1 stop
step many
delete 7
replay
diagram DriveInit1 out.txt
show
tick 2
where
""")
    assert rc == 1  # a scripted session with errors exits non-zero
    lines = out.splitlines()
    errors = [line for line in lines if line.startswith("error: ")]
    expected = [
        "error: unknown command 'frobnicate'; commands: ",
        "error: DriveInit1 has no state 'turn_bak' (did you mean 'turn_back'?); states: ",
        "error: expected a number, a name or '(', found '>' at column 26 in 'DriveInit1.pos_Encoder > > 1'",
        "error: no chart 'NoSuchChart'",
        "error: DriveInit1 has no datum 'stp' (did you mean 'stop'?)",
        "error: DriveInit1.stop is a flag: give 1 or 0 (true/false), not 'maybe'",
        "error: DriveInit1: no transition handles event 'stop'",
        "error: step: expected a whole number, got 'many'",
        "error: no breakpoint 7; breakpoints: none",
        "error: replay: to which chart tick?",
        "error: diagram: unknown extension '.txt'",
        "error: show what? one of: charts, data, signals, trace, breakpoints, inputs, snapshot",
    ]
    assert len(errors) == len(expected)
    for line, start in zip(errors, expected, strict=True):
        assert line.startswith(start)
    # Each error is one line, right after its command; then the session went on.
    for i, line in enumerate(lines):
        if line.startswith("error: "):
            assert lines[i - 1].startswith(PROMPT)
    assert "done at t = 0.003 s, step 3, chart tick 2" in out
    assert re.search(r"DriveInit1 +run > initialise > turn_fwd", out)


def test_set_force_release_post_and_replay_through_the_repl(tmp_path, capsys):
    rc, out = _run_cli(tmp_path, capsys, """\
tick 100
set DriveInit1.stop 1
tick
where
force DriveInit2.index 1
show inputs
release
replay 101
replay 100
show inputs
trace save {trace}
diagram DriveInit1 {svg}
""".format(trace=tmp_path / "t.jsonl", svg=tmp_path / "d1.svg"))
    assert rc == 0, out
    assert "DriveInit1.stop = True\n" in out
    assert re.search(r"DriveInit1 +stopped", out)
    assert "DriveInit2.index = True (forced until release)" in out
    assert "step 199: set DriveInit1.stop True" in out and "step 201: force DriveInit2.index True" in out
    assert "released DriveInit2.index" in out
    assert "replayed to step 201 (t = 0.201 s, chart tick 101), 3 recorded inputs re-applied;" \
           " identical to the first visit" in out
    assert "replayed to step 199 (t = 0.199 s, chart tick 100), 1 recorded input re-applied," \
           " 2 later ones kept (applied again when you run to their steps); identical to the first visit" in out
    # kept, not dropped: show inputs lists them as ahead
    assert "step 201: force DriveInit2.index True (ahead: applied when the run gets there)" in out
    assert (tmp_path / "t.jsonl").read_text().count("\n") == 1  # replayed to before run -> stopped
    assert "<svg" in (tmp_path / "d1.svg").read_text()


def test_standard_input_that_is_not_a_terminal_is_read_as_commands(monkeypatch, capsys):
    monkeypatch.setattr(sys, "stdin", io.StringIO("tick 3\nwhere\n"))  # StringIO is no terminal
    assert main(["debug", "--seed", "2", "--start", "10,20,-30"]) == 0
    out = capsys.readouterr().out
    assert "seed 2, start (10.0, 20.0, -30.0, 0.0) deg" in out
    assert "done at t = 0.005 s, step 5, chart tick 3" in out


def test_bad_options_are_one_line_cli_errors(capsys):
    assert main(["debug", "--start", "1,2"]) == 2
    assert capsys.readouterr().err.strip() == \
        "ttt-sm debug: error: --start: expected 3 or 4 finite angles in degrees, got '1,2'"
    assert main(["debug", "--start", "400,0,0"]) == 2
    assert "lies outside joint 1's limits" in capsys.readouterr().err


def test_the_installed_command_with_a_pipe_quits_at_the_end_of_input():
    exe = Path(sys.executable).with_name("ttt-sm")
    done = subprocess.run([str(exe), "debug"], input="break enter DriveInit1.turn_back\nrun 20\nwhere\n",
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "breakpoint 1 (enter DriveInit1.turn_back): entered turn_back" in done.stdout
    assert re.search(r"DriveInit1 +run > initialise > turn_back", done.stdout)
    assert done.stdout.rstrip().endswith("(end of commands)")


@pytest.mark.parametrize("argv", [["--start", "-120,0,0"], ["--start=-120,0,0"]])
def test_a_negative_start_angle_is_read_after_a_space_or_an_equals_sign(argv, monkeypatch, capsys):
    """docs/tutorial.md writes `--start -120,0,0`: argparse alone took -120,0,0 for an option."""
    monkeypatch.setattr(sys, "stdin", io.StringIO("show signals\n"))
    assert main(["debug", *argv]) == 0
    out = capsys.readouterr().out
    assert "start (-120.0, 0.0, 0.0, 0.0) deg" in out
    assert re.search(r"q_true +\[-2\.0944 ", out)  # -120 deg in radians


def test_continue_runs_on_as_run_does(tmp_path, capsys):
    rc, out = _run_cli(tmp_path, capsys, "break enter DriveInit1.turn_fwd\nbreak enter DriveInit1.turn_back\n"
                                         "continue\ncontinue 20\nhelp continue\n")
    assert rc == 0, out
    assert "entered turn_fwd at chart tick 1" in out and "entered turn_back at chart tick" in out
    assert "continue [TIME]: the same as run" in out
