"""docs/vision.md stays true: its example runs and prints what the page shows; its pictures exist."""

from __future__ import annotations

import re
from pathlib import Path

import cv2

DOC = Path(__file__).resolve().parents[2] / "docs" / "vision.md"


def test_the_example_prints_what_the_page_says(capsys):
    text = DOC.read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert blocks
    namespace: dict = {"__name__": "vision_docs"}
    for i, block in enumerate(blocks):
        exec(compile(block, f"{DOC.name}[block {i}]", "exec"), namespace)  # noqa: S102
    printed = capsys.readouterr().out
    assert printed.strip() in text


def test_the_pictures_the_page_shows_exist():
    text = DOC.read_text(encoding="utf-8")
    names = re.findall(r"\]\((img/[^)]+\.png)\)", text)
    assert len(names) == 5
    for name in names:
        img = cv2.imread(str(DOC.parent / name))
        assert img is not None and img.shape[2] == 3, name
