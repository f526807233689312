"""A chart class as the runtime executes it: states, junctions and segments, read once per class.

python-statemachine declares a chart (states, ``.to()`` transitions, callbacks by
name); this module turns the declaration into the small graph that
Stateflow's execution walks (:mod:`.engine`): for every state its outer
transitions, its ``on`` actions and its inner transitions in execution order,
its default entry, its history junction; for every junction its outgoing
segments.  Nothing here runs an action.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Literal

from statemachine.state import HistoryState, State
from statemachine.transition import Transition

from .errors import ChartDefinitionError
from .junction import is_junction
from .structure import TICK_EVENT_PREFIX, ChartStructure, TransitionInfo
from .temporal import Temporal, duration_of, temporal_of

NodeKind = Literal["state", "junction", "history"]


@dataclass(eq=False)
class Seg:
    """One transition segment: from a state or junction to a state, junction or history junction."""

    transition: Transition
    info: TransitionInfo
    source: Node
    target: Node | None
    #: the events that trigger it; None: any wake-up (an eventless transition)
    events: frozenset[str] | None
    #: the state whose clock its temporal guards read (a junction's: the state it sits in)
    clock: Node | None
    temporal: tuple[Temporal, ...] = ()

    @property
    def label(self) -> str:
        return self.info.label


@dataclass(eq=False)
class Node:
    """A state, a junction or a history junction of a chart."""

    id: str
    state: State
    kind: NodeKind
    parent: Node | None
    index: int = 0
    depth: int = 0
    parallel: bool = False
    children: tuple[Node, ...] = ()
    junctions: tuple[Node, ...] = ()
    #: every state id below this one (not itself), for "does the target lie inside?"
    below: frozenset[str] = frozenset()
    outer: tuple[Seg, ...] = ()
    inner: tuple[Seg, ...] = ()
    actions: tuple[Seg, ...] = ()
    out: tuple[Seg, ...] = ()  # a junction's segments
    default: Node | None = None  # the initial child: a state or a junction
    history: Node | None = None
    deep: bool = False
    during: str | None = None
    durations: tuple[object, ...] = field(default=(), repr=False)

    @property
    def is_state(self) -> bool:
        return self.kind == "state"

    def ancestors(self) -> Iterator[Node]:
        """This node's parents, innermost first."""
        node = self.parent
        while node is not None:
            yield node
            node = node.parent

    def contains(self, other: Node) -> bool:
        """Whether `other` lies strictly inside this state."""
        return other.id in self.below

    def __repr__(self) -> str:
        return f"<{self.kind} {self.id}>"


@dataclass(frozen=True)
class Program:
    """The executable graph of one chart class."""

    top: tuple[Node, ...]
    nodes: dict[str, Node]
    segs: dict[int, Seg]
    #: the top level's default (a state or a junction)
    default: Node | None
    #: True when some state or transition uses ``duration``
    has_durations: bool
    #: every state (not junctions), parents before children, in the order written
    ordered: tuple[Node, ...] = ()
    #: the chart's events by id (the generated tick events too)
    events: dict[str, object] = field(default_factory=dict)


def _events_of(t: Transition) -> frozenset[str] | None:
    """The events that trigger `t`, None for an eventless one.

    ``after(3, "E")`` in the condition of an eventless transition is Stateflow's
    conditional notation (``[after(3, E)]``: tried at every wake-up); assigned to
    the event ``E`` it is the trigger notation (``after(3, E)``: tried on E only).
    """
    names = [str(e) for e in t.events if not str(e).startswith(TICK_EVENT_PREFIX)]
    # the SCXML alias the library adds beside a dotted event name
    names = [n for n in names if not ("." in n and n.replace(".", "_") in names)]
    return frozenset(names) if names else None


def _owner(node: Node) -> Node | None:
    """The state a junction or a history junction sits in (None at the top level)."""
    parent = node.parent
    while parent is not None and not parent.is_state:
        parent = parent.parent
    return parent


def build_program(cls: type, structure: ChartStructure) -> Program:
    """Read the executable graph of a chart class."""
    nodes: dict[str, Node] = {}
    order = 0

    def make(state: State, parent: Node | None, depth: int) -> Node:
        nonlocal order
        kind: NodeKind = "history" if isinstance(state, HistoryState) else "junction" if is_junction(state) else "state"
        node = Node(id=state.id, state=state, kind=kind, parent=parent, index=order, depth=depth,
                    parallel=bool(state.parallel))
        order += 1
        nodes[state.id] = node
        if kind != "state":
            return node
        kids = [make(s, node, depth + 1) for s in state.states]
        node.children = tuple(k for k in kids if k.is_state)
        node.junctions = tuple(k for k in kids if k.kind == "junction")
        for h in state.history:
            node.history = make(h, node, depth + 1)
            node.deep = bool(h.type.is_deep)
        initial = [k for k in kids if k.state.initial]
        if node.children and not node.parallel:
            if len(initial) != 1:
                raise ChartDefinitionError(
                    f"{cls.__name__}: state {state.id!r} needs exactly one initial sub-state or initial junction"
                    f" (State(initial=True) or Junction(initial=True)); found {[k.id for k in initial]}")
            node.default = initial[0]
        return node

    top = [make(s, None, 0) for s in cls.states]  # type: ignore[attr-defined]
    initial = [n for n in top if n.state.initial]
    for node in nodes.values():
        if node.is_state:
            node.below = frozenset(_below(node))
            during = f"during_{node.id}"
            node.during = during if structure.state(node.id).during else None

    segs: dict[int, Seg] = {}
    has_durations = False
    for info in structure.transitions:
        t = info.transition
        source = nodes[info.source]
        target = nodes[info.target] if info.target is not None else None
        temporal = tuple(spec for spec in (temporal_of(c.func) for c in t.cond) if spec is not None)
        durations = tuple(d for d in (duration_of(c.func) for c in t.cond) if d is not None)
        has_durations = has_durations or bool(durations)
        clock = source if source.is_state else _owner(source)
        seg = Seg(transition=t, info=info, source=source, target=target, events=_events_of(t),
                  clock=clock, temporal=temporal)
        segs[id(t)] = seg
        if clock is not None:
            clock.durations = tuple(dict.fromkeys((*clock.durations, *durations)))
        if source.kind == "history":
            continue  # the library's own default of a history state: not Stateflow's
        if info.scope == "segment":
            if target is None:
                raise ChartDefinitionError(f"{cls.__name__}: {info.label}: a junction's segment must end somewhere")
            source.out += (seg,)
        elif info.scope == "action":
            source.actions += (seg,)
        elif info.scope == "inner":
            source.inner += (seg,)
        else:
            source.outer += (seg,)
    events = {str(e.id): e for e in cls._events}  # type: ignore[attr-defined]
    return Program(top=tuple(n for n in top if n.is_state), nodes=nodes, segs=segs,
                   default=initial[0] if initial else None, has_durations=has_durations,
                   ordered=tuple(n for n in nodes.values() if n.is_state), events=events)


def _below(node: Node) -> Iterator[str]:
    for child in node.children:
        yield child.id
        yield from _below(child)
    for j in node.junctions:
        yield j.id
    if node.history is not None:
        yield node.history.id
