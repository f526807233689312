"""A student's lab folder for the live-reload tests: the DriveInit3 exercise with the tutorial's solution.

The solution is the one docs/lab.md's tutorial writes (its ``doc-test: file``
block), read from the page, so these tests and the page cannot drift apart.
:func:`save` writes a file as an editor does: a new file renamed over the old.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from ttt_sm.lab.exercise import Exercise, start

LAB_DOC = Path(__file__).resolve().parents[2] / "docs" / "lab.md"
#: A syntax error on the line of the class statement (a missing parenthesis).
BROKEN_CLASS = ("class MyDriveInit3(TickChart):", "class MyDriveInit3(TickChart:")
#: The fix renames a state: the redrawn diagram shows it.
RENAMED = ("approach", "seek_switch")
#: The line of :func:`raising` that raises (ZeroDivisionError: the increment is 0.0 until the search starts).
RAISING = "self.inc = 1.0 / self.inc"


def reference_solution() -> str:
    """The tutorial's MyDriveInit3 (docs/lab.md, "Tutorial: DriveInit3 from start to a passing check")."""
    text = LAB_DOC.read_text(encoding="utf-8")
    m = re.search(r"<!-- doc-test: file my_init3/drive_init3\.py -->\n```python\n(.*?)```", text, re.S)
    assert m is not None, "docs/lab.md no longer has the tutorial's solution block"
    return m.group(1)


def broken() -> str:
    """The solution with a syntax error, and the line it is on."""
    text = reference_solution()
    assert BROKEN_CLASS[0] in text
    return text.replace(*BROKEN_CLASS)


def broken_line() -> int:
    return next(n for n, line in enumerate(broken().splitlines(), 1) if line.startswith(BROKEN_CLASS[1]))


def fixed() -> str:
    """The solution with state ``approach`` renamed (it still passes: the checks judge what it does).

    The state's callbacks are renamed with it (``during_approach``): the runtime
    refuses a ``during_`` method of a state that does not exist.  (``\\b`` alone
    would not reach them: ``_`` is a word character.)
    """
    text = re.sub(rf"(?<![A-Za-z0-9]){RENAMED[0]}\b", RENAMED[1], reference_solution())
    assert f"during_{RENAMED[1]}" in text, "the tutorial's solution no longer has a during_ action to rename"
    return text


def raising() -> str:
    """The solution with an action that raises on the first chart tick: it divides by the increment, still 0.0.

    It loads and fits the slot; it fails only when the robot runs it.
    """
    text = reference_solution()
    anchor = "    def start_search(self):\n"
    assert anchor in text, "the tutorial's solution no longer has start_search"
    return text.replace(anchor, f"    def during_wait_ini1(self):\n        {RAISING}\n\n{anchor}")


def raising_line() -> int:
    return next(n for n, line in enumerate(raising().splitlines(), 1) if line.strip() == RAISING)


def lab_folder(folder: Path) -> Exercise:
    """``ttt-sm lab start drive_init3 folder``, then the tutorial's solution saved in it."""
    ex = start("drive_init3", folder)
    save(ex.chart_file, reference_solution())
    return ex


def save(path: Path, text: str) -> None:
    """Save as an editor does: a new file, renamed over the old one."""
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)
