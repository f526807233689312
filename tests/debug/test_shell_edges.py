"""What the debugger says at its edges (issue 28's smaller points): never an internal exception's name, a
command file that does not end at a line ``EOF``, an input forced beyond what its chart can do refused."""

from __future__ import annotations

from pathlib import Path

import pytest

from ttt_sm.cli import main
from ttt_sm.debug.debugger import Debugger
from ttt_sm.debug.errors import DebugError
from ttt_sm.debug.shell import PROMPT, DebugShell


def _run(tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str) -> tuple[int, str]:
    commands = tmp_path / "commands.txt"
    commands.write_text(text)
    rc = main(["debug", "--commands", str(commands)])
    return rc, capsys.readouterr().out


def test_no_internal_exception_name_reaches_the_user(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rc, out = _run(tmp_path, capsys, "show timeline Control 1e308\npost Control button event=1\n"
                                     "post Control button self=1\nstep 2\n")
    assert rc == 1  # two commands refused
    for name in ("OverflowError", "TypeError", "Error:"):
        assert name not in out, out
    assert "Control: chart ticks 0..0" in out  # a window longer than the run: the whole run
    assert out.count("may not carry a datum named") == 2
    assert "done at t = 0.002 s, step 2" in out  # the robot runs on


def test_a_line_EOF_in_a_commands_file_is_an_unknown_command_not_the_end(  # noqa: N802
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rc, out = _run(tmp_path, capsys, "step\nEOF\nstep\n")
    assert f"{PROMPT}EOF\nerror: unknown command 'EOF'" in out
    assert "done at t = 0.002 s, step 2" in out and out.rstrip().endswith("(end of commands)")


def test_forcing_a_cell_beyond_the_field_is_refused_and_within_it_taken(dbg: Debugger) -> None:
    """``force Control.row 1e12`` left the Control chart moving to a cell it never reached, for ever."""
    for value in ("1e12", "0", "6", "-3"):
        with pytest.raises(DebugError, match=r"Control.row takes 1 to 5, not"):
            dbg.set_input("Control", "row", value, force=True)
    with pytest.raises(DebugError, match=r"Control.column takes 1 to 5"):
        dbg.set_input("Control", "column", 7)
    assert dbg.actions == []  # nothing recorded
    assert dbg.set_input("Control", "row", "5", force=True) == 5


def test_a_command_that_breaks_inside_is_said_in_words(dbg: Debugger, capsys: pytest.CaptureFixture[str],
                                                       monkeypatch: pytest.MonkeyPatch) -> None:
    def broken(*args: object) -> None:
        raise ZeroDivisionError("float division by zero")

    monkeypatch.setattr(dbg, "step", broken)
    shell = DebugShell(dbg)
    shell.run_script(["step", "where"])
    out = capsys.readouterr().out
    assert "error: step: it failed inside (float division by zero)" in out and "ZeroDivisionError" not in out
    assert shell.errors == 1
