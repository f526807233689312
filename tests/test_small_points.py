"""The smaller points of issue 28 on files and arguments, each a case that was wrong before.

- ``trace save ''`` in the debugger wrote a file named ``''``;
- ``play --out ''`` wrote into the current folder;
- ``1e12`` in a scenario was the text ``'1e12'`` (YAML 1.1), its message "expected a number, got text";
- a parameter file starting with a UTF-8 byte-order mark was "Invalid statement (line 1, column 1)".
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

import pytest

from ttt_sm.cli import main
from ttt_sm.params import load_params
from ttt_sm.scenario.errors import ScenarioError
from ttt_sm.scenario.loader import load_scenario_text

SCENARIOS = Path(__file__).resolve().parent / "scenarios" / "drive_1_finds_its_index_on_the_first_turn.yaml"


def test_trace_save_with_an_empty_name_is_refused_and_a_quoted_name_is_one_name(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.chdir(tmp_path)
    commands = tmp_path / "commands.txt"
    commands.write_text("tick 3\ntrace save ''\ntrace save \"\"\ntrace save 'two words.jsonl'\n")
    assert main(["debug", "--commands", str(commands)]) == 1  # a scripted session with errors
    out = capsys.readouterr().out
    assert out.count("error: trace save: the file name is empty") == 2, out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["commands.txt", "two words.jsonl"]


@pytest.mark.parametrize("argv", [["play", "--out", ""], ["demo", "--out", " "], ["draw", "X", "--out", ""],
                                  ["debug", "--trace", "", "--commands", "/dev/null"],
                                  ["scenario", "run", str(SCENARIOS), "--out", ""]])
def test_an_empty_out_or_trace_is_refused_before_anything_is_written(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], argv: list[str]) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "name is empty" in err[0] and ("--out" in err[0] or "--trace" in err[0]), err
    assert list(tmp_path.iterdir()) == []


SCENARIO = """\
name: a number in exponent form
steps:
  - run_until: {{condition: "Control.ready", timeout_s: {value}}}
"""


@pytest.mark.parametrize("value", ["1e12", "1.0e12", "1E+12"])
def test_a_number_in_exponent_form_is_a_number_in_a_scenario(value: str) -> None:
    with pytest.raises(ScenarioError) as caught:
        load_scenario_text(SCENARIO.format(value=value), "s.yaml")
    message = str(caught.value)
    assert "beyond 600 s of simulated time" in message and "text" not in message, message


def test_small_numbers_in_exponent_form_load() -> None:
    scenario = load_scenario_text(SCENARIO.format(value="2.5e1"), "s.yaml")
    assert scenario.steps[0].timeout_s == 25.0  # type: ignore[attr-defined]


def test_a_parameter_file_with_a_byte_order_mark_loads_as_without(tmp_path: Path) -> None:
    text = resources.files("ttt_sm.data").joinpath("arm.toml").read_text(encoding="utf-8")
    path = tmp_path / "arm.toml"
    path.write_bytes(b"\xef\xbb\xbf" + text.encode("utf-8"))
    plain = tmp_path / "plain.toml"
    plain.write_text(text, encoding="utf-8")
    assert load_params(path).drives == load_params(plain).drives
    assert load_params(path).control == load_params(plain).control


def _arm_file(tmp_path: Path, *edits: tuple[str, str]) -> Path:
    text = resources.files("ttt_sm.data").joinpath("arm.toml").read_text(encoding="utf-8")
    for old, new in edits:
        assert old in text
        text = text.replace(old, new, 1)
    path = tmp_path / "arm.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize("edits, message", [
    ((("rate_hz = 1000.0", "rate_hz = 20000.0"),), r"arm\.toml:\d+: \[control\] rate_hz = 20000: outside 700\.\.1250"),
    ((("gear_ratio = 150.0", "gear_ratio = 1.0"),),
     r"arm\.toml: \[drive\.1\] gear_ratio = 1: the encoder shows 0\.16 counts per chart tick .* gear_ratio >= 25\.1"),
    ((("rate_hz = 1000.0", "rate_hz = 1250.0"), ("chart_divider = 2", "chart_divider = 1")), None),
    ((("gear_stiffness = 10000.0", "gear_stiffness = 1.0e6"),),
     r"\[drive\.1\] gear_ratio = 150: the gear spring's natural frequency \(\d+ Hz\) is too fast for the twin's"
     r" step of 80 us|\[drive\.1\] gear_ratio = 150: the gear spring's natural frequency .* step of 100 us"),
])
def test_the_drives_relations_are_checked_at_load(tmp_path: Path, edits: tuple[tuple[str, str], ...],
                                                  message: str | None) -> None:
    """Values the drives and the twin cannot honour (they passed, then failed: a switch "not found", an encoder
    "jumped 5.5e18 rad/s") are refused when the file is loaded, naming the file, the key and the range."""
    from ttt_sm.params import ParameterError
    from ttt_sm.twin.workspace import load_arm

    path = _arm_file(tmp_path, *edits)
    if message is None:
        load_arm(path)  # 1250 Hz with the charts at every control step: 7.6 counts per tick, within the bounds
        return
    with pytest.raises(ParameterError, match=message):
        load_arm(path)


def test_the_still_speed_the_check_assumes_is_the_charts() -> None:
    from ttt_sm.charts.drive_init import DriveInit1
    from ttt_sm.twin.workspace import INIT_STILL_SPEED_RAD_S

    declared = {d.name: d.default for d in DriveInit1.declarations()}
    assert declared["still_speed"] == INIT_STILL_SPEED_RAD_S
