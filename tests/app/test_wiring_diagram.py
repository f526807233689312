"""The wiring drawn (charts/wiring_<part>.svg and their section of charts/index.md): from the table, and kept fresh."""

from __future__ import annotations

import html
import re
from pathlib import Path

import pytest

from ttt_sm.app.wires import GAME_WIRES, ROBOT_WIRES
from ttt_sm.app.wiring import check
from ttt_sm.app.wiring_diagram import PARTS, all_blocks, part_of, wiring_diagrams, wiring_dot
from ttt_sm.charts import ALL_CHARTS
from ttt_sm.cli.commands import REPO_CHART_FORMATS
from ttt_sm.runtime.export import ExtraDiagram, stale_files

REPO = Path(__file__).resolve().parents[2]
CHARTS = REPO / "charts"


def _labels() -> list[str]:
    rows = check([*ROBOT_WIRES, *GAME_WIRES], all_blocks())
    labels = []
    for r in rows:
        source = r.source.port + ("" if r.source.index is None else f"[{r.source.index}]")
        target = r.target.port + ("" if r.target.index is None else f"[{r.target.index}]")
        labels.append(source if source == target else f"{source} → {target}")
    return labels


def _svgs() -> dict[str, str]:
    return {p.name: (CHARTS / f"wiring_{p.name}.svg").read_text(encoding="utf-8") for p in PARTS}


def _texts(svg: str) -> set[str]:
    return {html.unescape(text) for text in re.findall(r"<text[^>]*>([^<]*)</text>", svg)}


def test_every_chart_is_a_block_and_every_wire_a_label_on_an_arrow_of_the_drawings():
    svgs = _svgs()
    texts = set().union(*(_texts(svg) for svg in svgs.values()))
    for chart in ALL_CHARTS:
        assert chart.__name__ in texts, chart.__name__
    for block in ("Encoder", "IK", "FK", "Drives", "Homing", "EraseFlag", "Session"):
        assert block in texts
    missing = [label for label in _labels() if label not in texts]
    assert missing == []
    # one arrow per pair of blocks that a wire joins, in the picture of its part and in no other
    pairs = {(r.source.block, r.target.block) for r in check([*ROBOT_WIRES, *GAME_WIRES], all_blocks())}
    for part in PARTS:
        mine = [pair for pair in pairs if part_of(*pair) is part]
        assert svgs[part.name].count('class="edge"') == len(mine), part.name
    assert sum(svg.count('class="edge"') for svg in svgs.values()) == len(pairs)


def test_no_picture_is_much_wider_than_a_page_holds():
    # one picture of every wire was 3161 x 798 pt: at a page's width its labels were a few pixels high
    for name, svg in _svgs().items():
        match = re.search(r'<svg width="(\d+)pt" height="(\d+)pt"', svg)
        assert match, name
        width, height = int(match[1]), int(match[2])
        assert width <= 1800 and width / height <= 5.5, (name, width, height)


def test_a_wire_between_blocks_no_part_has_is_refused():
    with pytest.raises(ValueError, match="no part of the wiring's pictures .* has both Monitor and Game"):
        part_of("Monitor", "Game")
    with pytest.raises(ValueError, match="no part 'arm'"):
        wiring_dot(part="arm")


def test_the_wiring_section_of_the_index_shows_the_picture_and_every_row():
    index = (CHARTS / "index.md").read_text(encoding="utf-8")
    assert "## Wiring" in index
    for part in PARTS:
        assert f"![{part.title}](wiring_{part.name}.svg)" in index
    for wire in (*ROBOT_WIRES, *GAME_WIRES):
        assert f"| `{wire.source}` | `{wire.target}` |" in index, wire


def test_a_changed_table_makes_the_drawing_stale():
    assert stale_files(ALL_CHARTS, CHARTS, REPO_CHART_FORMATS, wiring_diagrams()) == []
    last = check(ROBOT_WIRES, all_blocks())[-1]
    part = part_of(last.source.block, last.target.block).name
    fewer = [ExtraDiagram(d.name, wiring_dot(ROBOT_WIRES[:-1], part=part), d.section) if d.name == f"wiring_{part}"
             else d for d in wiring_diagrams()]
    assert stale_files(ALL_CHARTS, CHARTS, REPO_CHART_FORMATS, fewer) == [str(CHARTS / f"wiring_{part}.svg")]


def test_every_block_of_the_drawing_has_its_column_so_no_arrow_crosses_the_whole_picture():
    # A block without a column is placed where Graphviz likes: the Safety chart's inputs then ran from its
    # monitors at the far left across every other block to it.
    from ttt_sm.app.wiring_diagram import COLUMNS

    drawn = {end.block for r in check([*ROBOT_WIRES, *GAME_WIRES], all_blocks()) for end in (r.source, r.target)}
    placed = {name for column in COLUMNS for name in column}
    assert sorted(drawn - placed) == []
