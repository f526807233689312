"""What a chart class is made of, read once from its python-statemachine definition.

The clock (:mod:`.chart`), the diagrams (:mod:`.diagram`), the coverage report and a
future debugger all read the same :class:`ChartStructure`: states in document
order with their entry/during/exit actions, and every transition with its kind
(``tick`` or ``event``), guards, actions, Stateflow priority and a stable label.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

from statemachine.event import Event
from statemachine.state import HistoryState, State
from statemachine.transition import Transition
from statemachine.utils import humanize_id

from .junction import is_junction

if TYPE_CHECKING:
    from statemachine import StateChart

#: Prefix of the event generated for each tick transition (one unique event each).
TICK_EVENT_PREFIX = "_tick_"
#: Name the generated events show in python-statemachine's own diagrams.
TICK_EVENT_NAME = "tick"
#: Prefix of a during action's method name: ``during_<state id>``.
DURING_PREFIX = "during_"


@dataclass(frozen=True)
class StateInfo:
    """One state of a chart, with the names of its actions."""

    id: str
    label: str
    parent: str | None
    depth: int
    children: tuple[str, ...]
    initial: bool
    final: bool
    parallel: bool
    entry: tuple[str, ...]
    during: tuple[str, ...]
    exit: tuple[str, ...]
    history: Literal["", "shallow", "deep"] = ""
    junction: bool = False

    @property
    def is_compound(self) -> bool:
        return bool(self.children)


@dataclass(frozen=True)
class TransitionInfo:
    """One transition of a chart, as a diagram, a trace and coverage name it.

    ``kind`` is ``"tick"`` for a transition without an event (Stateflow's eventless
    transition, tried at every wake-up of the chart), ``"event"`` for one triggered
    by an event.  ``scope`` says where Stateflow tries it: ``"outer"`` (it leaves its
    source), ``"inner"`` (from the source's inner edge to the source itself, a
    descendant or a junction inside it), ``"segment"`` (it leaves a junction),
    ``"action"`` (no target: the source state's ``on`` action, run in its during
    phase).  ``priority`` is the 1-based execution order among the transitions of
    the same source and scope, in the order they were written.
    ``condition_actions`` run when the segment's condition holds (``before=``),
    ``transition_actions`` when the whole path reaches a state (``on=``).
    """

    index: int
    source: str
    target: str | None
    kind: Literal["tick", "event"]
    events: tuple[str, ...]
    tick_event: str | None
    guards: tuple[str, ...]
    actions: tuple[str, ...]
    internal: bool
    inner: bool
    priority: int
    label: str
    transition: Transition = field(compare=False, repr=False)
    scope: Literal["outer", "inner", "segment", "action"] = "outer"
    condition_actions: tuple[str, ...] = ()
    transition_actions: tuple[str, ...] = ()
    after_actions: tuple[str, ...] = ()

    @property
    def trigger(self) -> str:
        """``"tick"`` for a tick transition, else the event names joined by spaces."""
        return TICK_EVENT_NAME if self.kind == "tick" else " ".join(self.events)


@dataclass(frozen=True)
class ChartStructure:
    """States (pre-order: parents before children) and transitions of a chart class."""

    name: str
    doc: str
    states: tuple[StateInfo, ...]
    transitions: tuple[TransitionInfo, ...]
    tick_by_state: dict[str, tuple[TransitionInfo, ...]] = field(repr=False)
    by_transition: dict[int, TransitionInfo] = field(repr=False)
    tick_events: frozenset[str] = field(repr=False)
    user_events: tuple[str, ...] = ()

    def state(self, state_id: str) -> StateInfo:
        return next(s for s in self.states if s.id == state_id)

    def info(self, transition: Transition) -> TransitionInfo:
        """The :class:`TransitionInfo` of a transition object of this chart."""
        return self.by_transition[id(transition)]


def walk_states(states: Iterable[State], depth: int = 0) -> Iterator[tuple[State, int]]:
    """Yield ``(state, depth)`` in document order, each parent before its children."""
    for state in states:
        yield state, depth
        yield from walk_states(state.states, depth + 1)


def _walk_with_history(states: Iterable[State], depth: int = 0) -> Iterator[tuple[State, int]]:
    """Like :func:`walk_states`, with each compound's history pseudo-states after its children."""
    for state in states:
        yield state, depth
        yield from _walk_with_history(state.states, depth + 1)
        for history in state.history:
            yield history, depth + 1


def is_inner(transition: Transition) -> bool:
    """Whether a transition stays inside its source (Stateflow's inner transition).

    Written ``source.to(target, internal=True)`` with a target that is the source
    itself, a state inside it, or a junction (or history junction) inside it.
    """
    target = transition.target
    return bool(
        transition.internal and target is not None
        and (target is transition.source or target.is_descendant(transition.source))
    )


def scope_of(transition: Transition) -> Literal["outer", "inner", "segment", "action"]:
    """Where Stateflow tries a transition (see :class:`TransitionInfo`)."""
    if is_junction(transition.source):
        return "segment"
    if transition.target is None:
        return "action"
    return "inner" if is_inner(transition) else "outer"


def tag_tick_transitions(cls: type[StateChart]) -> None:
    """Give every eventless transition of ``cls`` its own generated event.

    python-statemachine takes eventless transitions by itself after every event
    (SCXML), which is not Stateflow's clock.  Each one gets a unique event
    ``_tick_<source>_<k>`` instead, named ``tick`` in diagrams; the runtime sends
    exactly that event when the transition's guard holds on a tick.
    """
    for state, _depth in walk_states(cls.states):
        k = 0
        for transition in state.transitions:
            if transition.initial or not transition.is_eventless:
                continue
            event = Event(id=f"{TICK_EVENT_PREFIX}{state.id}_{k}", name=TICK_EVENT_NAME)
            transition.add_event(event)
            cls.add_event(event)  # type: ignore[attr-defined]
            k += 1


def _display_name(state: State) -> str:
    # States show by their id (the thesis' names: start_stop, wait_1), unless the
    # chart gave an explicit name.
    return state.id if state.name == humanize_id(state.id) else str(state.name)


def action_names(cls: type, grouper: Any) -> tuple[str, ...]:
    """Names of the callbacks of a spec group that the class defines or was given."""
    names = set(dir(cls))
    return tuple(
        str(spec) for spec in grouper
        if not spec.is_convention or spec.func in names
    )


def _display_events(transition: Transition) -> tuple[str, ...]:
    """Event ids of a transition, without the generated tick event and without the
    SCXML dotted alias (``done.state.x``) the library adds beside ``done_state_x``."""
    ids = [str(e) for e in transition.events if not str(e).startswith(TICK_EVENT_PREFIX)]
    return tuple(e for e in ids if not ("." in e and e.replace(".", "_") in ids))


def _guard_names(transition: Transition) -> tuple[str, ...]:
    return tuple(str(spec) for spec in transition.cond)


def build_structure(cls: type[StateChart]) -> ChartStructure:
    """Read the structure of a chart class (after :func:`tag_tick_transitions`)."""
    names = set(dir(cls))
    states: list[StateInfo] = []
    transitions: list[TransitionInfo] = []
    tick_by_state: dict[str, tuple[TransitionInfo, ...]] = {}
    labels: dict[str, int] = {}
    index = 0
    for state, depth in _walk_with_history(cls.states):
        if isinstance(state, HistoryState):
            # A history pseudo-state: drawn and targeted, never active itself; its
            # default transition belongs to the library's entry, not to the clock.
            history_kind: Literal["shallow", "deep"] = "deep" if state.type.is_deep else "shallow"
            states.append(StateInfo(
                id=state.id, label="H*" if history_kind == "deep" else "H",
                parent=state.parent.id if state.parent else None, depth=depth, children=(),
                initial=False, final=False, parallel=False, entry=(), during=(), exit=(),
                history=history_kind,
            ))
            continue
        junction = is_junction(state)
        during_name = f"{DURING_PREFIX}{state.id}"
        states.append(StateInfo(
            id=state.id,
            label=state.id if junction else _display_name(state),
            parent=state.parent.id if state.parent else None,
            depth=depth,
            children=tuple(c.id for c in state.states) + tuple(h.id for h in state.history),
            initial=bool(state.initial),
            final=bool(state.final),
            parallel=bool(state.parallel),
            entry=() if junction else action_names(cls, state.enter),
            during=(during_name,) if during_name in names and not junction else (),
            exit=() if junction else action_names(cls, state.exit),
            junction=junction,
        ))
        own = [t for t in state.transitions if not t.initial]
        # Stateflow's execution order: per source and scope, in the order written
        orders: dict[str, int] = {}
        infos: dict[int, TransitionInfo] = {}
        for t in own:
            scope = scope_of(t)
            orders[scope] = orders.get(scope, 0) + 1
            tick_event = next((str(e) for e in t.events if str(e).startswith(TICK_EVENT_PREFIX)), None)
            events = _display_events(t)
            guards = _guard_names(t)
            kind: Literal["tick", "event"] = "tick" if tick_event else "event"
            target = t.target.id if t.target is not None else None
            trigger = TICK_EVENT_NAME if kind == "tick" else " ".join(events)
            guard_text = f" [{' and '.join(guards)}]" if guards else ""
            label = f"{state.id} -> {target or '(none)'}: {trigger}{guard_text}"
            labels[label] = labels.get(label, 0) + 1
            if labels[label] > 1:
                label = f"{label} #{labels[label]}"
            before, on, after = action_names(cls, t.before), action_names(cls, t.on), action_names(cls, t.after)
            info = TransitionInfo(
                index=index, source=state.id, target=target, kind=kind, events=events,
                tick_event=tick_event, guards=guards, actions=before + on + after,
                internal=bool(t.internal), inner=scope == "inner", priority=orders[scope],
                label=label, transition=t, scope=scope,
                condition_actions=before, transition_actions=on, after_actions=after,
            )
            index += 1
            infos[id(t)] = info
            transitions.append(info)
        tick_by_state[state.id] = tuple(
            i for scope in ("outer", "inner", "segment") for i in infos.values()
            if i.kind == "tick" and i.scope == scope)
    tick_events = frozenset(t.tick_event for t in transitions if t.tick_event)
    user_events: list[str] = []
    for t in transitions:
        for e in t.transition.events:
            if str(e) not in user_events and not str(e).startswith(TICK_EVENT_PREFIX):
                user_events.append(str(e))
    return ChartStructure(
        name=cls.__name__,
        doc=(cls.__doc__ or "").strip(),
        states=tuple(states),
        transitions=tuple(transitions),
        tick_by_state=tick_by_state,
        by_transition={id(t.transition): t for t in transitions},
        tick_events=tick_events,
        user_events=tuple(user_events),
    )


def states_entered_by(chart: StateChart, transition: Transition) -> list[State]:
    """The active states that ``transition`` (just taken) entered or re-entered.

    A chart of the runtime records them as it enters them (for a path through
    junctions, every segment of the path answers with the states the whole
    path entered); for another chart, the library's own transition domain says.
    Call it after the transition (e.g. from ``after_transition``).
    """
    path, entered = vars(chart).get("_entered_path", ((), None))
    if entered is not None and any(seg.transition is transition for seg in path):
        # the path's last segment enters them; the segments before it only lead there
        return list(entered) if path[-1].transition is transition else []
    if not transition.targets:
        return []
    domain = chart._engine.get_transition_domain(transition)
    config = list(chart.configuration)
    if domain is None:
        return config
    return [s for s in config if s.is_descendant(domain)]
