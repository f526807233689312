"""Every ```python block of docs/runtime.md runs, in order, in one namespace."""

from __future__ import annotations

import re
from pathlib import Path

DOC = Path(__file__).resolve().parents[2] / "docs" / "runtime.md"


def test_docs_examples_run(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)  # the examples write under out/
    blocks = re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)
    assert len(blocks) >= 5
    namespace: dict = {"__name__": "runtime_docs"}
    for i, block in enumerate(blocks):
        exec(compile(block, f"{DOC.name}[block {i}]", "exec"), namespace)  # noqa: S102
    printed = capsys.readouterr().out
    assert "input index bool False" in printed
    assert "Homing: states" in printed


def test_the_conformance_line_counts_the_folder():
    """docs/runtime.md's conformance numbers are the folder's: tests, passing, xfail (cannot be written)."""
    folder = DOC.parents[1] / "tests" / "runtime" / "stateflow"
    tests = xfails = 0
    per_file = {}
    for path in sorted(folder.glob("test_*.py")):
        text = path.read_text(encoding="utf-8")
        n = len(re.findall(r"^def test_", text, re.M))
        per_file[path.name] = n
        tests += n
        xfails += len(re.findall(r"^@pytest\.mark\.xfail", text, re.M))
    doc = DOC.read_text(encoding="utf-8")
    assert (f"**{tests} documented examples: {tests - xfails} agree, 0 disagree, {xfails} cannot be written**"
            in doc)
    for name, n in per_file.items():
        assert f"| `{name}` | {n} |" in doc, name
