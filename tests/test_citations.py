"""The repository stands on its own: it cites docs/ and the thesis, never notes that live outside it.

A reader of the repository has the code, ``docs/`` and the thesis (Daniel
Youssef, *Design of application for educational model of manipulator with
three degrees of freedom*, Brno 2014), cited by section, figure and equation.
The working notes the project was built from are not in the repository, so a
citation of them is a dead end for that reader.
"""

from __future__ import annotations

import re
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
#: Built from parts, so this file does not match itself.
OUTSIDE = re.compile("|".join(re.escape(p) for p in ("DESIGN" + ".md", "STYLE" + ".md", "shared" + "/", "seeds" + "/")))
SCANNED = ("src", "docs", "tests", "charts", "scripts", ".ci", "README.md", "Makefile", "pyproject.toml")
TEXT = {".py", ".md", ".toml", ".yaml", ".yml", ".sh", ".txt", ".cfg", ".svg", ".dot", ".json", ".ini", ""}
SKIPPED = {"__pycache__", "node_modules", ".pytest_cache"}


def outside_citations(repo: Path) -> list[str]:
    """``path:line: text`` of every line that cites a note outside the repository."""
    found = []
    for top in SCANNED:
        base = repo / top
        paths = [base] if base.is_file() else sorted(base.rglob("*")) if base.is_dir() else []
        for path in paths:
            parts = set(path.relative_to(repo).parts)
            if not path.is_file() or path.suffix not in TEXT or parts & SKIPPED or any(
                    p.endswith(".egg-info") for p in parts):
                continue
            for n, line in enumerate(path.read_text(encoding="utf-8", errors="replace").splitlines(), 1):
                if OUTSIDE.search(line):
                    found.append(f"{path.relative_to(repo).as_posix()}:{n}: {line.strip()}")
    return found


def test_no_citation_of_notes_outside_the_repository():
    found = outside_citations(REPO)
    assert found == [], ("cite docs/... (docs/architecture.md for how the parts fit) or the thesis by section and "
                         "equation, not notes outside the repository:\n" + "\n".join(found))


def test_the_guard_finds_such_a_citation(tmp_path):
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "m.py").write_text('"""The control step of ' + "DESIGN" + '.md."""\n', encoding="utf-8")
    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "a.md").write_text("ok\nthe thesis (`" + "shared" + "/x.txt`)\n", encoding="utf-8")
    assert outside_citations(tmp_path) == ["src/m.py:1: \"\"\"The control step of " + "DESIGN" + ".md.\"\"\"",
                                           "docs/a.md:2: the thesis (`" + "shared" + "/x.txt`)"]
