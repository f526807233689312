"""Diagram text of a chart: Mermaid, a Markdown page, and what every diagram shares.

Drawn from the chart's :class:`~.structure.ChartStructure`, not from the
library's renderers, so that

* compound states are nested, tick transitions show their Stateflow priority,
  guards and actions sit on the edges, and entry/during/exit actions are listed
  inside the states (Graphviz pictures: :mod:`.dot`);
* the text is a pure function of the chart class (and, for :func:`to_mermaid`
  with ``active``, of the active states): byte-identical on every export, so a
  test can tell a stale ``charts/`` folder.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from statemachine import StateChart

from .action_text import HELPERS, action_text, helpers
from .structure import ChartStructure, StateInfo, TransitionInfo

ACTIVE_FILL = "turquoise"
ACTIVE_CLUSTER_FILL = "#e3f8f6"
FONT = "Helvetica"


def chart_class(chart: StateChart | type[StateChart]) -> type[StateChart]:
    """The class of a chart given as a class or an instance."""
    return chart if isinstance(chart, type) else type(chart)


def structure_of(chart: StateChart | type[StateChart]) -> ChartStructure:
    cls = chart_class(chart)
    structure = getattr(cls, "_structure", None)
    if structure is None:
        raise TypeError(f"{cls.__name__} is not a TickChart subclass")
    return structure


def active_ids(chart: StateChart) -> set[str]:
    """Ids of the states active in a chart instance."""
    return {s.id for s in chart.configuration}


# -- shared text -------------------------------------------------------------


#: Stateflow's keywords of a state's actions.
KEYWORDS = (("entry", "en"), ("during", "du"), ("exit", "ex"))


def action_lines(cls: type | None, name: str) -> tuple[str, ...]:
    """What action ``name`` does as the picture writes it (:mod:`.action_text`), else its name."""
    text = action_text(cls, name) if cls is not None else None
    return text.lines if text is not None else (name,)


def action_full(cls: type | None, name: str) -> str:
    """The whole text of action ``name`` (its name when it has none)."""
    text = action_text(cls, name) if cls is not None else None
    return text.full if text is not None else name


def _actions(state: StateInfo) -> list[tuple[str, str]]:
    return [(short, name) for kind, short in KEYWORDS for name in getattr(state, kind)]


def state_actions(state: StateInfo, cls: type | None = None) -> list[str]:
    """The state's actions as Stateflow writes them in its box: ``en: ...``, ``du: ...``, ``ex: ...``.

    A text of several statements takes a line each, the first after the keyword.
    """
    out = []
    for short, name in _actions(state):
        lines = action_lines(cls, name)
        out.append(f"{short}: {lines[0]}")
        out.extend(f"    {line}" for line in lines[1:])
    return out


def state_actions_full(state: StateInfo, cls: type | None = None) -> list[str]:
    """The state's actions with their whole texts, one line each (tooltips, the cockpit's panel)."""
    return [f"{short}: {action_full(cls, name)}" for short, name in _actions(state)]


def handler_lines(state: StateInfo, structure: ChartStructure, cls: type | None = None,
                  full: bool = False) -> list[str]:
    """The state's ``on`` actions (``on button / ignore_button``) and inner self-transitions, listed inside it.

    They leave no state and enter none, so they are written in the state's box
    rather than drawn as loops, which would read as an exit and a re-entry.
    """
    lines = []
    for t in structure.transitions:
        if t.source != state.id:
            continue
        if t.target is None:
            first, action = edge_text(t, structure, cls, "; ", full)
            lines.append(" ".join(p for p in ("on", first or "every wake-up", action) if p))
        elif t.scope == "inner" and t.target == state.id and not state.is_compound:
            first, action = edge_text(t, structure, cls, "; ", full)
            lines.append(" ".join(p for p in ("↻", first, action) if p))
    return lines


def competing(structure: ChartStructure, t: TransitionInfo) -> int:
    """How many transitions of the same source and scope are tried in turn with `t` (its order counts)."""
    return sum(1 for u in structure.transitions if u.source == t.source and u.scope == t.scope)


def edge_text(t: TransitionInfo, structure: ChartStructure, cls: type | None = None, sep: str = "; ",
              full: bool = False) -> tuple[str, str]:
    """(order, trigger, [guard] and {condition action}; / transition action) of a segment, as Stateflow labels it.

    With the chart class ``cls``, an action reads as what it does (:mod:`.action_text`),
    its statements joined by ``sep``; ``full``: the whole texts, not the picture's summaries.
    """

    def text(names: tuple[str, ...]) -> str:
        if full:
            return "; ".join(action_full(cls, n) for n in names)
        return sep.join(line for n in names for line in action_lines(cls, n))

    order = f"{t.priority}:" if t.scope != "action" and competing(structure, t) > 1 else ""
    trigger = " ".join(t.events) if t.kind == "event" else ""
    guard = f"[{' and '.join(t.guards)}]" if t.guards else ""
    condition = f"{{{text(t.condition_actions)}}}" if t.condition_actions else ""
    first = " ".join(p for p in (order, trigger, guard, condition) if p)
    done = t.transition_actions + t.after_actions
    action = f"/ {text(done)}" if done else ""
    return first, action


def is_within(structure: ChartStructure, state: str, ancestor: str) -> bool:
    """Whether ``state`` is ``ancestor`` or one of its descendants."""
    parents = {s.id: s.parent for s in structure.states}
    node: str | None = state
    while node is not None:
        if node == ancestor:
            return True
        node = parents[node]
    return False


# -- Mermaid -------------------------------------------------------------------


def _m(text: str) -> str:
    """Escape text for a Mermaid state-diagram label."""
    return (text.replace("#", "#35;").replace(";", "#59;").replace("<", "#lt;")
            .replace(">", "#gt;").replace(":", "#58;"))


def _scope(structure: ChartStructure, t: TransitionInfo) -> str | None:
    """The compound whose block a transition is written in: its states' common parent.

    A transition written inside ``state X { }`` makes Mermaid draw both its states in
    X: one between states of different parents (``wait_23 --> pass_pos``) is written at
    the top level, where it moves no state.
    """
    parents = {s.id: s.parent for s in structure.states}
    source, target = parents[t.source], parents[t.target or t.source]
    return source if source == target else None


def to_mermaid(chart: StateChart | type[StateChart], active: set[str] | None = None) -> str:
    """Mermaid ``stateDiagram-v2`` of a chart, compound states nested."""
    structure = structure_of(chart)
    cls = chart_class(chart)
    active = active or set()
    by_id = {s.id: s for s in structure.states}
    scoped: dict[str | None, list[TransitionInfo]] = {}
    for t in structure.transitions:
        scoped.setdefault(_scope(structure, t), []).append(t)
    # As the Graphviz pictures: a chart with sub-charts reads top down, others left to right.
    has_subcharts = any(s.parent is None and s.is_compound for s in structure.states)
    out = ["stateDiagram-v2", f"    direction {'TB' if has_subcharts else 'LR'}"]
    notes: list[str] = []

    def edges(scope: str | None, indent: str) -> None:
        for t in scoped.get(scope, []):
            if t.target is None or (t.scope == "inner" and t.target == t.source and not by_id[t.source].is_compound):
                continue  # listed in its state (handler_lines)
            first, action = edge_text(t, structure, cls)
            label = " ".join(p for p in (first, action) if p)
            target = t.target or t.source
            suffix = f" : {_m(label)}" if label else ""
            out.append(f"{indent}{t.source} --> {target}{suffix}")

    def emit(states: list[StateInfo], indent: str, parent: StateInfo | None) -> None:
        initial = next((s for s in states if s.initial), None)
        if initial is not None and (parent is None or not parent.parallel):
            out.append(f"{indent}[*] --> {initial.id}")
        for i, state in enumerate(states):
            if parent is not None and parent.parallel and i > 0:
                out.append(f"{indent}--")
            actions = state_actions(state, cls) + handler_lines(state, structure, cls)
            # Mermaid titles a state with its first description line: declare the name
            # as that line, so `s : entry / ...` lines sit under the name, not in its place.
            if state.label != state.id or (actions and not state.is_compound):
                out.append(f'{indent}state "{_m(state.label)}" as {state.id}')
            if state.history:
                continue
            if state.junction:
                out.append(f"{indent}state {state.id} <<choice>>")
                continue
            if state.is_compound:
                out.append(f"{indent}state {state.id} {{")
                emit([by_id[c] for c in state.children], indent + "    ", state)
                edges(state.id, indent + "    ")
                out.append(f"{indent}}}")
                if actions:
                    notes.append(f"    note right of {state.id}")
                    notes.extend(f"        {_m(a)}" for a in actions)
                    notes.append("    end note")
            else:
                if actions:
                    out.extend(f"{indent}{state.id} : {_m(a)}" for a in actions)
                else:
                    out.append(f"{indent}{state.id}")
                if state.final:
                    out.append(f"{indent}{state.id} --> [*]")

    emit([s for s in structure.states if s.parent is None], "    ", None)
    edges(None, "    ")
    out += notes
    if active:
        out.append(f"    classDef active fill:{ACTIVE_FILL},stroke:#333,stroke-width:2px")
        out += [f"    class {s.id} active" for s in structure.states if s.id in active]
    return "\n".join(out) + "\n"


# -- Markdown page -------------------------------------------------------------


def _cell(value: Any) -> str:
    text = str(value).replace("|", "\\|").replace("\n", " ")
    return text if text else "—"


def _actions_cell(cls: type, names: Sequence[str]) -> str:
    """Actions in a table cell: ``name``: what it does."""
    parts = []
    for name in names:
        text = action_full(cls, name)
        parts.append(f"`{name}`" + (f": `{text}`" if text != name else ""))
    return _cell("; ".join(parts))


#: Under each Mermaid diagram: how to read it (Mermaid draws no legend of its own).
MERMAID_LEGEND = (
    "How to read it: a box is titled with the state's name; under it, its actions"
    " (`en:` runs when the state is entered, `du:` at every wake-up of the chart"
    " in which the state stays active, `ex:` when it is left; each written as what it does, in the"
    " chart's data: `du: pos_out = pos_out_p + inc`, `pos_out_p` the output's value at the previous"
    " tick; a text ending in `…` is summarised, the tables below give it whole) and its `on` actions"
    " (`on button / ignore_button`: runs after the during action when the event wakes the chart)."
    " Notes beside compound states list theirs. An edge reads"
    " `2: event [guard] {condition action} / transition action`, as in Stateflow: an edge with"
    " no event is tried at every wake-up; `2:` is its execution order among the transitions"
    " of its source (outer and inner ones counted apart), 1 first; the condition action runs as"
    " soon as the guard holds, the transition action when the whole path reaches a state."
    " A diamond is a connective junction: the segments leaving it are tried in their order."
    " `H` / `H*`: history (the sub-state active when the compound was left; `H*` at every depth)."
)


def to_markdown(chart: StateChart | type[StateChart], pictures: Sequence[tuple[str, str]] = (),
                legend: Sequence[str] = ()) -> str:
    """A Markdown page: pictures, Mermaid diagram, data, states and transitions tables.

    ``pictures`` are the chart's Graphviz pictures as (what it shows, file name),
    the first the one to see first: with more than one, it is embedded in the page
    and all are linked.  ``legend``: the pictures' legend, Markdown table rows
    (:func:`~.dot_text.legend_markdown`), written once under them.
    """
    structure = structure_of(chart)
    cls = chart_class(chart)
    out = [f"# {structure.name}", ""]
    if structure.doc:
        out += [line.strip() if i else line for i, line in enumerate(structure.doc.splitlines())]
        out.append("")
    out += ["<!-- generated by ttt_sm.runtime.export; do not edit -->", ""]
    if len(pictures) > 1:
        caption, first = pictures[0]
        out += ["## Pictures", "", f"![{structure.name}: {caption}]({first})", ""]
        out += [f"- [{caption}]({name})" for caption, name in pictures]
        out.append("")
    elif pictures:
        out += [f"![{structure.name}]({pictures[0][1]})", ""]
    if legend:
        out += ["How to read the pictures:", "", *legend, ""]
    out += ["## Diagram", "",
            "```mermaid", to_mermaid(cls).rstrip("\n"), "```", "", MERMAID_LEGEND, ""]
    decls = cls.declarations() if hasattr(cls, "declarations") else ()
    out += ["## Data", ""]
    if decls:
        out += ["| kind | name | unit | default | description |", "|---|---|---|---|---|"]
        for d in decls:
            doc = d.doc + (f" (previous tick: `{d.name}_p`)" if d.kind == "output" else "")
            out.append(f"| {d.kind} | `{d.name}` | {_cell(d.unit)} | `{d.default!r}` | {_cell(doc)} |")
    else:
        out.append("This chart declares no data.")
    own = {name: doc for name, doc in helpers(cls).items() if name not in HELPERS}
    if own:
        out += ["", "## Names in the actions", "",
                "Besides the data above (an output's value at the previous tick as `<name>_p`) and `dt` (the tick"
                " period), the actions on the pictures name:", "", "| name | meaning |", "|---|---|"]
        out += [f"| `{name}` | {_cell(doc)} |" for name, doc in own.items()]
    out += ["", "## States", "", "| state | inside | entry | during | exit |", "|---|---|---|---|---|"]
    for s in structure.states:
        if s.history:
            out.append(f"| `{s.id}` ({s.history} history) | {_cell(s.parent or '')} | — | — | — |")
            continue
        if s.junction:
            out.append(f"| `{s.id}` (junction{', initial' if s.initial else ''}) | {_cell(s.parent or '')}"
                       " | — | — | — |")
            continue
        out.append(f"| `{s.id}`{' (initial)' if s.initial else ''} | {_cell(s.parent or '')} |"
                   f" {_actions_cell(cls, s.entry)} | {_actions_cell(cls, s.during)} |"
                   f" {_actions_cell(cls, s.exit)} |")
    out += ["", "## Transitions", "",
            "Tried in Stateflow's order at every wake-up of the chart: the outer transitions of the"
            " active state, outermost state first; then its during and `on` actions; then its inner"
            " transitions; then its active sub-state. *kind*: outer, inner (from the state's inner"
            " edge), segment (from a junction), on (the state's `on` action). *order*: the execution"
            " order among the transitions of the same source and kind. A transition with an event is"
            " tried only when that event wakes the chart.", "",
            "| source | target | kind | order | trigger | guard | condition action | transition action |",
            "|---|---|---|---|---|---|---|---|"]
    for t in structure.transitions:
        target = f"`{t.target}`" if t.target else "(none)"
        kind = "on" if t.scope == "action" else t.scope
        out.append(f"| `{t.source}` | {target} | {kind} | {t.priority} | {_cell(t.trigger)} |"
                   f" {_cell(' and '.join(t.guards))} | {_actions_cell(cls, t.condition_actions)} |"
                   f" {_actions_cell(cls, t.transition_actions + t.after_actions)} |")
    return "\n".join(out) + "\n"
