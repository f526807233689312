"""docs/game.md: its Python example runs and prints what the comments say."""

from __future__ import annotations

import re
from pathlib import Path

DOC = Path(__file__).resolve().parents[2] / "docs" / "game.md"


def test_the_example_runs(capsys):
    blocks = [b for b in re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)
              if ">>> " not in b]  # the doctest of parse_board's errors is run by tests/docs/test_doc_pages.py
    assert len(blocks) == 1
    exec(compile(blocks[0], f"{DOC.name}[example]", "exec"), {"__name__": "game_docs"})  # noqa: S102
    out = capsys.readouterr().out
    assert "Move(row=2, column=2)" in out and "source='book'" in out
    assert "winner: X" in out
