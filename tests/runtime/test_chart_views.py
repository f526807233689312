"""Graphviz pictures of a chart with sub-charts: overview, one per sub-chart, the whole chart, legends."""

from __future__ import annotations

import html
import re
import shutil

import pytest
from statemachine import State

from ttt_sm.runtime import Data, TickChart
from ttt_sm.runtime.dot import legend_features, to_dot
from ttt_sm.runtime.dot_text import legend_dot, legend_markdown
from ttt_sm.runtime.dot_views import WHOLE, View, views
from ttt_sm.runtime.export import export_all, pictures, render_active, svg_from_dot

needs_dot = pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz dot not installed")


class Plotter(TickChart):
    """Wait, then draw or wipe, and come back; stop from anywhere."""

    inputs = (Data("go", "bool", False, "draw"), Data("dirty", "bool", False, "wipe"),
              Data("done", "bool", False, "move done"), Data("stop", "bool", False, "stop"))

    class base(State.Compound):
        idle = State(initial=True)
        back = State()
        back.to(idle, cond="done")

    class draw(State.Compound):
        pen_down = State(initial=True)
        stroke = State()
        lift = State()
        pen_down.to(stroke, cond="done")
        stroke.to(lift, cond="done")

    class wipe(State.Compound):
        sponge = State(initial=True)
        rinse = State()
        sponge.to(rinse, cond="done")

    halted = State(final=True)

    base.idle.to(wipe, cond="dirty")
    base.idle.to(draw, cond="go")
    draw.lift.to(base.back, cond="done")
    wipe.rinse.to(base.back, cond="done")
    draw.to(halted, cond="stop")
    wipe.to(halted, cond="stop")
    poke = base.to(None, on="count_poke")  # type: ignore[arg-type]

    def count_poke(self) -> None:
        pass

    def during_stroke(self) -> None:
        pass


def _edges(dot: str) -> list[str]:
    return [line.strip() for line in dot.splitlines() if " -> " in line]


def test_views_are_the_overview_one_per_sub_chart_and_the_whole_chart():
    assert [v.file_stem("Plotter") for v in views(Plotter)] == [
        "Plotter.overview", "Plotter.base", "Plotter.draw", "Plotter.wipe", "Plotter"]
    assert [name for _, name in pictures(Plotter)][0] == "Plotter.overview.svg"

    class Flat(TickChart):
        a = State(initial=True)
        b = State()
        a.to(b)

    assert views(Flat) == (WHOLE,)


def test_the_overview_closes_the_sub_charts_and_ends_edges_on_their_inner_states():
    overview = views(Plotter)[0]
    dot = to_dot(Plotter, view=overview)
    # sub-charts are boxes, not clusters; their inner states are not drawn as states
    assert "subgraph" not in dot
    for inner in ("idle", "pen_down", "stroke", "sponge"):
        assert f'"{inner}" [' not in dot
    # the edges between sub-charts start and end on the rows of the inner states they
    # leave from (idle, lift, rinse) or enter (back), which the boxes list
    edges = _edges(dot)
    assert '"base":"p_idle":s -> "draw" [label="2: [go]\\l"' in "\n".join(edges)
    assert '"base":"p_idle":s -> "wipe" [label="1: [dirty]\\l"' in "\n".join(edges)
    box = next(line for line in dot.splitlines() if line.strip().startswith('"base" ['))
    assert 'port="p_back"' in box and "▸ back" in box and "idle ▸" in box
    assert "poke / count_poke" in box  # a targetless transition is listed in its state
    assert not any("pen_down" in e or "stroke" in e for e in edges)  # inside a closed sub-chart
    assert 'URL="Plotter.draw.svg"' in dot


def test_the_same_transition_from_several_states_is_drawn_once_from_a_junction():
    dot = to_dot(Plotter, view=views(Plotter)[0])
    edges = _edges(dot)
    # lift and rinse -> back [done], draw and wipe -> halted [stop]: each pair meets at a dot
    joined = [e for e in edges if e.startswith('"join_')]
    assert len(joined) == 2
    assert any('"back"' not in e and '"halted" [label="[stop]\\l"' in e for e in joined)
    assert any('"base":"p_back":w [label="[done]\\l"' in e for e in joined)
    into_join = [e for e in edges if '-> "join_' in e]
    assert len(into_join) == 4 and all('arrowhead="none"' in e for e in into_join)
    # ... and each transition keeps its own id on its segment
    assert {re.search(r'id="(tr-\d+)"', e).group(1) for e in into_join} == {  # type: ignore[union-attr]
        f"tr-{t.index}" for t in Plotter.structure().transitions
        if (t.source, t.target) in {("lift", "back"), ("rinse", "back"), ("draw", "halted"), ("wipe", "halted")}}


def test_a_sub_chart_is_drawn_open_with_the_states_outside_it_as_linked_stubs():
    dot = to_dot(Plotter, view=View("draw", root="draw"))
    assert 'subgraph "cluster_draw"' in dot
    for inner in ("pen_down", "stroke", "lift"):
        assert f'"{inner}" [' in dot
    assert '"idle" [' not in dot and '"sponge" [' not in dot
    stubs = {m.group(1): m.group(2) for m in re.finditer(r'"stub__(\w+)" \[.*?URL="([^"]+)"', dot)}
    assert stubs == {"idle": "Plotter.base.svg", "back": "Plotter.base.svg", "halted": "Plotter.overview.svg"}
    edges = "\n".join(_edges(dot))
    assert ('"stub__idle" -> "draw__start" [label="2: [go]\\l", tooltip="idle → draw: 2: [go]",'
            ' lhead="cluster_draw"') in edges
    assert '"lift" -> "stub__back" [label="[done]\\l"' in edges
    assert '"draw" -> "stub__halted" [label="[stop]\\l", tooltip="draw → halted: [stop]", ltail="cluster_draw"' in edges
    assert "rinse" not in edges  # wipe's own transitions belong to wipe's picture


def _legend(dot: str) -> str:
    return dot[dot.index("Legend"):dot.index("</table>>")]


def test_the_legend_is_drawn_once_apart_from_the_pictures_with_what_they_use():
    for view in views(Plotter):
        assert "Legend" not in to_dot(Plotter, view=view)
    used = legend_features(Plotter)
    legend = _legend(legend_dot(used))
    # the overview and the sub-charts' pictures together draw these ...
    assert "transition without an event" in legend and "sub-chart, closed" in legend
    assert "drawn once from the dot" in legend and "outside this sub-chart" in legend
    assert "2: [guard]" in legend and "final state" in legend and "du: f" in legend
    # ... and no history junction, no connective junction
    assert "history" not in legend and "connective" not in legend
    assert "history" in _legend(legend_dot())  # every row, when asked for all
    rows = legend_markdown(used)
    assert rows[:2] == ["| on the picture | meaning |", "|---|---|"] and len(rows) == 2 + len(used)


@needs_dot
def test_the_pictures_render_with_titles_stable_ids_and_links(tmp_path):
    export_all([Plotter], tmp_path, ("svg",))
    overview = html.unescape((tmp_path / "Plotter.overview.svg").read_text())
    assert "Plotter — overview, sub-charts closed" in overview
    assert 'id="state-base"' in overview and 'xlink:href="Plotter.draw.svg"' in overview
    sub = html.unescape((tmp_path / "Plotter.draw.svg").read_text())
    assert 'id="state-stroke"' in sub and 'id="stub-idle"' in sub and 'xlink:href="Plotter.base.svg"' in sub
    whole = html.unescape(svg_from_dot(to_dot(Plotter)))
    for state in ("base", "idle", "back", "draw", "pen_down", "stroke", "lift", "wipe", "sponge", "rinse"):
        assert f'id="state-{state}"' in whole


def test_a_closed_sub_chart_is_highlighted_while_a_state_inside_it_is_active():
    chart = Plotter()
    chart.go = True
    chart.tick()
    assert chart.configuration_values == {"draw", "pen_down"}
    dot = render_active(chart, "dot", views(Plotter)[0])
    box = {line.strip().split(" ")[0]: line for line in dot.splitlines()
           if line.strip().startswith('"') and " -> " not in line}
    assert 'fillcolor="turquoise"' in box['"draw"'] and 'fillcolor="turquoise"' not in box['"base"']
    assert "Legend" not in dot
    sub = render_active(chart, "dot", View("draw", root="draw"))
    assert re.search(r'"pen_down" \[[^\n]*fillcolor="turquoise"', sub)
