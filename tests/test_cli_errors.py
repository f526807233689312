"""How the CLI ends when something goes wrong: one line, never a traceback (ttt_sm.cli.main)."""

from __future__ import annotations

import errno
import subprocess
import sys
from pathlib import Path

import pytest

from ttt_sm.cli import BUG_STATUS, error_line, main

TTT = Path(sys.executable).with_name("ttt-sm")
needs_script = pytest.mark.skipif(not TTT.exists(), reason="the ttt-sm console script is not installed beside python")


@needs_script
def test_a_closed_pipe_ends_quietly():
    """`ttt-sm params | head -0`: the reader goes away; no BrokenPipeError, nothing on standard error.

    The reader closes the pipe before the command can write (it is still
    starting): the parameters (3 kB) fit in a pipe's buffer, so a reader that
    went away only after the first line could be too late, the output written.
    """
    proc = subprocess.Popen([str(TTT), "params"], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert proc.stdout is not None and proc.stderr is not None
    proc.stdout.close()  # as head -0 does
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=60) == 141 and err == ""


@needs_script
def test_play_with_standard_input_closed_is_one_line_for_a_terminal_opponent(tmp_path):
    done = subprocess.run(["sh", "-c", f"exec '{TTT}' play --opponent terminal --out '{tmp_path}' 0<&-"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert done.stderr.strip().splitlines()[-1].startswith("ttt-sm play: error: --opponent terminal: standard"
                                                           " input is closed")


def test_an_os_error_on_a_path_names_the_path_and_what_to_do():
    line, status = error_line("draw", PermissionError(errno.EACCES, "Permission denied", "/srv/out/board.png"))
    assert status == 2
    assert line == ("ttt-sm draw: error: /srv/out/board.png: Permission denied; check its permissions,"
                    " or choose another path")
    line, _ = error_line("play", IsADirectoryError(errno.EISDIR, "Is a directory", "out/game.jsonl"))
    assert line.endswith("out/game.jsonl: Is a directory; it is a folder where a file belongs: name a file")


def test_a_path_or_a_message_with_line_breaks_stays_one_line():
    line, status = error_line("play", PermissionError(errno.EACCES, "Permission denied", "out\rdir\n/game.jsonl"))
    assert status == 2 and len(line.splitlines()) == 1 and "'out\\rdir\\n/game.jsonl'" in line
    line, status = error_line("draw", ValueError("first\rsecond\nthird"))
    assert (line, status) == ("ttt-sm draw: error: first second third", 2)


def test_a_bug_is_one_line_that_says_so(monkeypatch, capsys):
    import ttt_sm.cli.commands as commands

    def broken(_args):
        raise ZeroDivisionError("division by zero")

    monkeypatch.setattr(commands, "cmd_params", broken)
    monkeypatch.delenv("TTT_SM_TRACEBACK", raising=False)
    assert main(["params"]) == BUG_STATUS
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith("ttt-sm params: internal error (a bug of ttt_sm, please report it): ZeroDivisionError")
    monkeypatch.setenv("TTT_SM_TRACEBACK", "1")  # the developer's way to see where
    with pytest.raises(ZeroDivisionError):
        main(["params"])
