"""Diagram export: nested clusters, Mermaid, Markdown page, determinism, staleness, highlighting."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys

import pytest
from statemachine import HistoryState, State

from ttt_sm.runtime import Data, TickChart, after
from ttt_sm.runtime.diagram import to_markdown, to_mermaid
from ttt_sm.runtime.dot import to_dot
from ttt_sm.runtime.export import export_all, export_chart, render_active, stale_files
from ttt_sm.runtime.listeners import Coverage

needs_dot = pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz dot not installed")


class Lamp(TickChart):
    """A lamp with a dimmer."""

    inputs = (Data("switch", "bool", False, "wall switch"),)
    outputs = (Data("level", "1", 0.0, "light level"),)

    off = State(initial=True)

    class on(State.Compound):
        dim = State(initial=True)
        bright = State()
        dim.to(bright, cond=after(3), on="louder")
        bright.to(dim, cond="not switch")

        def during_dim(self) -> None:
            self.level = self.level_p + 1

    off.to(on, cond="switch")
    on.to(off, cond="not switch")
    button = off.to(on)

    def louder(self) -> None:
        self.level += 10

    def on_enter_off(self) -> None:
        self.level = 0.0


def _cluster_body(dot: str, name: str) -> str:
    start = dot.index(f'subgraph "cluster_{name}" {{')
    depth, i = 0, start
    while True:
        if dot[i] == "{":
            depth += 1
        elif dot[i] == "}":
            depth -= 1
            if depth == 0:
                return dot[start:i]
        i += 1


def test_dot_draws_compound_states_as_nested_clusters_with_guards_and_actions():
    dot = to_dot(Lamp)
    body = _cluster_body(dot, "on")
    assert '"dim" [' in body and '"bright" [' in body and '"off" [' not in body
    # actions read as what they do (their own statements, Stateflow's en:/du:), inside the state
    assert "du: level = level_p + 1" in body
    assert "en: level = 0.0" in dot
    assert '"dim" -> "bright" [label="[after(3)]\\l/ level += 10\\l"' in dot
    # off's two transitions into on are tried in the order written: their execution order is drawn
    assert '"off" -> "on__start" [label="1: [switch]\\l", tooltip="off → on: 1: [switch]", lhead="cluster_on"' in dot
    assert '"on" -> "off" [label="[not switch]\\l", tooltip="on → off: [not switch]", ltail="cluster_on"' in dot
    assert '"off" -> "on__start" [label="2: button\\l"' in dot


def test_mermaid_nests_compound_states():
    text = to_mermaid(Lamp)
    assert text.startswith("stateDiagram-v2\n")
    nested = re.search(r"state on \{\n(.*?)\n    \}", text, re.S)
    assert nested is not None
    assert "[*] --> dim" in nested.group(1)
    assert "dim --> bright : [after(3)] / level += 10" in nested.group(1)
    assert "dim : du#58; level = level_p + 1" in nested.group(1)
    assert "off --> on : 1#58; [switch]" in text and "off --> on : 2#58; button" in text


def test_markdown_page_has_the_mermaid_block_and_data_table():
    page = to_markdown(Lamp)
    assert page.startswith("# Lamp\n\nA lamp with a dimmer.\n")
    assert "```mermaid\nstateDiagram-v2\n" in page
    assert "| input | `switch` | bool | `False` | wall switch |" in page
    assert "| output | `level` | 1 | `0.0` | light level (previous tick: `level_p`) |" in page
    assert "| `dim` | `bright` | outer | 1 | tick | after(3) | — | `louder`: `level += 10` |" in page
    assert "| `dim` (initial) | on | — | `during_dim`: `level = level_p + 1` | — |" in page


def test_render_active_highlights_the_active_states():
    lamp = Lamp()
    lamp.switch = True
    lamp.tick()
    dot = render_active(lamp, "dot")
    assert re.search(r'"dim" \[[^\n]*fillcolor="turquoise"', dot)
    assert not re.search(r'"off" \[[^\n]*fillcolor="turquoise"', dot)
    assert "filled" in _cluster_body(dot, "on")
    mermaid = render_active(lamp, "mermaid")
    assert "class on active" in mermaid and "class dim active" in mermaid
    assert "class off active" not in mermaid
    assert "turquoise" not in to_dot(Lamp)  # the class diagram highlights nothing


def test_text_export_is_deterministic_and_stale_files_are_found(tmp_path):
    formats = ("mermaid", "dot")
    written = export_all([Lamp], tmp_path, formats)
    # Lamp's compound state `on` is a sub-chart: an overview and its own picture besides the whole chart
    assert sorted(p.name for p in written) == ["Lamp.dot", "Lamp.md", "Lamp.on.dot", "Lamp.overview.dot", "index.md"]
    first = {p.name: p.read_bytes() for p in written}
    export_all([Lamp()], tmp_path, formats)  # an instance exports as its class
    assert {p.name: p.read_bytes() for p in written} == first
    assert stale_files([Lamp], tmp_path, formats) == []

    (tmp_path / "Lamp.dot").write_text("digraph {}\n")
    (tmp_path / "Lamp.md").unlink()
    assert stale_files([Lamp], tmp_path, formats) == [str(tmp_path / "Lamp.dot"), str(tmp_path / "Lamp.md")]


def test_a_changed_chart_makes_its_files_stale(tmp_path):
    export_all([Lamp], tmp_path, ("mermaid", "dot"))

    class Edited(TickChart):  # the same name, one more state: someone edited the chart
        """A lamp that can break."""

        off = State(initial=True)
        on = State()
        broken = State()
        off.to(on)
        on.to(off)
        on.to(broken)

    Edited.__name__ = "Lamp"
    # ... and without its compound state it has no sub-chart pictures: export would remove them
    assert stale_files([Edited], tmp_path, ("mermaid", "dot")) == [
        str(tmp_path / "Lamp.dot"), str(tmp_path / "Lamp.md"), str(tmp_path / "Lamp.on.dot"),
        str(tmp_path / "Lamp.overview.dot"), str(tmp_path / "index.md")]
    (tmp_path / "notes.txt").write_text("kept")
    export_all([Edited], tmp_path, ("mermaid", "dot"))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["Lamp.dot", "Lamp.md", "index.md", "notes.txt"]
    assert stale_files([Edited], tmp_path, ("mermaid", "dot")) == []


def test_dot_text_is_identical_in_a_fresh_interpreter(tmp_path):
    # Nothing in the text depends on object ids or hash seeds.
    export_chart(Lamp, tmp_path, ("dot",))
    code = (
        "import sys; sys.path.insert(0, sys.argv[1]);"
        "from test_chart_diagrams import Lamp; from ttt_sm.runtime.dot import to_dot;"
        "sys.stdout.write(to_dot(Lamp))"
    )
    here = str(__import__("pathlib").Path(__file__).parent)
    out = subprocess.run([sys.executable, "-c", code, here], capture_output=True, text=True,
                         check=True, env={"PYTHONHASHSEED": "123", "PATH": ""}).stdout
    assert out == (tmp_path / "Lamp.dot").read_text()


@needs_dot
def test_svg_and_png_carry_the_dot_hash_and_re_export_identically(tmp_path):
    written = export_chart(Lamp, tmp_path)
    assert sorted(p.name for p in written) == [
        "Lamp.dot", "Lamp.md", "Lamp.on.dot", "Lamp.on.png", "Lamp.on.svg",
        "Lamp.overview.dot", "Lamp.overview.png", "Lamp.overview.svg", "Lamp.png", "Lamp.svg"]
    svg = (tmp_path / "Lamp.svg").read_text()
    assert "Generated by graphviz" not in svg and "ttt_sm-dot-sha256" in svg
    assert 'class="cluster"' in svg
    assert (tmp_path / "Lamp.png").read_bytes().startswith(b"\x89PNG")
    before = {p.name: p.read_bytes() for p in written}
    export_chart(Lamp, tmp_path)
    assert {p.name: p.read_bytes() for p in written} == before
    export_all([Lamp], tmp_path)
    assert stale_files([Lamp], tmp_path) == []
    # a rendered file from an older chart is stale, told by its hash alone
    svg_path = tmp_path / "Lamp.svg"
    svg_path.write_text(re.sub(r"sha256: [0-9a-f]{64}", "sha256: " + "0" * 64, svg))
    assert stale_files([Lamp], tmp_path) == [str(svg_path)]


@needs_dot
def test_render_active_svg_and_png():
    lamp = Lamp()
    svg = render_active(lamp, "svg")
    assert svg.lstrip().startswith("<?xml") and "turquoise" in svg
    assert render_active(lamp, "png").startswith(b"\x89PNG")
    with pytest.raises(ValueError, match="unknown format"):
        render_active(lamp, "gif")


class Resumable(TickChart):
    """Work resumes where it paused: a history state."""

    inputs = (Data("go", "bool", False, "next step"),)

    class work(State.Compound):
        a = State(initial=True)
        b = State()
        h = HistoryState()
        a.to(b, cond="go")

    pause = State()
    hold = work.to(pause)
    resume = pause.to(work.h)


def test_history_states_are_drawn_inside_their_compound_and_not_counted_as_states():
    dot = to_dot(Resumable)
    assert '"h" [label="H", shape="circle"' in _cluster_body(dot, "work")
    assert '"pause" -> "h" [label="resume\\l"' in dot
    assert 'state "H" as h' in to_mermaid(Resumable)
    assert "| `h` (shallow history) | work |" in to_markdown(Resumable)
    chart = Resumable()
    coverage = Coverage().observe(chart)
    chart.go = True
    chart.tick()
    chart.post("hold")
    chart.tick()
    chart.post("resume")
    chart.tick()
    assert chart.configuration_values == {"work", "b"}
    report = coverage.report().charts[0]
    assert "h" not in report.states and report.missing_states == ()
