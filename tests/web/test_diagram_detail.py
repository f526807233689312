"""The cockpit's SVG carries what each state and transition does, whole; the legend is a picture of its own."""

from __future__ import annotations

from xml.dom import minidom

import pytest

from ttt_sm.charts import Control, DriveInit1
from ttt_sm.runtime.action_text import action_text
from ttt_sm.web.diagrams import DiagramError, Diagrams


def _groups(svg: str) -> dict[str, minidom.Element]:
    return {g.getAttribute("id"): g for g in minidom.parseString(svg).getElementsByTagName("g") if g.getAttribute("id")}


def test_a_state_and_an_edge_carry_their_actions_whole_in_data_detail_and_title() -> None:
    diagrams = Diagrams({"DriveInit1": DriveInit1})
    groups = _groups(diagrams.svg("DriveInit1", "whole"))
    entry = action_text(DriveInit1, "on_enter_turn_fwd")
    assert entry is not None and not entry.short  # the picture summarises it ...
    state = groups["state-turn_fwd"]
    assert f"en: {entry.full}" in state.getAttribute("data-detail")  # ... the element keeps it whole
    title = state.getElementsByTagName("title")[0].firstChild
    assert isinstance(title, minidom.Text) and f"en: {entry.full}" in title.data
    index = next(t.index for t in DriveInit1.structure().transitions
                 if t.source == "turn_fwd" and t.target == "turn_back")
    edge = groups[f"tr-{index}"]
    assert edge.getAttribute("data-detail") == (
        "turn_fwd → turn_back: 2: [stalled] / pos_out = enc_prev = pos_Encoder; index_start = index;"
        " direction = -1; moving = False")
    # the link wrappers are gone: an edge's path is its own child (the page's `.edge > path` styles)
    assert not [g for g in groups if g.startswith("a_")]
    assert any(c.nodeName == "path" for c in edge.childNodes)


def test_the_legend_is_its_own_picture_of_what_the_charts_pictures_use() -> None:
    diagrams = Diagrams({"Control": Control, "DriveInit1": DriveInit1})
    assert "Legend" not in diagrams.svg("Control", "overview")
    control = diagrams.svg("Control", "legend")
    assert "Legend" in control and "sub-chart, closed" in control and "history junction" not in control
    assert "history junction" in diagrams.svg("DriveInit1", "legend")  # DriveInit1 draws its H*
    with pytest.raises(DiagramError, match="opens no sub-charts"):
        diagrams.svg("Control", "legend", ("Erase",))
