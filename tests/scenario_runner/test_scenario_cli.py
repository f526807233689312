"""`ttt-sm scenario run/check`: exit status, JSON shape, coverage, traces, errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ttt_sm.cli import main

PASSING = """\
name: drive 1 starts turning forward
steps:
  - run_until: {entered: DriveInit1.turn_fwd, timeout_s: 0.1}
  - run: {seconds: 0.1}
"""
FAILING = """\
name: drive 1 turns back at once
steps:
  - run: {chart_steps: 2}
  - expect: "DriveInit1.turn_back"
"""
MALFORMED = """\
name: a typo
steps:
  - run: {seconds: 1}
  - expect_state: {chart: DriveInit1, sequence: [turn_fwd]}
"""


@pytest.fixture
def files(tmp_path: Path) -> dict[str, Path]:
    out = {}
    for name, text in (("passing", PASSING), ("failing", FAILING), ("malformed", MALFORMED)):
        out[name] = tmp_path / f"{name}.yaml"
        out[name].write_text(text)
    return out


def run_cli(capsys, *args: str) -> tuple[int, str, str]:
    code = main(["scenario", *args])
    out, err = capsys.readouterr()
    return code, out, err


def test_passing_run_exits_0_and_json_lists_each_scenario(files, capsys) -> None:
    code, out, err = run_cli(capsys, "run", str(files["passing"]), "--json")
    assert code == 0
    data = json.loads(out)
    assert data["passed"] is True and data["counts"] == {"passed": 1, "failed": 0}
    (s,) = data["scenarios"]
    assert s["name"] == "drive 1 starts turning forward" and s["file"] == str(files["passing"])
    assert s["passed"] is True and s["failures"] == [] and s["sim_time_s"] == pytest.approx(0.102)
    assert {"wall_time_s", "steps_run", "steps_total"} <= set(s)
    assert "coverage" not in data
    assert "PASS drive 1 starts turning forward" in err  # progress goes to stderr with --json


def test_a_failing_scenario_exits_1_naming_file_and_line(files, capsys) -> None:
    code, out, _ = run_cli(capsys, "run", str(files["passing"]), str(files["failing"]), "--json")
    assert code == 1
    data = json.loads(out)
    assert data["passed"] is False and data["counts"] == {"passed": 1, "failed": 1}
    failing = data["scenarios"][1]
    assert failing["passed"] is False
    assert failing["failures"][0].startswith(f"{files['failing']}:4: expect: 'DriveInit1.turn_back' is false")
    code, out, _ = run_cli(capsys, "run", str(files["failing"]))
    assert code == 1
    assert f"FAIL drive 1 turns back at once  ({files['failing']}" in out
    assert f"  {files['failing']}:4: expect:" in out and "0 passed, 1 failed" in out


def test_a_malformed_file_exits_2_and_nothing_runs(files, capsys) -> None:
    code, out, err = run_cli(capsys, "run", str(files["passing"]), str(files["malformed"]))
    assert code == 2 and out == ""
    assert err.strip() == (f"ttt-sm scenario: error: {files['malformed']}:4: unknown step kind 'expect_state'"
                           " (did you mean 'expect_states'?); step kinds: set, release, post, run, run_until,"
                           " expect, expect_states, expect_events, mark")
    code, out, _ = run_cli(capsys, "run", str(files["malformed"]), "--json")
    assert code == 2
    assert json.loads(out)["errors"][0].startswith(f"{files['malformed']}:4: unknown step kind")


def test_every_mistake_of_a_file_is_reported_one_line_each(tmp_path: Path, capsys) -> None:
    path = tmp_path / "typos.yaml"
    path.write_text("name: typos\nsteps:\n  - run: {seconds: 1}\n  - expect_state: {chart: DriveInit1}\n"
                    "  - run_until: {entered: DriveInit1.turn_bak, timeout_s: 5}\n")
    code, out, err = run_cli(capsys, "check", str(path))
    assert code == 2 and out == ""
    assert [line.split(": ", 3)[1:3] for line in err.splitlines()] == [
        ["error", f"{path}:4"], ["error", f"{path}:5"]]
    assert "unknown step kind 'expect_state'" in err.splitlines()[0]
    assert "DriveInit1 has no state 'turn_bak' (did you mean 'turn_back'?)" in err.splitlines()[1]
    code, out, _ = run_cli(capsys, "check", str(path), "--json")
    assert [e.split(": ")[0] for e in json.loads(out)["errors"]] == [f"{path}:4", f"{path}:5"]


def test_coverage_report_lists_entered_taken_and_missing(files, capsys) -> None:
    code, out, _ = run_cli(capsys, "run", str(files["passing"]), "--json", "--coverage")
    assert code == 0
    cov = json.loads(out)["coverage"]["DriveInit1"]
    assert cov["entered"] == ["run", "initialise", "power_on", "turn_fwd"]
    assert cov["taken"] == ["power_on -> turn_fwd: tick"]
    assert "turn_back" in cov["missing_states"] and cov["complete"] is False
    assert "turn_fwd -> turn_back: tick [stalled]" in cov["missing_transitions"]
    assert cov["states"] == f"4/{len(cov['entered']) + len(cov['missing_states'])}"
    code, out, _ = run_cli(capsys, "run", str(files["passing"]), "--coverage")
    assert "coverage of all the scenarios together:" in out and "never entered: turn_back" in out


def test_folders_traces_and_check(files, tmp_path, capsys) -> None:
    files["malformed"].unlink()
    files["failing"].unlink()
    trace_dir = tmp_path / "traces"
    code, out, _ = run_cli(capsys, "run", str(tmp_path), "--trace", str(trace_dir))
    assert code == 0 and "1 passed, 0 failed" in out
    records = [json.loads(line) for line in (trace_dir / "passing.jsonl").read_text().splitlines()]
    assert records[0]["source"] == "power_on" and records[0]["target"] == "turn_fwd"
    code, out, _ = run_cli(capsys, "check", str(files["passing"]))
    assert code == 0 and out.startswith("ok drive 1 starts turning forward")
    code, out, _ = run_cli(capsys, "check", str(tmp_path / "nothing_here"), "--json")
    assert code == 2 and "cannot read the file" in json.loads(out)["errors"][0]
    empty = tmp_path / "empty"
    empty.mkdir()
    code, _, err = run_cli(capsys, "run", str(empty))
    assert code == 2 and "no scenario files" in err


def test_the_scenario_command_is_registered(capsys) -> None:
    with pytest.raises(SystemExit):
        main(["scenario", "--help"])
    assert "run" in capsys.readouterr().out
