"""The wiring table drawn: which chart feeds which, with the data on the arrows.

What Simulink shows as signal lines between Stateflow blocks, drawn from
:data:`~ttt_sm.app.wires.ROBOT_WIRES` and :data:`~ttt_sm.app.wires.GAME_WIRES`
with Graphviz: charts are blue blocks, the other blocks of the loop grey, and
each arrow carries the data it feeds (``ini_23 → ini1``: the source's output,
then the target's input where their names differ).  One picture of every wire
is four times as wide as it is tall and unreadable at a page's width, so the
wiring is drawn in three parts (:data:`PARTS`: the drives, the game, the
Safety chart); a block may appear in several, each wire in exactly one.
``ttt-sm charts export`` writes them as ``charts/wiring_<part>.svg`` with a
section of ``charts/index.md``; docs/architecture.md shows the same section.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from ..charts import ALL_CHARTS
from ..runtime.export import ExtraDiagram
from .wires import BLOCKS, GAME_WIRES, ROBOT_WIRES
from .wiring import Block, CheckedWire, Wire, chart_block, check

#: Left to right, the order of one chart step: the game, the Control chart, inverse
#: kinematics and the Encoder blocks, the init charts, the drives (and whether they
#: are initialised), then the Safety chart, its monitors beside it and what it asks
#: of the drives.  Every block has a column (a test checks it): one Graphviz places
#: at will can end up far from its wires.  Blocks in one
#: column share a rank; arrows that run back (a chart's output read at the next
#: step) are drawn back.
COLUMNS: tuple[tuple[str, ...], ...] = (
    ("AlgorithmActivator",),
    ("Session",),
    ("Game",),
    ("EraseFlag", "FK"),
    ("Control",),
    ("IK", "Encoder"),
    ("DriveInit1",),  # drive 1 first: drives 2 and 3 wait for its ini_23
    ("DriveInit2",),
    ("DriveInit3",),
    ("Drives", "Homing"),
    ("Monitor", "Link", "Camera"),
    ("Safety",),
    ("SafeState",),
)



@dataclass(frozen=True)
class Part:
    """One picture of the wiring: its blocks; a wire is drawn in the first part that has both its ends."""

    name: str
    title: str
    blocks: frozenset[str]


#: The pictures, in the order a wire looks for its part.
PARTS: tuple[Part, ...] = (
    Part("drives", "One chart step: the Control chart, inverse kinematics, the init charts and the drives",
         frozenset({"FK", "Control", "IK", "Encoder", "DriveInit1", "DriveInit2", "DriveInit3", "Drives", "Homing"})),
    Part("game", "A game: the Game chart, the AlgorithmActivator and the Control chart",
         frozenset({"AlgorithmActivator", "Session", "Game", "EraseFlag", "Control", "Homing"})),
    Part("safety", "The Safety chart: what it watches and what it asks of the drives",
         frozenset({"Homing", "FK", "Monitor", "Link", "Camera", "Safety", "SafeState"})),
)

_CHART_STYLE = 'shape=box, style="rounded,filled", fillcolor="#d6e6f5", color="#3b6ea8", penwidth=1.4'
_BLOCK_STYLE = 'shape=box, style="filled", fillcolor="#eeeeee", color="#777777"'


def all_blocks() -> list[Block]:
    """Every chart of the project as a block, and the other blocks of the loop."""
    return [*(chart_block(c) for c in ALL_CHARTS), *BLOCKS]


def _quote(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _label(row: CheckedWire) -> str:
    source = row.source.port + ("" if row.source.index is None else f"[{row.source.index}]")
    target = row.target.port + ("" if row.target.index is None else f"[{row.target.index}]")
    return source if source == target else f"{source} → {target}"


def part_of(source: str, target: str) -> Part:
    """The picture a wire from block `source` to block `target` is drawn in (ValueError: none has both)."""
    for part in PARTS:
        if source in part.blocks and target in part.blocks:
            return part
    raise ValueError(f"no part of the wiring's pictures (PARTS) has both {source} and {target}: add them to one")


def wiring_dot(wires: Iterable[Wire] = (*ROBOT_WIRES, *GAME_WIRES), blocks: Sequence[Block] | None = None,
               part: str | None = None) -> str:
    """Graphviz source of the wiring: one node per block, one arrow per pair of blocks, labelled per wire.

    `part`: only the wires drawn in that :data:`PARTS` picture (None: every wire, in one picture).
    """
    blocks = list(blocks) if blocks is not None else all_blocks()
    rows = check(wires, blocks)
    if part is not None:
        if part not in {p.name for p in PARTS}:
            raise ValueError(f"no part {part!r} of the wiring; parts: {', '.join(p.name for p in PARTS)}")
        rows = [r for r in rows if part_of(r.source.block, r.target.block).name == part]
    title = next((p.title for p in PARTS if p.name == part), "How the charts are wired")
    used = {r.source.block for r in rows} | {r.target.block for r in rows}
    edges: dict[tuple[str, str], list[str]] = {}
    for row in rows:
        edges.setdefault((row.source.block, row.target.block), []).append(_label(row))
    lines = [
        "digraph wiring {",
        '  graph [rankdir=LR, fontname="Helvetica", nodesep=0.35, ranksep=0.9, newrank=true,'
        f' label={_quote(title + " (ttt_sm.app.wires): blue = chart, grey = another block of the loop")},'
        " labelloc=t, fontsize=12];",
        '  node [fontname="Helvetica", fontsize=11];',
        '  edge [fontname="Helvetica", fontsize=9, color="#555555", arrowsize=0.7];',
    ]
    for block in blocks:
        if block.name not in used:
            continue
        style = _CHART_STYLE if block.chart else _BLOCK_STYLE
        kind = "chart" if block.chart else block.doc
        label = f"<<b>{block.name}</b><br/><font point-size=\"8\">{_html(kind)}</font>>"
        lines.append(f"  {block.name} [{style}, label={label}, tooltip={_quote(block.doc)}];")
    column_of = {name: k for k, column in enumerate(COLUMNS) for name in column}
    placed = [[name for name in column if name in used] for column in COLUMNS]
    placed = [column for column in placed if column]
    for column in placed:
        lines.append(f"  {{rank=same; {'; '.join(column)}}}")
    for left, right in zip(placed, placed[1:], strict=False):  # keep the columns in order
        lines.append(f"  {left[0]} -> {right[0]} [style=invis];")
    for (source, target), labels in edges.items():
        back = column_of.get(source, 0) >= column_of.get(target, 0)
        extra = ", constraint=false" if back else ""
        lines.append(f"  {source} -> {target} [label={_quote(chr(10).join(labels))}{extra}];")
    lines.append("}")
    return "\n".join(lines) + "\n"


def _html(text: str) -> str:
    text = text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
    words, out, width = text.split(), [], 0
    for word in words:  # wrap at about 28 characters, so grey blocks stay narrow
        if width and width + len(word) > 28:
            out.append("<br/>")
            width = 0
        out.append(("" if not width else " ") + word)
        width += len(word) + 1
    return "".join(out)


def wiring_table(wires: Iterable[Wire], blocks: Sequence[Block] | None = None) -> str:
    """The rows as a Markdown table: source, target, unit, what the target means."""
    rows = check(wires, list(blocks) if blocks is not None else all_blocks())
    lines = ["| source | target | unit | what the target takes |", "|---|---|---|---|"]
    for row in rows:
        lines.append(f"| `{row.source}` | `{row.target}` | {row.target_port.unit} | {row.target_port.doc} |")
    return "\n".join(lines)


def wiring_section(directory: str = "", heading: str = "##") -> str:
    """Markdown: the pictures (``<directory>wiring_<part>.svg``) and the table of the robot's and a game's wires."""
    return "\n".join([
        f"{heading} Wiring",
        "",
        "Charts read each other only through declared data: one table wires a chart's output, or an",
        "output of another block of the loop, to a chart's input (`ttt_sm.app.wires`).  The Robot",
        "checks it against the charts' declarations when it is built (a misspelt name, an output",
        "used as a target, a unit mismatch raise `WiringError` naming the row) and compiles it into",
        "plain attribute copies run at every chart step.",
        "",
        *(line for p in PARTS for line in (f"![{p.title}]({directory}wiring_{p.name}.svg)", "")),
        f"{heading}# Every robot: the init charts and the Control chart",
        "",
        wiring_table(ROBOT_WIRES),
        "",
        f"{heading}# A game adds the Game chart and the AlgorithmActivator",
        "",
        wiring_table(GAME_WIRES),
        "",
    ])


def wiring_diagrams() -> tuple[ExtraDiagram, ...]:
    """What `ttt-sm charts export` writes beside the charts: `wiring_<part>.svg` and their index.md section."""
    return tuple(ExtraDiagram(name=f"wiring_{p.name}", dot=wiring_dot(part=p.name),
                              section=wiring_section() if k == 0 else "") for k, p in enumerate(PARTS))
