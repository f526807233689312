"""Graphviz DOT of a chart: the whole chart, an overview and one picture per sub-chart.

A chart whose top level holds compound states (Control: ``start_stop``,
``Drawing_X``, ...) is drawn in several :class:`~.dot_views.View`\\ s (:mod:`.dot_views`), the way Stateflow shows
a chart with subcharts:

* the **overview**: those compound states *closed*, each a grey box with its name,
  its own actions, and one row per inner state that a transition from outside
  enters (``▸ go_wait``) or that a transition leaves to the outside
  (``wait_1 ▸``); the edges between sub-charts start and end on those rows;
* one picture per **sub-chart**: the compound state open, and each state outside it
  that one of its transitions comes from or goes to drawn as a dashed stub
  that links to the picture where that state is drawn;
* the **whole chart**, compound states as nested clusters (what
  :func:`~.export.render_active` highlights).

Every picture carries its title; the legend of what a chart's pictures use
(transitions with and without events, execution order, condition and transition
actions, ``en:``/``du:``/``ex:``, history, connective junctions, ...) is drawn
once per page: :func:`~.dot_text.legend_dot` (the cockpit), :func:`~.dot_text.legend_markdown` (the
chart's Markdown page); :mod:`.dot_text` holds the pieces of the text.  Labels read as in Stateflow:
``2: event [guard] {condition action} / transition action``; an action reads as
what it does (:mod:`.action_text`), a long one summarised with ``…`` and whole in
the element's tooltip.  A
connective junction is a small circle.  Transitions with the same trigger,
guard and action into the same state are drawn once, from a small dot their
sources lead into.  A state's ``on`` actions (``on button / ignore_button``)
and a leaf's inner transitions to itself are listed inside its box.

The text is a pure function of the chart class, the view and the active states:
byte-identical on every export.  SVG element ids are stable: ``state-<id>`` for a
state (box, closed box or cluster), ``stub-<id>`` for a stub, ``tr-<n>`` for the
edge of transition ``n`` (its index in :class:`~.structure.ChartStructure`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from statemachine import StateChart

from .diagram import (
    ACTIVE_CLUSTER_FILL,
    ACTIVE_FILL,
    FONT,
    KEYWORDS,
    chart_class,
    edge_text,
    handler_lines,
    is_within,
    state_actions,
    state_actions_full,
    structure_of,
)
from .dot_text import (
    CLOSED_FILL,
    EVENT_COLOR,
    STUB_COLOR,
    closed_label,
    html,
    html_label,
    left_quote,
    quote,
    title_label,
)
from .dot_views import OVERVIEW, WHOLE, View, views
from .structure import ChartStructure, StateInfo, TransitionInfo


def legend_features(chart: StateChart | type[StateChart]) -> set[str]:
    """What the pictures of a chart use (its legend explains those): ``tick``, ``event``, ``entry``, ..."""
    structure, cls = structure_of(chart), chart_class(chart)
    found: set[str] = set()
    for view in views(chart):
        picture = _Picture(structure, view, set(), cls)
        picture.dot()
        found |= picture.features
    return found


# -- the drawing ---------------------------------------------------------------


@dataclass(frozen=True)
class _End:
    """One end of a drawn edge: a DOT node, maybe a port of it, maybe clipped at a cluster."""

    node: str
    port: str = ""
    compass: str = ""
    cluster: str = ""

    def ref(self) -> str:
        ref = quote(self.node)
        if self.port:
            ref += f":{quote(self.port)}"
        if self.compass:
            ref += f":{self.compass}"
        return ref


@dataclass
class _Edge:
    tail: _End
    head: _End
    label: str
    kind: str
    source: str
    target: str
    #: whether the source lies in the compound state that holds the target (or both at the top)
    local: bool
    transitions: list[int] = field(default_factory=list)
    #: the label with the actions' whole texts, for the tooltip
    full: str = ""


class _Picture:
    """The DOT text of one view, and what its legend must explain."""

    def __init__(self, structure: ChartStructure, view: View, active: set[str], cls: type | None = None) -> None:
        self.structure = structure
        self.cls = cls
        self.view = view
        self.active = active
        self.by_id = {s.id: s for s in structure.states}
        self.features: set[str] = set()
        self.stubs: list[str] = []
        # closed box -> inner state -> (entered from outside, left to the outside)
        self.ports: dict[str, dict[str, list[bool]]] = {c: {} for c in view.closed}
        #: junction dots by the compound state whose cluster holds them (None: outside all)
        self.junctions: dict[str | None, list[str]] = {}

    # -- where a state is drawn

    def shown(self, state_id: str) -> bool:
        return self.view.root is None or is_within(self.structure, state_id, self.view.root)

    def closed_box(self, state_id: str) -> str | None:
        """The outermost closed compound holding (or being) the state."""
        found: str | None = None
        node: str | None = state_id
        while node is not None:
            if node in self.view.closed:
                found = node
            node = self.by_id[node].parent
        return found

    def picture_of(self, state_id: str) -> str:
        """File of the picture that draws a state open (for the links of stubs)."""
        top = state_id
        while self.by_id[top].parent is not None:
            top = self.by_id[top].parent  # type: ignore[assignment]
        key = top if self.by_id[top].is_compound else OVERVIEW
        return f"{self.structure.name}.{key}.svg"

    def end(self, t: TransitionInfo, state_id: str, as_head: bool) -> _End:
        """Where an edge of ``t`` ends at ``state_id`` (its source, or with ``as_head`` its target)."""
        other = t.source if as_head else (t.target or t.source)
        if not self.shown(state_id):
            return _End(f"stub__{state_id}")
        box = self.closed_box(state_id)
        if box is not None:
            if box == state_id:
                return _End(box)
            return _End(box, f"p_{state_id}", "w" if as_head else "")
        state = self.by_id[state_id]
        if state.is_compound and not is_within(self.structure, other, state_id):
            # Into a compound from outside: end at its initial dot, clipped at the border,
            # so the arrow meets the cluster where its story starts.
            node = f"{state_id}__start" if as_head and not state.parallel else state_id
            return _End(node, cluster=f"cluster_{state_id}")
        return _End(state_id)

    # -- edges

    def edges(self) -> list[_Edge]:
        drawn: dict[tuple[_End, _End, str, str], _Edge] = {}
        for t in self.structure.transitions:
            if t.target is None or (t.scope == "inner" and t.target == t.source
                                    and not self.by_id[t.source].is_compound):
                continue  # listed inside its state
            if not self.shown(t.source) and not self.shown(t.target):
                continue
            tail, head = self.end(t, t.source, False), self.end(t, t.target, True)
            if tail.node == head.node and tail.node in self.view.closed and t.source != t.target:
                continue  # inside a closed sub-chart
            first, action = edge_text(t, self.structure, self.cls, "\n  ")
            label = "\n".join(p for p in (first, action) if p)
            self.note_text(label)
            for state_id, end, as_head in ((t.source, tail, False), (t.target, head, True)):
                if end.node.startswith("stub__") and state_id not in self.stubs:
                    self.stubs.append(state_id)
                if end.port and self.by_id[state_id].history:
                    self.features.add("history")
                if end.port:
                    self.ports[end.node].setdefault(state_id, [False, False])[0 if as_head else 1] = True
            key = (tail, head, label, t.kind)
            scope = self.by_id[t.target].parent
            local = scope is None or is_within(self.structure, t.source, scope)
            full = " ".join(p for p in edge_text(t, self.structure, self.cls, full=True) if p)
            edge = drawn.setdefault(key, _Edge(tail, head, label, t.kind, t.source, t.target, local,
                                               full=f"{t.source} → {t.target}" + (f": {full}" if full else "")))
            edge.transitions.append(t.index)
            self.features.add(t.kind)
            if first[:1].isdigit():
                self.features.add("priority")
            if t.condition_actions:
                self.features.add("condition")
            if t.transition_actions or t.after_actions:
                self.features.add("action")
        edges = list(drawn.values())
        for e in edges:
            if e.tail.port and not e.tail.compass:
                rows = self.port_rows(e.tail.node)
                last = rows[-1][0] == e.tail.port if rows else False
                e.tail = _End(e.tail.node, e.tail.port, "s" if last else "e")
        return edges

    def port_rows(self, box: str) -> list[tuple[str, str, bool, bool]]:
        """The rows of a closed box's ports: (port, name, entered, left); entered ones first."""
        ports = sorted(self.ports[box].items(), key=lambda item: (item[1][1] and not item[1][0], self._order(item[0])))
        return [(f"p_{s}", self.by_id[s].label, into, out_of) for s, (into, out_of) in ports]

    def edge_lines(self, edges: list[_Edge]) -> list[str]:
        out: list[str] = []
        # Edges with the same label into the same state meet at a junction dot first; those
        # from inside the target's compound state and those from outside it meet apart, so
        # that the junction sits on one side of the target.
        groups: dict[tuple[_End, str, str, bool], list[_Edge]] = {}
        for e in edges:
            groups.setdefault((e.head, e.label, e.kind, e.local), []).append(e)
        junction = 0
        for (head, label, kind, _local), group in groups.items():
            colour = [] if kind == "tick" else [f'color="{EVENT_COLOR}"', f'fontcolor="{EVENT_COLOR}"']
            if len(group) == 1 or not label:
                for e in group:
                    attrs = [f"label={left_quote(label)}"] if label else []
                    attrs.append(f"tooltip={quote(e.full)}")
                    attrs += self.clip_attrs(e.tail, e.head)
                    attrs += ['style="solid"'] if kind == "tick" else colour
                    attrs.append(f'id="{_edge_id(e.transitions)}"')
                    out.append(f"  {e.tail.ref()} -> {e.head.ref()} [{', '.join(attrs)}];")
                continue
            junction += 1
            self.features.add("junction")
            join = f"join_{junction}"
            all_ids = [i for e in group for i in e.transitions]
            ink = EVENT_COLOR if colour else "black"
            scope = self.scope_of([e.source for e in group] + [group[0].target])
            self.junctions.setdefault(scope, []).append(
                f'{quote(join)} [shape="point", width="0.09", label="", color="{ink}", fillcolor="{ink}"];')
            for e in group:
                attrs = self.clip_attrs(e.tail, _End(join)) + ['arrowhead="none"'] + colour
                attrs.append(f'id="{_edge_id(e.transitions)}"')
                out.append(f"  {e.tail.ref()} -> {quote(join)} [{', '.join(attrs)}];")
            attrs = [f"label={left_quote(label)}", f"tooltip={quote(chr(10).join(e.full for e in group))}"]
            attrs += self.clip_attrs(_End(join), head) + colour
            attrs.append(f'id="{_edge_id(all_ids)}-join"')
            out.append(f"  {quote(join)} -> {head.ref()} [{', '.join(attrs)}];")
        return out

    def scope_of(self, states: list[str]) -> str | None:
        """The innermost compound state drawn open that holds all ``states`` strictly inside it."""
        if not all(self.shown(x) for x in states):
            return None
        chains = []
        for state_id in states:
            chain, node = [], self.by_id[state_id].parent
            while node is not None:
                chain.append(node)
                node = self.by_id[node].parent
            chains.append(chain)
        for ancestor in chains[0]:  # innermost first
            if all(ancestor in chain for chain in chains[1:]) and self.closed_box(ancestor) is None:
                return ancestor
        return None

    @staticmethod
    def clip_attrs(tail: _End, head: _End) -> list[str]:
        attrs = []
        if tail.cluster:
            attrs.append(f"ltail={quote(tail.cluster)}")
        if head.cluster:
            attrs.append(f"lhead={quote(head.cluster)}")
        return attrs

    # -- states

    def note_text(self, text: str) -> None:
        """What the legend must explain of an action's text: previous values, summaries."""
        if "…" in text:
            self.features.add("summary")
        if "_p " in text or "_p)" in text or "_p," in text or text.endswith("_p"):
            self.features.add("previous")

    def tooltip(self, state: StateInfo) -> str:
        """The state's name and its actions' whole texts: what hovering it shows."""
        lines = state_actions_full(state, self.cls) + handler_lines(state, self.structure, self.cls, full=True)
        return "\n".join([state.id, *lines])

    def lines_of(self, state: StateInfo) -> list[str]:
        actions = state_actions(state, self.cls)
        for kind, short in KEYWORDS:
            if any(a.startswith(short + ":") for a in actions):
                self.features.add(kind)
        handlers = handler_lines(state, self.structure, self.cls)
        for line in actions + handlers:
            self.note_text(line)
        if handlers:
            for t in self.structure.transitions:
                if t.source == state.id and (t.target is None or t.target == t.source):
                    self.features.add("handler" if t.target is None else "inner")
                    self.features.add(t.kind)
                    if t.condition_actions:
                        self.features.add("condition")
                    if t.transition_actions or t.after_actions:
                        self.features.add("action")
        return actions + handlers

    def state_lines(self, states: list[StateInfo], indent: str, parent: StateInfo | None) -> list[str]:
        out: list[str] = []
        if parent is None or not parent.parallel:
            initial = next((s for s in states if s.initial), None)
            if initial is not None:
                self.features.add("initial")
                start = f"{parent.id}__start" if parent else "__start__"
                out.append(f'{indent}{quote(start)} [shape="point", width="0.12", fillcolor="black", label=""];')
                target = initial.id
                lhead = ""
                if initial.id not in self.view.closed and initial.is_compound:
                    target = f"{initial.id}__start" if not initial.parallel else initial.id
                    lhead = f', lhead={quote("cluster_" + initial.id)}'
                out.append(f"{indent}{quote(start)} -> {quote(target)} [weight=\"10\"{lhead}];")
        for state in states:
            is_active = state.id in self.active
            if is_active:
                self.features.add("active")
            state_id = f'id="state-{state.id}"'
            if state.id in self.view.closed:
                self.features.add("closed")
                ports = self.port_rows(state.id)
                # closed, as Stateflow draws a subchart: its name and ports; its own actions in its
                # tooltip and in its own picture
                attrs = [f"label={closed_label(state.label, [], ports)}",
                         f'fillcolor="{ACTIVE_FILL if is_active else CLOSED_FILL}"', 'penwidth="2"',
                         f'URL="{self.structure.name}.{state.id}.svg"',
                         f"tooltip={quote('sub-chart ' + self.tooltip(state))}",
                         state_id]
                out.append(f"{indent}{quote(state.id)} [{', '.join(attrs)}];")
            elif state.is_compound:
                style = "rounded,dashed" if parent is not None and parent.parallel else "rounded"
                attrs = [f"label={html_label(state.label, self.lines_of(state))}",
                         f"tooltip={quote(self.tooltip(state))}",
                         f"style={quote(style + (',filled' if is_active else ''))}", 'labeljust="c"', state_id]
                if is_active:
                    attrs += [f'fillcolor="{ACTIVE_CLUSTER_FILL}"', 'penwidth="2.5"']
                out.append(f"{indent}subgraph {quote('cluster_' + state.id)} {{")
                out.extend(f"{indent}  {a};" for a in attrs)
                # Invisible anchor: edges to and from the compound start or end here.
                out.append(f'{indent}  {quote(state.id)} [shape="point", style="invis", width="0",'
                           ' height="0", label=""];')
                out.extend(self.state_lines([self.by_id[c] for c in state.children], indent + "  ", state))
                out.extend(f"{indent}  {line}" for line in self.junctions.get(state.id, []))
                out.append(f"{indent}}}")
            elif state.junction:
                self.features.add("connective")
                out.append(f'{indent}{quote(state.id)} [label="", shape="circle", width="0.16", height="0.16",'
                           f' fixedsize="true", style="filled", fillcolor="white", penwidth="1.5",'
                           f' tooltip="junction {state.id}", {state_id}];')
            elif state.history:
                self.features.add("history")
                out.append(f'{indent}{quote(state.id)} [label={quote(state.label)}, shape="circle",'
                           f' width="0.3", fixedsize="true", {state_id}];')
            else:
                attrs = [f"label={html_label(state.label, self.lines_of(state))}",
                         f"tooltip={quote(self.tooltip(state))}"]
                if state.final:
                    self.features.add("final")
                    attrs.append('peripheries="2"')
                if is_active:
                    attrs += [f'fillcolor="{ACTIVE_FILL}"', 'penwidth="2.5"']
                attrs.append(state_id)
                out.append(f"{indent}{quote(state.id)} [{', '.join(attrs)}];")
        return out

    def _order(self, state_id: str) -> int:
        return next(i for i, s in enumerate(self.structure.states) if s.id == state_id)

    def stub_lines(self) -> list[str]:
        out = []
        for state_id in sorted(self.stubs, key=self._order):
            self.features.add("stub")
            state = self.by_id[state_id]
            where = f'<br/><font point-size="9">in {html(state.parent)}</font>' if state.parent else ""
            out.append(
                f'  {quote("stub__" + state_id)} [label=<<i>{html(state.label)}</i>{where}>, style="rounded,dashed",'
                f' color="{STUB_COLOR}", fontcolor="{STUB_COLOR}", URL="{self.picture_of(state_id)}",'
                f' tooltip="{state_id}: open its picture", id="stub-{state_id}"];'
            )
        return out

    def dot(self) -> str:
        s = self.structure
        # Edges first: they tell which ports, stubs and junctions there are.
        edge_lines = self.edge_lines(self.edges())
        roots = [self.by_id[self.view.root]] if self.view.root else [x for x in s.states if x.parent is None]
        body = self.state_lines(roots, "  ", None) + self.stub_lines()
        body += [f"  {line}" for line in self.junctions.get(None, [])] + edge_lines
        # A chart of a few states reads left to right, as the thesis' figures.  A chart with
        # sub-charts reads top down in every view: the start above, the sub-charts side by
        # side below it (as in thesis fig. 3.24), and their long sequences within a page's width.
        has_subcharts = any(x.parent is None and x.is_compound for x in s.states)
        rankdir = "TB" if has_subcharts else "LR"
        head = [
            f"digraph {quote(self.view.file_stem(s.name))} {{",
            f"  graph [label={title_label(self.view.title(s.name))}, labelloc=\"t\","
            f' labeljust="l", fontname={quote(FONT)}, fontsize="10", rankdir="{rankdir}", compound="true",'
            ' nodesep="0.35", ranksep="0.45"];',
            f'  node [fontname={quote(FONT)}, fontsize="10", shape="box", style="rounded,filled",'
            ' fillcolor="white", penwidth="1.5"];',
            # decorate: a label is underlined and tied to its edge by a line, so a guard placed
            # away from a crowded edge still says which edge it belongs to
            f'  edge [fontname={quote(FONT)}, fontsize="9", decorate="true"];',
        ]
        return "\n".join(head + body + ["}"]) + "\n"


def _edge_id(transitions: list[int]) -> str:
    return "tr-" + "-".join(str(i) for i in transitions)


def to_dot(chart: StateChart | type[StateChart], active: set[str] | None = None, view: View = WHOLE) -> str:
    """Graphviz DOT of one view of a chart (default: the whole chart, compound states nested).

    Parameters
    ----------
    chart : TickChart class or instance
    active : set of str, optional
        Ids of states to highlight (see :func:`~.diagram.active_ids`).
    view : View, optional
        One of :func:`views`.
    """
    structure = structure_of(chart)
    if view.root is not None and view.root not in {x.id for x in structure.states}:
        raise ValueError(f"{structure.name} has no state {view.root!r} to draw as a sub-chart")
    return _Picture(structure, view, active or set(), chart_class(chart)).dot()
