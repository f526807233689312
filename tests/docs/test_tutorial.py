"""docs/tutorial.md stays true: its debugger session and its scenario run as written."""

import re
from pathlib import Path

from ttt_sm.cli import main
from ttt_sm.params import load_params
from ttt_sm.scenario import load_scenario_text, run_scenario

TUTORIAL = (Path(__file__).resolve().parents[2] / "docs" / "tutorial.md").read_text()


def test_the_debugger_session_stops_where_drive_1_turns_back(tmp_path, capsys):
    block = re.search(r"```\n\$ \.venv/bin/ttt-sm debug\n(.*?)```", TUTORIAL, re.S)
    assert block, "the tutorial's debugger session is missing"
    commands = [line.removeprefix("(ttt-sm) ") for line in block.group(1).splitlines()
                if line.startswith("(ttt-sm) ")]
    assert commands[0] == "break enter DriveInit1.turn_back"
    script = tmp_path / "tutorial.txt"
    script.write_text("\n".join(commands) + "\n")
    assert main(["debug", "--commands", str(script)]) == 0
    out = capsys.readouterr().out
    assert "entered turn_back" in out
    q1 = re.search(r"q_true +\[[^]]*\] rad +\(\[([-\d.]+) ", out)
    assert q1 is not None and abs(float(q1.group(1)) - 170.0) < 0.5


def test_the_scenario_in_the_tutorial_passes_and_the_broken_one_fails():
    block = re.search(r"```yaml\n(.*?)```", TUTORIAL, re.S)
    assert block, "the tutorial's scenario is missing"
    params = load_params()
    result = run_scenario(load_scenario_text(block.group(1), "tutorial.md"), params)
    assert result.passed, result.failures
    broken = block.group(1).replace("165deg", "175deg")
    result = run_scenario(load_scenario_text(broken, "tutorial.md"), params)
    assert not result.passed
    assert "tutorial.md:6: expect: 'q_true[1] > 175deg' is false" in str(result.failures[0])
