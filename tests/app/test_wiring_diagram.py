"""The wiring drawn (charts/wiring.svg and its section of charts/index.md): from the table, and kept fresh."""

from __future__ import annotations

import html
import re
from pathlib import Path

from ttt_sm.app.wires import GAME_WIRES, ROBOT_WIRES
from ttt_sm.app.wiring import check
from ttt_sm.app.wiring_diagram import all_blocks, wiring_diagram, wiring_dot
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


def test_every_chart_is_a_block_and_every_wire_a_label_on_an_arrow_of_the_drawing():
    svg = (CHARTS / "wiring.svg").read_text(encoding="utf-8")
    texts = {html.unescape(text) for text in re.findall(r"<text[^>]*>([^<]*)</text>", svg)}
    for chart in ALL_CHARTS:
        assert chart.__name__ in texts, chart.__name__
    for block in ("Encoder", "IK", "FK", "Drives", "Homing", "EraseFlag", "Session"):
        assert block in texts
    missing = [label for label in _labels() if label not in texts]
    assert missing == []
    # one arrow per pair of blocks that a wire joins
    pairs = {(r.source.block, r.target.block) for r in check([*ROBOT_WIRES, *GAME_WIRES], all_blocks())}
    assert svg.count('class="edge"') == len(pairs)


def test_the_wiring_section_of_the_index_shows_the_picture_and_every_row():
    index = (CHARTS / "index.md").read_text(encoding="utf-8")
    assert "## Wiring" in index and "![How the charts are wired](wiring.svg)" in index
    for wire in (*ROBOT_WIRES, *GAME_WIRES):
        assert f"| `{wire.source}` | `{wire.target}` |" in index, wire


def test_a_changed_table_makes_the_drawing_stale():
    assert stale_files(ALL_CHARTS, CHARTS, REPO_CHART_FORMATS, [wiring_diagram()]) == []
    fewer = ExtraDiagram("wiring", wiring_dot(ROBOT_WIRES[:-1]), wiring_diagram().section)
    assert stale_files(ALL_CHARTS, CHARTS, REPO_CHART_FORMATS, [fewer]) == [str(CHARTS / "wiring.svg")]


def test_every_block_of_the_drawing_has_its_column_so_no_arrow_crosses_the_whole_picture():
    # A block without a column is placed where Graphviz likes: the Safety chart's inputs then ran from its
    # monitors at the far left across every other block to it.
    from ttt_sm.app.wiring_diagram import COLUMNS

    drawn = {end.block for r in check([*ROBOT_WIRES, *GAME_WIRES], all_blocks()) for end in (r.source, r.target)}
    placed = {name for column in COLUMNS for name in column}
    assert sorted(drawn - placed) == []
