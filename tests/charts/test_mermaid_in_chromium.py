"""The Mermaid diagrams of charts/*.md, rendered by the Mermaid library in Chromium, as a reader sees them.

GitHub and most Markdown viewers draw a page's ```mermaid blocks with the Mermaid
library; this test does the same with the pinned release of ``tests/js`` and
reads back the drawn text: every state box must be titled with the state's name
(the tutorial starts with "find ``turn_fwd``"), and every transition's trigger
and guard must be drawn.  All pages render in one browser page.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from ttt_sm.charts import ALL_CHARTS
from ttt_sm.runtime.diagram import structure_of
from ttt_sm.runtime.structure import ChartStructure

REPO = Path(__file__).resolve().parents[2]
RENDER_JS = REPO / "tests" / "js" / "render_mermaid.js"
BLOCK = re.compile(r"```mermaid\n(.*?)```", re.S)


@pytest.fixture(scope="module")
def mermaid(browser: Any, js_file: Callable[[str], Path]) -> Iterator[Callable[[list[str]], list[dict[str, Any]]]]:
    """``mermaid(diagrams)``: what the Mermaid library draws for each diagram text, in one page."""
    page = browser.new_page()
    page.set_content("<!doctype html><html><body></body></html>")
    page.add_script_tag(path=str(js_file("mermaid/dist/mermaid.min.js")))
    page.add_script_tag(path=str(RENDER_JS))
    try:
        yield lambda diagrams: page.evaluate("diagrams => renderMermaid(diagrams)", diagrams)
    finally:
        page.close()


@pytest.fixture(scope="module")
def rendered(mermaid: Callable[[list[str]], list[dict[str, Any]]]) -> dict[str, list[dict[str, Any]]]:
    """Chart name -> what Mermaid drew for each ```mermaid block of charts/<Name>.md."""
    pages = {c.__name__: BLOCK.findall((REPO / "charts" / f"{c.__name__}.md").read_text()) for c in ALL_CHARTS}
    results = iter(mermaid([code for blocks in pages.values() for code in blocks]))
    return {name: [next(results) for _ in blocks] for name, blocks in pages.items()}


def _words(text: str) -> str:
    return " ".join(text.split())


def _missing_names(structure: ChartStructure, drawn: list[dict[str, Any]]) -> list[str]:
    """States of the chart that no drawn box carries as its title."""
    titles = {_words(box["texts"][0]) for d in drawn for box in d["boxes"]
              if box["texts"] and box["kind"] != "note"}
    return [s.label for s in structure.states if s.label not in titles]


@pytest.mark.parametrize("chart", ALL_CHARTS, ids=lambda c: c.__name__)
def test_every_state_is_drawn_titled_with_its_name(chart, rendered):
    drawn = rendered[chart.__name__]
    assert drawn, f"charts/{chart.__name__}.md has no mermaid block"
    errors = [d["error"] for d in drawn if "error" in d]
    assert not errors, f"Mermaid could not draw charts/{chart.__name__}.md: {errors}"
    assert _missing_names(structure_of(chart), drawn) == []


def _inside(inner: dict[str, float], outer: dict[str, float]) -> bool:
    return (inner["left"] >= outer["left"] and inner["right"] <= outer["right"]
            and inner["top"] >= outer["top"] and inner["bottom"] <= outer["bottom"])


@pytest.mark.parametrize("chart", ALL_CHARTS, ids=lambda c: c.__name__)
def test_every_state_is_drawn_inside_its_compound_state_and_no_other(chart, rendered):
    # Mermaid draws a state in the composite block of the last transition naming it:
    # a state drawn outside its compound would tell a reader the wrong story.
    structure = structure_of(chart)
    boxes = {_words(box["texts"][0]): box for d in rendered[chart.__name__] if "error" not in d
             for box in d["boxes"] if box["texts"] and box["kind"] != "note"}
    composites = {s.id: boxes[s.label]["rect"] for s in structure.states if s.is_compound}
    misplaced = []
    for s in structure.states:
        if s.history:
            continue  # titled H or H*, not by a unique name
        inside = {c for c, rect in composites.items() if c != s.id and _inside(boxes[s.label]["rect"], rect)}
        ancestors, node = set(), s.parent
        while node is not None:
            ancestors.add(node)
            node = structure.state(node).parent
        if inside != ancestors:
            misplaced.append(f"{s.id}: drawn in {sorted(inside)}, belongs in {sorted(ancestors)}")
    assert misplaced == []


@pytest.mark.parametrize("chart", ALL_CHARTS, ids=lambda c: c.__name__)
def test_every_guard_and_event_is_drawn(chart, rendered):
    drawn = [d for d in rendered[chart.__name__] if "error" not in d]
    edge_text = [_words(text) for d in drawn for text in d["edgeLabels"]]
    box_text = [_words(text) for d in drawn for box in d["boxes"] for text in box["texts"]]
    missing = []
    for t in structure_of(chart).transitions:
        # a transition that leaves no state is listed in its state's box, not drawn as an edge
        texts = edge_text if t.target is not None else box_text
        wanted = [f"[{' and '.join(t.guards)}]"] if t.guards else []
        wanted += list(t.events)
        for piece in wanted:
            if not any(piece in text for text in texts):
                missing.append(f"{t.label}: {piece}")
    assert missing == []


def test_the_check_sees_names_replaced_by_actions_and_syntax_errors(mermaid):
    # The way charts/ was written before: `s : entry / ...` alone.  Mermaid then titles
    # the box with the first action, and the name is drawn nowhere.
    old = "stateDiagram-v2\n    [*] --> turn_fwd\n    turn_fwd : entry / on_enter_turn_fwd\n" \
          "    turn_fwd : during / during_turn_fwd\n"
    broken = "stateDiagram-v2\n    a --> b : x\n    state {\n"
    (drawn_old, drawn_broken) = mermaid([old, broken])
    titles = [box["texts"][0] for box in drawn_old["boxes"] if box["texts"]]
    assert "entry / on_enter_turn_fwd" in titles and "turn_fwd" not in titles
    assert "error" in drawn_broken and "Parse error" in drawn_broken["error"]


def test_the_tutorials_first_step_can_be_done_on_the_rendered_page(rendered):
    tutorial = (REPO / "docs" / "tutorial.md").read_text()
    step = tutorial[tutorial.index("## 1."):tutorial.index("## 2.")]
    drawn = rendered["DriveInit1"]
    boxes = {_words(box["texts"][0]): box for d in drawn for box in d["boxes"] if box["texts"]}
    nesting = re.search(r"the compound state `(\w+)` holding\s+`(\w+)`, which holds (.*?);", step, re.S)
    assert nesting, "the tutorial's first step no longer names the nesting"
    outer, inner, held = nesting.group(1), nesting.group(2), re.findall(r"`(\w+)`", nesting.group(3))
    assert held == ["power_on", "turn_fwd", "turn_back", "go_park", "wait_23"]
    assert _inside(boxes[inner]["rect"], boxes[outer]["rect"])
    assert all(_inside(boxes[name]["rect"], boxes[inner]["rect"]) for name in held)
    edge = re.search(r"the edge `(\w+) --> (\w+) : ([^`]+)`", step)
    assert edge and edge.group(3) in [_words(text) for d in drawn for text in d["edgeLabels"]]
    during = re.search(r"the during action in `(\w+)`'s box, `(du: [^`]+)`", step)
    assert during, "the tutorial's first step no longer quotes a during action"
    assert during.group(1) == "turn_fwd" and during.group(2) in "\n".join(boxes["turn_fwd"]["texts"][1:])
