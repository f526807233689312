"""Breakpoints: what they watch, how their commands are parsed, the listener that hits them, the session's table.

Five kinds, written as in the REPL:

- ``enter Chart.state`` / ``exit Chart.state``: the library enters or exits
  the state (``on_enter_state`` / ``on_exit_state``), including re-entries
  and the states a history pseudo-state restores;
- ``transition Chart source->target``: a transition from ``source`` to
  ``target`` is taken (``after_transition``); ``*`` stands for any state; a
  junction is a source or a target too, so a breakpoint can watch one way out
  of a decision (``transition Chart j->large``);
- ``event Chart.name``: an event posted to the chart is handled at a tick, a
  transition with that trigger is taken (``tick`` for tick transitions, as
  the trace names them), or an action broadcasts it as a local event;
- ``when condition``: the condition (see :mod:`.expr`) *becomes* true; it is
  checked after every chart tick.

Transitions and events hit during the chart tick that takes them, so the
debugger stops right after the control step holding that tick.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any, Literal

from statemachine import StateChart
from statemachine.state import State
from statemachine.transition import Transition

from ..runtime.errors import suggest
from ..runtime.structure import TICK_EVENT_NAME, TICK_EVENT_PREFIX, ChartStructure
from .errors import DebugError
from .expr import Condition, Names, parse_condition

#: Breakpoints a session holds at most.
MAX_BREAKPOINTS = 50
#: Characters of ``when`` conditions, all together, at most: each is evaluated after every chart tick
#: (about 10 us a comparison in Python, 500 chart ticks a simulated second), so this keeps them to a few
#: tenths of a millisecond a tick and a run at its pace.
MAX_CONDITIONS_CHARS = 2000

Kind = Literal["enter", "exit", "transition", "event", "when"]
KINDS: tuple[Kind, ...] = ("enter", "exit", "transition", "event", "when")


@dataclass
class Breakpoint:
    """One breakpoint; ``spec`` is its command text without ``break``."""

    id: int
    kind: Kind
    spec: str
    chart: str | None = None
    state: str | None = None  # enter, exit
    source: str | None = None  # transition ('*': any)
    target: str | None = None
    event: str | None = None
    condition: Condition | None = None
    enabled: bool = True
    hits: int = 0
    #: For ``when``: the condition's value at the last check (it hits on a rising edge).
    last_value: bool = field(default=False, repr=False)

    def describe(self) -> str:
        state = "" if self.enabled else " (disabled)"
        return f"{self.id}: {self.spec}{state}, {self.hits} hit{'s' if self.hits != 1 else ''}"


@dataclass(frozen=True)
class Hit:
    """A breakpoint that hit: which, where (chart tick), and what happened."""

    breakpoint: int
    spec: str
    chart: str | None
    tick: int
    detail: str

    def describe(self) -> str:
        return f"breakpoint {self.breakpoint} ({self.spec}): {self.detail} at chart tick {self.tick}"


class ChartIndex:
    """The charts' names, states, transitions and events, for checking breakpoint specs."""

    def __init__(self, charts: dict[str, StateChart]) -> None:
        self.charts = charts

    def structure(self, chart: str) -> ChartStructure:
        c = self.charts.get(chart)
        if c is None:
            raise DebugError(f"no chart {chart!r}{suggest(chart, self.charts)};"
                             f" charts: {', '.join(self.charts)}")
        return type(c).structure()  # type: ignore[attr-defined,no-any-return]

    def states(self, chart: str) -> list[str]:
        return [s.id for s in self.structure(chart).states if not s.history]

    def check_state(self, chart: str, state: str) -> None:
        states = self.states(chart)
        if state not in states:
            raise DebugError(f"{chart} has no state {state!r}{suggest(state, states)};"
                             f" states: {', '.join(states)}")

    def events(self, chart: str) -> list[str]:
        return [TICK_EVENT_NAME, *self.structure(chart).user_events]

    def check_transition(self, chart: str, source: str, target: str) -> None:
        structure = self.structure(chart)
        all_states = [s.id for s in structure.states]
        for s in (source, target):
            if s != "*" and s not in all_states:
                raise DebugError(f"{chart} has no state {s!r}{suggest(s, all_states)};"
                                 f" states: {', '.join(all_states)}")
        if not any((source in ("*", t.source)) and (target in ("*", t.target))
                   for t in structure.transitions):
            near = [f"{t.source}->{t.target}" for t in structure.transitions
                    if t.source == source or t.target == target] or \
                   [f"{t.source}->{t.target}" for t in structure.transitions]
            raise DebugError(f"{chart} has no transition {source}->{target};"
                             f" transitions: {', '.join(dict.fromkeys(near))}")

    def check_event(self, chart: str, event: str) -> None:
        events = self.events(chart)
        if event not in events:
            raise DebugError(f"{chart} handles no event {event!r}{suggest(event, events)};"
                             f" events: {', '.join(events)} ('tick': any tick transition)")


_CHART_DOT = re.compile(r"^([A-Za-z_]\w*)\.([A-Za-z_]\w*)$")
_ARROW = re.compile(r"^([A-Za-z_]\w*|\*)\s*->\s*([A-Za-z_]\w*|\*)$")


def _chart_dot(kind: str, text: str, what: str) -> tuple[str, str]:
    m = _CHART_DOT.match(text.strip())
    if m is None:
        raise DebugError(f"break {kind}: expected Chart.{what}, got {text.strip()!r}")
    return m.group(1), m.group(2)


def parse_breakpoint(bp_id: int, text: str, index: ChartIndex, names: Names) -> Breakpoint:
    """A breakpoint from its command text (``enter DriveInit1.turn_back`` ...).

    Every chart, state, transition, event and datum is checked now, so a typo
    is an error at once, not a breakpoint that never hits.
    """
    kind, _, rest = text.strip().partition(" ")
    rest = rest.strip()
    if kind not in KINDS:
        raise DebugError(f"unknown breakpoint kind {kind!r}; kinds: {', '.join(KINDS)}")
    if not rest:
        example = {"enter": "DriveInit1.turn_back", "exit": "DriveInit1.turn_fwd",
                   "transition": "DriveInit1 turn_fwd->turn_back", "event": "DriveInit1.tick",
                   "when": "DriveInit1.pos_Encoder > 1.0"}[kind]
        raise DebugError(f"break {kind}: what? e.g. 'break {kind} {example}'")
    if kind in ("enter", "exit"):
        chart, state = _chart_dot(kind, rest, "state")
        index.check_state(chart, state)
        return Breakpoint(bp_id, kind, f"{kind} {chart}.{state}", chart=chart, state=state)
    if kind == "event":
        chart, event = _chart_dot(kind, rest, "event")
        index.check_event(chart, event)
        return Breakpoint(bp_id, kind, f"event {chart}.{event}", chart=chart, event=event)
    if kind == "transition":
        chart, _, arrow = rest.partition(" ")
        if "." in chart and not arrow.strip():  # Chart.source->target
            chart, _, arrow = rest.partition(".")
        m = _ARROW.match(arrow.strip())
        if m is None:
            raise DebugError(f"break transition: expected 'Chart source->target', got {rest!r}")
        source, target = m.group(1), m.group(2)
        index.structure(chart)
        index.check_transition(chart, source, target)
        return Breakpoint(bp_id, kind, f"transition {chart} {source}->{target}", chart=chart,
                          source=source, target=target)
    condition = parse_condition(rest, names)
    return Breakpoint(bp_id, "when", f"when {condition.text}", condition=condition)


class BreakListener:
    """A python-statemachine listener that turns chart callbacks into :class:`Hit` records.

    The debugger attaches one to every chart and reads :attr:`hits` after each
    control step; :attr:`transitions` counts the transitions taken (for ``next``).
    """

    def __init__(self, breakpoints: list[Breakpoint]) -> None:
        self.breakpoints = breakpoints
        self.hits: list[Hit] = []
        self.transitions = 0
        self.muted = False  # during a replay

    def _hit(self, bp: Breakpoint, machine: Any, detail: str) -> None:
        if self.muted:
            return
        tick = int(getattr(machine, "tick_count", 0))
        # One hit per breakpoint and tick for events (a posted event that also takes
        # a transition); enter/exit/transition may hit twice in a tick (two events).
        if any(h.breakpoint == bp.id and h.tick == tick and (bp.kind == "event" or h.detail == detail)
               for h in self.hits):
            return
        bp.hits += 1
        self.hits.append(Hit(bp.id, bp.spec, bp.chart, tick, detail))

    def _watching(self, kind: str, chart: str) -> list[Breakpoint]:
        return [bp for bp in self.breakpoints if bp.enabled and bp.kind == kind and bp.chart == chart]

    def on_enter_state(self, machine: StateChart, target: State) -> None:
        for bp in self._watching("enter", machine.chart_name):  # type: ignore[attr-defined]
            if bp.state == target.id:
                self._hit(bp, machine, f"entered {target.id}")

    def on_exit_state(self, machine: StateChart, source: State) -> None:
        for bp in self._watching("exit", machine.chart_name):  # type: ignore[attr-defined]
            if bp.state == source.id:
                self._hit(bp, machine, f"exited {source.id}")

    def after_transition(self, machine: StateChart, transition: Transition, event: Any) -> None:
        self.transitions += 1
        chart = machine.chart_name  # type: ignore[attr-defined]
        source = transition.source.id
        target = transition.target.id if transition.target is not None else source
        for bp in self._watching("transition", chart):
            if bp.source in ("*", source) and bp.target in ("*", target):
                self._hit(bp, machine, f"{source} -> {target}")
        event_id = str(event) if event is not None else ""
        trigger = TICK_EVENT_NAME if event_id.startswith(TICK_EVENT_PREFIX) else event_id
        for bp in self._watching("event", chart):
            if bp.event == trigger:
                self._hit(bp, machine, f"{trigger}: {source} -> {target}")

    def on_local_event(self, machine: StateChart, event: str, source: State | None, target: State | None) -> None:
        """A chart's action broadcast a local event (``self.send``): an event breakpoint on it hits."""
        chart = machine.chart_name  # type: ignore[attr-defined]
        for bp in self._watching("event", chart):
            if bp.event == event:
                where = f" from {source.id}" if source is not None else ""
                to = f" to {target.id}" if target is not None else ""
                self._hit(bp, machine, f"local event {event} sent{where}{to}")

    def events_handled(self, machine: StateChart, events: Iterable[str]) -> None:
        """Posted events the chart handled in its last tick (taken or not)."""
        chart = machine.chart_name  # type: ignore[attr-defined]
        for event in events:
            for bp in self._watching("event", chart):
                if bp.event == event:
                    self._hit(bp, machine, f"{event} handled")


class BreakpointTable:
    """The session's breakpoints, by number: added from their command text, enabled, disabled, deleted.

    :attr:`items` is the list the :attr:`listener` (attached to every chart)
    watches; ``when`` breakpoints are checked after every chart tick
    (:meth:`check_conditions`) and hit when their condition *becomes* true.
    ``index``: the charts as they are now (a replay or a Safety reset replaces
    them); ``names``: what conditions read.
    """

    def __init__(self, index: Callable[[], ChartIndex], names: Names) -> None:
        #: The breakpoints, in the order they were added.
        self.items: list[Breakpoint] = []
        self.listener = BreakListener(self.items)
        self._index = index
        self._names = names
        self._next_id = 1

    def add(self, text: str) -> Breakpoint:
        """Add a breakpoint from its command text, e.g. ``"enter DriveInit1.turn_back"``,
        ``"transition DriveInit1 turn_fwd->turn_back"``, ``"event DriveInit1.tick"``,
        ``"when DriveInit1.pos_Encoder > 1.0"``."""
        if len(self.items) >= MAX_BREAKPOINTS:
            raise DebugError(f"at most {MAX_BREAKPOINTS} breakpoints: delete some first (delete N, or delete all)")
        bp = parse_breakpoint(self._next_id, text, self._index(), self._names)
        if bp.condition is not None:
            total = sum(len(b.spec) for b in self.items if b.condition is not None) + len(bp.spec)
            if total > MAX_CONDITIONS_CHARS:
                raise DebugError(f"the 'when' breakpoints would hold {total} characters of conditions, more than the"
                                 f" {MAX_CONDITIONS_CHARS} that are checked after every chart tick; delete some"
                                 " first")
            bp.last_value = bp.condition.evaluate(self._names)
        self._next_id += 1
        self.items.append(bp)
        return bp

    def find(self, bp_id: int) -> Breakpoint:
        """The breakpoint numbered ``bp_id``; :class:`DebugError` lists the numbers there are."""
        for bp in self.items:
            if bp.id == bp_id:
                return bp
        known = ", ".join(str(b.id) for b in self.items) or "none"
        raise DebugError(f"no breakpoint {bp_id}; breakpoints: {known}")

    def delete(self, bp_id: int | None = None) -> None:
        """Delete one breakpoint, or all of them (``None``)."""
        if bp_id is None:
            self.items.clear()
        else:
            self.items.remove(self.find(bp_id))

    def enable(self, bp_id: int, enabled: bool = True) -> None:
        """Enable a breakpoint (``enabled=False``: disable it); a condition enabled hits when it *becomes* true."""
        bp = self.find(bp_id)
        if enabled and not bp.enabled and bp.condition is not None:
            bp.last_value = bp.condition.evaluate(self._names)  # hits when it *becomes* true
        bp.enabled = enabled

    def disable(self, bp_id: int) -> None:
        """Keep a breakpoint, unchecked."""
        self.enable(bp_id, False)

    def conditions(self) -> list[Breakpoint]:
        """The enabled ``when`` breakpoints: checked after every chart tick."""
        return [bp for bp in self.items if bp.enabled and bp.kind == "when"]

    def watch_events(self) -> bool:
        """An enabled ``event`` breakpoint needs the events each chart tick handles."""
        return any(bp.enabled and bp.kind == "event" for bp in self.items)

    def check_conditions(self, when: list[Breakpoint], tick: int) -> None:
        """After chart tick ``tick``: each condition that became true hits."""
        for bp in when:
            assert bp.condition is not None
            value = bp.condition.evaluate(self._names)
            if value and not bp.last_value:
                bp.hits += 1
                self.listener.hits.append(Hit(bp.id, bp.spec, None, tick, "became true"))
            bp.last_value = value

    def rearm(self) -> None:
        """Read every condition again (the robot was rebuilt under it): it hits when it becomes true from now."""
        for bp in self.items:
            if bp.condition is not None:
                bp.last_value = bp.condition.evaluate(self._names)
