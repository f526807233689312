"""A class of submissions for ``ttt-sm lab grade``: made from the algorithm_activator exercise's skeleton
and reference, and the ways a student's code can go wrong (tests/lab/test_grade.py, the bench)."""

from __future__ import annotations

import re
from pathlib import Path

from ttt_sm.lab.exercise import exercise

EXERCISE = "algorithm_activator"

#: The thesis' own chart, under the student's class name: passes every check.
REFERENCE = "from ttt_sm.charts.game import AlgorithmActivator as MyActivator  # noqa: F401\n"


def _skeleton() -> str:
    return exercise(EXERCISE).chart_file.read_text(encoding="utf-8")


def _action(body: str) -> str:
    """The skeleton with `body` as the action run when the chart enters `enabled` (on the first click)."""
    text = _skeleton().replace("    def on_enter_enabled(self) -> None:\n        self.enable = True\n",
                               f"    def on_enter_enabled(self) -> None:\n{body}")
    assert body in text
    return text


def kinds() -> dict[str, str]:
    """Each kind of submission, by the student name the tests give it, and its chart file's text."""
    return {
        "ada_reference": REFERENCE,
        "ben_skeleton": _skeleton(),
        "cy_syntax_error": re.sub(r"class MyActivator\(TickChart\):", "class MyActivator(TickChart:", _skeleton()),
        "dee_endless_loop": _action("        while True:\n            self.enable = True\n"),
        "eve_memory_hog": _action("        self.hoard = []\n        while True:\n"
                                  "            self.hoard.append(bytearray(50_000_000))\n"),
        "hal_wrong_contract": _skeleton().replace('Data("enable", "bool"', 'Data("enable_it", "bool"'),
        "fay_never_finishes": _action("        import time\n\n        time.sleep(1e6)\n"),
    }


def make_class(folder: Path, kinds_: dict[str, str] | None = None, copies: int = 1) -> Path:
    """A submissions folder: one sub-folder per student holding the exercise's chart file."""
    ex = exercise(EXERCISE)
    for n in range(copies):
        for student, text in (kinds_ or kinds()).items():
            sub = folder / (student if copies == 1 else f"{student}_{n + 1:02d}")
            sub.mkdir(parents=True)
            (sub / ex.file).write_text(text, encoding="utf-8")
    return folder
