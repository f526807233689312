"""docs/architecture.md is generated from the code (`make docs`): a test fails when it is stale."""

from __future__ import annotations

import json
import re
from pathlib import Path

from tools.architecture import document
from tools.architecture.layers import CONTRACT
from tools.docs import main as docs_main

from ttt_sm.runtime.export import svg_dot_sha256

REPO = Path(__file__).resolve().parents[2]


def test_the_architecture_page_is_up_to_date():
    assert document.stale(REPO) == [], "regenerate with `make docs` (from the repository's root)"


def test_docs_check_covers_charts_and_the_page(capsys):
    assert docs_main(["check", "--root", str(REPO), "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == {"root": str(REPO), "stale": [], "ok": True}


def test_an_edited_page_or_a_picture_of_other_code_is_stale(tmp_path):
    written = document.export(tmp_path)
    assert [p.relative_to(tmp_path).as_posix() for p in written] == [
        "docs/architecture.md", "docs/img/architecture_layers.svg", "docs/img/architecture_control_step.svg"]
    assert document.stale(tmp_path) == []
    page, svg, _ = written
    page.write_text(page.read_text(encoding="utf-8").replace("| **twin** |", "| **Twin** |"), encoding="utf-8")
    text = svg.read_text(encoding="utf-8")
    svg.write_text(text.replace(svg_dot_sha256(text) or "", "0" * 64), encoding="utf-8")
    assert document.stale(tmp_path) == [str(page), str(svg)]


def test_the_page_shows_every_component_and_the_real_imports():
    text, dots = document.render()
    for comp in CONTRACT:
        assert f"| **{comp.name}** |" in text
    edges = set(re.findall(r'^  "([^"]+)" -> "([^"]+)" \[penwidth', dots["architecture_layers.svg"], re.M))
    assert ("app", "twin") in edges and ("charts", "runtime") in edges and ("sched", "twin") in edges
    assert not {("twin", "app"), ("runtime", "charts"), ("twin", "sched")} & edges


def test_a_section_added_to_the_list_appears_on_the_page(monkeypatch):
    def wiring(pictures: document.Pictures) -> str:
        return "## Wiring\n\n" + pictures.add("wiring", "digraph { a -> b }\n", "the wiring") + "\n"

    monkeypatch.setattr(document, "SECTIONS", [*document.SECTIONS, wiring])
    text, dots = document.render()
    assert text.rstrip().endswith("## Wiring\n\n![the wiring](img/architecture_wiring.svg)")
    assert dots["architecture_wiring.svg"] == "digraph { a -> b }\n"


def test_docs_check_outside_the_repository_is_one_line(tmp_path, capsys):
    assert docs_main(["check", "--root", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("tools.docs: error: ") and "no src/ttt_sm there" in err and err.count("\n") == 1
