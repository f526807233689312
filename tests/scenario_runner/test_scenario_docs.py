"""docs/scenarios.md stays true: its worked example is the scenario file, every YAML example loads,
its Python runs, and it lists every scenario file of tests/scenarios."""

from __future__ import annotations

import re
from pathlib import Path

from ttt_sm.scenario import load_scenario_text
from ttt_sm.scenario.steps import STEP_OPTIONS

ROOT = Path(__file__).resolve().parents[2]
DOC = (ROOT / "docs" / "scenarios.md").read_text(encoding="utf-8")
SCENARIOS = ROOT / "tests" / "scenarios"


def test_the_worked_example_is_the_scenario_file_and_every_example_loads() -> None:
    # A file the reader saves (<!-- doc-test: file NAME -->: one with mistakes too) is run by the page's
    # commands below it, in tests/docs/test_doc_pages.py; every other example loads.
    blocks = re.findall(r"(<!-- doc-test: file [^>]*-->\n)?```yaml\n(.*?)```", DOC, re.S)
    example, *others = [text for marker, text in blocks if not marker]
    assert len(blocks) > len(others) + 1, "the files the page's commands run"
    assert example == (SCENARIOS / "drive_1_turns_back_at_a_hard_stop.yaml").read_text(encoding="utf-8")
    assert load_scenario_text(example, "docs/scenarios.md").name == "drive 1 turns back at a hard stop"
    assert others, "the bare-chart example"
    for text in others:
        load_scenario_text(text, "docs/scenarios.md")


def test_every_step_kind_and_scenario_file_is_documented() -> None:
    for kind in STEP_OPTIONS:
        assert f"| `{kind}` |" in DOC, kind
    for path in SCENARIOS.glob("*.yaml"):
        assert f"`{path.stem}`" in DOC, path.name


def test_the_python_example_runs(monkeypatch, capsys) -> None:
    monkeypatch.chdir(ROOT)
    (block,) = [b for b in re.findall(r"```python\n(.*?)```", DOC, re.S) if "run_scenario" in b]
    exec(compile(block, "docs/scenarios.md", "exec"), {"__name__": "scenario_docs"})  # noqa: S102
    assert "DriveInit1: states" in capsys.readouterr().out
