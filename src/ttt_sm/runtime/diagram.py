"""Diagram text of a chart: Graphviz DOT, Mermaid and a Markdown page.

Drawn from the chart's :class:`~.structure.ChartStructure`, not from the
library's renderers, so that

* compound states are nested clusters, tick transitions show their Stateflow
  priority, guards and actions sit on the edges, and entry/during/exit actions
  are listed inside the states;
* the text is a pure function of the chart class (and, for :func:`to_dot` /
  :func:`to_mermaid` with ``active``, of the active states): byte-identical on
  every export, so a test can tell a stale ``charts/`` folder.
"""

from __future__ import annotations

from typing import Any

from statemachine import StateChart

from .structure import ChartStructure, StateInfo, TransitionInfo, priority_conflicts

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


def state_actions(state: StateInfo) -> list[str]:
    return (
        [f"entry / {a}" for a in state.entry]
        + [f"during / {a}" for a in state.during]
        + [f"exit / {a}" for a in state.exit]
    )


def handler_lines(state: StateInfo, structure: ChartStructure) -> list[str]:
    """The state's targetless transitions (``button / ignore_button``), listed inside it.

    They leave no state and enter none (python-statemachine runs their actions only),
    so they are written in the state's box rather than drawn as loops, which would read
    as an exit and a re-entry.
    """
    lines = []
    for t in structure.transitions:
        if t.source == state.id and t.target is None:
            lines.append(" ".join(p for p in edge_text(t, structure) if p))
    return lines


def edge_text(t: TransitionInfo, structure: ChartStructure) -> tuple[str, str]:
    """(trigger and guard, action) of a transition as drawn on its edge."""
    trigger = ""
    if t.kind == "event":
        trigger = " ".join(t.events)
    elif len(structure.tick_by_state[t.source]) > 1:
        trigger = f"{t.priority}:"
    guard = f"[{' && '.join(t.guards)}]" if t.guards else ""
    first = " ".join(p for p in (trigger, guard) if p)
    action = f"/ {', '.join(t.actions)}" if t.actions else ""
    return first, action


def _is_within(structure: ChartStructure, state: str, ancestor: str) -> bool:
    """Whether ``state`` is ``ancestor`` or one of its descendants."""
    parents = {s.id: s.parent for s in structure.states}
    node: str | None = state
    while node is not None:
        if node == ancestor:
            return True
        node = parents[node]
    return False


# -- DOT ---------------------------------------------------------------------


def _q(text: str) -> str:
    escaped = text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
    return '"' + escaped + '"'


def _html(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;")


def _html_label(title: str, lines: list[str]) -> str:
    if not lines:
        return f"<<b>{_html(title)}</b>>"
    body = "<br/>".join(_html(line) for line in lines)
    return (
        '<<table border="0" cellborder="0" cellspacing="0" cellpadding="2">'
        f"<tr><td><b>{_html(title)}</b></td></tr><hr/>"
        f'<tr><td align="left" balign="left">{body}</td></tr></table>>'
    )


def to_dot(chart: StateChart | type[StateChart], active: set[str] | None = None) -> str:
    """Graphviz DOT of a chart, compound states as nested clusters.

    Parameters
    ----------
    chart : TickChart class or instance
    active : set of str, optional
        Ids of states to highlight (see :func:`active_ids`).
    """
    structure = structure_of(chart)
    active = active or set()
    by_id = {s.id: s for s in structure.states}
    out = [
        f"digraph {_q(structure.name)} {{",
        f'  graph [label=<<b>{_html(structure.name)}</b>>, labelloc="t", fontname={_q(FONT)},'
        ' fontsize="12", rankdir="LR", compound="true", nodesep="0.35", ranksep="0.45"];',
        f'  node [fontname={_q(FONT)}, fontsize="10", shape="box", style="rounded,filled",'
        ' fillcolor="white", penwidth="1.5"];',
        f'  edge [fontname={_q(FONT)}, fontsize="9"];',
    ]

    def head(state_id: str) -> str:
        # An edge into a compound from outside ends at its initial dot, clipped at the
        # cluster border: the arrow then meets the cluster where its story starts.
        state = by_id[state_id]
        return f"{state_id}__start" if state.is_compound and not state.parallel else state_id

    def emit(states: list[StateInfo], indent: str, parent: StateInfo | None) -> None:
        if parent is None or not parent.parallel:
            initial = next((s for s in states if s.initial), None)
            if initial is not None:
                start = f"{parent.id}__start" if parent else "__start__"
                out.append(f'{indent}{_q(start)} [shape="point", width="0.12", fillcolor="black", label=""];')
                lhead = f', lhead={_q("cluster_" + initial.id)}' if initial.is_compound else ""
                out.append(f"{indent}{_q(start)} -> {_q(head(initial.id))} [weight=\"10\"{lhead}];")
        for state in states:
            is_active = state.id in active
            if state.is_compound:
                style = "rounded,dashed" if parent is not None and parent.parallel else "rounded"
                attrs = [f"label={_html_label(state.label, state_actions(state))}",
                         f"style={_q(style + (',filled' if is_active else ''))}"]
                if is_active:
                    attrs += [f'fillcolor="{ACTIVE_CLUSTER_FILL}"', 'penwidth="2.5"']
                out.append(f"{indent}subgraph {_q('cluster_' + state.id)} {{")
                out.extend(f"{indent}  {a};" for a in attrs)
                # Invisible anchor: edges to and from the compound start or end here.
                out.append(f'{indent}  {_q(state.id)} [shape="point", style="invis", width="0",'
                           ' height="0", label=""];')
                emit([by_id[c] for c in state.children], indent + "  ", state)
                out.append(f"{indent}}}")
            elif state.history:
                out.append(f'{indent}{_q(state.id)} [label={_q(state.label)}, shape="circle",'
                           ' width="0.3", fixedsize="true"];')
            else:
                attrs = [f"label={_html_label(state.label, state_actions(state))}"]
                if state.final:
                    attrs.append('peripheries="2"')
                if is_active:
                    attrs += [f'fillcolor="{ACTIVE_FILL}"', 'penwidth="2.5"']
                out.append(f"{indent}{_q(state.id)} [{', '.join(attrs)}];")

    emit([s for s in structure.states if s.parent is None], "  ", None)
    for t in structure.transitions:
        first, action = edge_text(t, structure)
        label = "\n".join(p for p in (first, action) if p)
        target = t.target or t.source
        attrs = [f"label={_q(label)}"] if label else []
        head_node = target
        if by_id[t.source].is_compound and not _is_within(structure, target, t.source):
            attrs.append(f"ltail={_q('cluster_' + t.source)}")
        if by_id[target].is_compound and not _is_within(structure, t.source, target):
            attrs.append(f"lhead={_q('cluster_' + target)}")
            head_node = head(target)
        if t.kind == "tick":
            attrs.append('style="solid"')
        else:
            attrs.append('color="#1f4e9c", fontcolor="#1f4e9c"')
        if t.target is None:
            attrs.append('arrowhead="none"')
        out.append(f"  {_q(t.source)} -> {_q(head_node)} [{', '.join(attrs)}];")
    out.append("}")
    return "\n".join(out) + "\n"


# -- Mermaid -------------------------------------------------------------------


def _m(text: str) -> str:
    """Escape text for a Mermaid state-diagram label."""
    return (text.replace("#", "#35;").replace(";", "#59;").replace("<", "#lt;")
            .replace(">", "#gt;").replace(":", "#58;"))


def _scope(structure: ChartStructure, t: TransitionInfo) -> str | None:
    """The innermost compound holding both ends of a transition strictly inside it."""
    parents = {s.id: s.parent for s in structure.states}
    target = t.target or t.source

    def ancestors(state: str) -> list[str]:
        chain, node = [], parents[state]
        while node is not None:
            chain.append(node)
            node = parents[node]
        return chain

    of_target = set(ancestors(target))
    return next((a for a in ancestors(t.source) if a in of_target), None)


def to_mermaid(chart: StateChart | type[StateChart], active: set[str] | None = None) -> str:
    """Mermaid ``stateDiagram-v2`` of a chart, compound states nested."""
    structure = structure_of(chart)
    active = active or set()
    by_id = {s.id: s for s in structure.states}
    scoped: dict[str | None, list[TransitionInfo]] = {}
    for t in structure.transitions:
        scoped.setdefault(_scope(structure, t), []).append(t)
    out = ["stateDiagram-v2", "    direction LR"]
    notes: list[str] = []

    def edges(scope: str | None, indent: str) -> None:
        for t in scoped.get(scope, []):
            if t.target is None:
                continue  # listed in its state (handler_lines)
            first, action = edge_text(t, structure)
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
            actions = state_actions(state) + handler_lines(state, structure)
            # Mermaid titles a state with its first description line: declare the name
            # as that line, so `s : entry / ...` lines sit under the name, not in its place.
            if state.label != state.id or (actions and not state.is_compound):
                out.append(f'{indent}state "{_m(state.label)}" as {state.id}')
            if state.history:
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


def to_markdown(chart: StateChart | type[StateChart]) -> str:
    """A Markdown page: Mermaid diagram, data, states and transitions tables."""
    structure = structure_of(chart)
    cls = chart_class(chart)
    out = [f"# {structure.name}", ""]
    if structure.doc:
        out += [line.strip() if i else line for i, line in enumerate(structure.doc.splitlines())]
        out.append("")
    out += ["<!-- generated by ttt_sm.runtime.export; do not edit -->", "",
            "```mermaid", to_mermaid(cls).rstrip("\n"), "```", ""]
    decls = cls.declarations() if hasattr(cls, "declarations") else ()
    out += ["## Data", ""]
    if decls:
        out += ["| kind | name | unit | default | description |", "|---|---|---|---|---|"]
        for d in decls:
            doc = d.doc + (f" (previous tick: `{d.name}_p`)" if d.kind == "output" else "")
            out.append(f"| {d.kind} | `{d.name}` | {_cell(d.unit)} | `{d.default!r}` | {_cell(doc)} |")
    else:
        out.append("This chart declares no data.")
    out += ["", "## States", "", "| state | inside | entry | during | exit |", "|---|---|---|---|---|"]
    for s in structure.states:
        if s.history:
            out.append(f"| `{s.id}` ({s.history} history) | {_cell(s.parent or '')} | — | — | — |")
            continue
        out.append(f"| `{s.id}`{' (initial)' if s.initial else ''} | {_cell(s.parent or '')} |"
                   f" {_cell(', '.join(s.entry))} | {_cell(', '.join(s.during))} |"
                   f" {_cell(', '.join(s.exit))} |")
    out += ["", "## Transitions", "",
            "Tick transitions are tried on every chart tick, outermost active state first;"
            " *priority* is their order within a state. Event transitions run when the event,"
            " posted from outside, is handled at the next tick.", "",
            "| source | target | trigger | priority | guard | action |", "|---|---|---|---|---|---|"]
    for t in structure.transitions:
        target = f"`{t.target}`" if t.target else "(none)"
        out.append(f"| `{t.source}` | {target} | {_cell(t.trigger)} |"
                   f" {t.priority or '—'} | {_cell(' && '.join(t.guards))} | {_cell(', '.join(t.actions))} |")
    conflicts = priority_conflicts(structure)
    if conflicts:
        out += ["", "## Priority notes", ""] + [f"- {c}" for c in conflicts]
    return "\n".join(out) + "\n"
