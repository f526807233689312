"""docs/debugger.md: its API example runs, and its example session's commands run without an error."""

from __future__ import annotations

import re
from pathlib import Path

from ttt_sm.debug import Debugger
from ttt_sm.debug.shell import PROMPT, DebugShell

DOC = Path(__file__).resolve().parents[2] / "docs" / "debugger.md"


def test_the_api_example_runs(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)  # it writes under out/
    blocks = re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)
    assert len(blocks) == 1
    exec(compile(blocks[0], f"{DOC.name}[api]", "exec"), {"__name__": "debugger_docs"})  # noqa: S102
    assert "breakpoint 1 (enter DriveInit1.turn_back)" in capsys.readouterr().out
    assert (tmp_path / "out/debug/api.jsonl").is_file()


def test_the_example_session_runs_without_errors(tmp_path, monkeypatch, params, capsys):
    monkeypatch.chdir(tmp_path)
    session = re.search(r"```\n\$ ttt-sm debug\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)
    assert session, "the example session is missing"
    commands = [line[len(PROMPT):] for line in session.group(1).splitlines() if line.startswith(PROMPT)]
    assert len(commands) > 10 and "break enter DriveInit1.turn_back" in commands
    shell = DebugShell(Debugger.build(params, seed=0))
    shell.run_script(commands)
    out = capsys.readouterr().out
    assert shell.errors == 0, out
    assert "identical to the first visit" in out
    assert (tmp_path / "out/debug/DriveInit1-stall.svg").is_file()
