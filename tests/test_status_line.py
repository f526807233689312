"""Long runs show where they are on a terminal, and only there: `ttt-sm play`, `ttt-sm init`.

See docs/reliability.md, "Bounded runs".

Each command runs in a process of its own with standard error on a real
pseudo-terminal (``pty.openpty``) and standard output on a pipe: the status
line is rewritten in place on the terminal (``\\r``, then erased), never
written into the ``--json`` document; with standard error on a pipe there is
no status line at all.
"""

from __future__ import annotations

import json
import os
import pty
import re
import subprocess
import sys
from pathlib import Path

import pytest

TTT = Path(sys.executable).with_name("ttt-sm")
needs_script = pytest.mark.skipif(not TTT.exists(), reason="the ttt-sm console script is not installed beside python")


def _run_with_stderr_on_a_terminal(argv: list[str], cwd: Path) -> tuple[int, str, str]:
    """Run ``ttt-sm argv``: standard error a pty's slave, standard output a pipe; what each received."""
    master, slave = pty.openpty()
    proc = subprocess.Popen([str(TTT), *argv], stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=slave,
                            cwd=cwd)
    os.close(slave)
    terminal = bytearray()
    while True:
        try:
            chunk = os.read(master, 65536)
        except OSError:  # EIO: the last writer closed the slave
            break
        if not chunk:
            break
        terminal += chunk
    assert proc.stdout is not None
    out = proc.stdout.read().decode()
    status = proc.wait(timeout=600)
    os.close(master)
    return status, out, terminal.decode(errors="replace")


def _status_lines(terminal: str) -> list[str]:
    """The texts shown on the status line: each written after a carriage return and an erase-line."""
    return [part.split("\x1b[K", 1)[1].strip() for part in terminal.split("\r") if part.startswith("\x1b[K")]


@needs_script
def test_init_shows_its_runs_done_on_a_terminal_not_in_its_json(tmp_path):
    status, out, terminal = _run_with_stderr_on_a_terminal(["init", "--starts", "2", "--json"], tmp_path)
    assert status == 0, terminal
    # rewritten at most every 0.25 s of wall time: a start that ends sooner after the last line is not
    # shown (a fast machine), so the lines are the expected ones in order, from the first, some maybe left out
    expected = ["0/2 init: starting in this process", "1/2 init: 1 initialised so far",
                "2/2 init: 2 initialised so far"]
    shown = [s for s in _status_lines(terminal) if s]
    assert shown[:1] == expected[:1] and shown == [line for line in expected if line in shown], shown
    assert terminal.endswith("\r\x1b[K")  # the status line taken off at the end
    report = json.loads(out)  # the document alone on standard output
    assert report["runs"] == 2 and "power-on pose" not in out


@needs_script
def test_play_shows_the_simulated_time_and_what_it_waits_for_on_a_terminal_only(tmp_path):
    argv = ["play", "--opponent", "simulated", "--camera", "direct", "--seed", "3", "--person", "random",
            "--json", "--out", str(tmp_path / "game")]
    status, out, terminal = _run_with_stderr_on_a_terminal(argv, tmp_path)
    assert status == 0, terminal
    shown = [s for s in _status_lines(terminal) if s.startswith("t = ")]
    assert any("s simulated: " in s and "field" in s for s in shown), shown  # drawing the field first
    assert len(shown) >= 3
    assert json.loads(out)["outcome"] in ("X", "O", "draw")
    piped = subprocess.run([str(TTT), *argv[:-1], str(tmp_path / "again")], capture_output=True, text=True,
                           timeout=600, cwd=tmp_path)
    assert piped.returncode == 0 and "\r" not in piped.stderr and "s simulated: " not in piped.stderr
    # a log shows both players: the simulated person's moves with the board after each, and the final board
    moves = re.findall(r"\[person\] draws X in row (\d), column (\d):\n    1 2 3 4 5\n((?:  \d [.XO ]+\n){5})",
                       piped.stderr)
    assert len(moves) >= 2, piped.stderr[-2000:]
    for row, column, picture in moves:
        assert picture.splitlines()[int(row) - 1].split()[int(column)] == "X"
    assert re.search(r"result: .*the board as the game ended:\n    1 2 3 4 5\n(  \d [.XO ]+\n){5}", piped.stderr)
