"""Breadth-first search over a chart's behaviour, by running it: which input steps take which transitions.

A **path** is a list of :class:`~.paths.Step` (:mod:`.paths` runs one): set
some inputs, maybe post an event, then tick the chart until it takes a transition (at most
:attr:`Bounds.max_ticks` chart steps).  The search runs the chart alone, as
bare-chart mode does (docs/scenarios.md, "Bare-chart mode"): built with the
arm's chart period, nothing feeding its inputs.  A chart cannot be copied, so
a path is replayed from power-on each time it is extended; that is exact, and
it is what the generated scenario file does too.

From each node the candidate steps come from the guards of the transitions
leaving the active states (:mod:`.guard_reader`): for every combination of
truth values of the comparisons on inputs (the truth table of the guards'
``and``/``or``/``not``), input values at the comparisons' boundaries, kept
once per transition that would then go first (Stateflow's priority: the order
written, docs/runtime.md); each comparison alone set just true and just false
(``x >= limit``: at ``limit`` and just below); the comparisons the active
states' actions make on inputs; every event the active states handle; and
waiting.  Time is no input: a step ticks until something happens, so
``after(n)``, ``after_s(t)`` and data that an action counts up are reached by
waiting.

Nodes are told apart by the active states and the data the guards read
(floating-point local data, which change every tick, left out); a step that
leads to a node seen before is kept only if it takes a transition no step took
before.  The first path that takes a transition is the shortest (fewest steps)
one found.
"""

from __future__ import annotations

import itertools
import math
import time
from collections import deque
from collections.abc import Container, Iterable
from dataclasses import dataclass
from typing import Any

from ..runtime import TickChart
from ..runtime.structure import TransitionInfo
from ..runtime.temporal import duration_of, temporal_of
from .guard_reader import GuardReader, Node, Setting, atoms, has_clock, kleene, refs, settings_for
from .paths import Sim, Step, same_value

#: How many comparisons of one decision the truth table enumerates (2**n combinations); above it,
#: only each comparison alone.
MAX_TABLE_ATOMS = 6


@dataclass(frozen=True)
class Bounds:
    """How far the search goes."""

    max_ticks: int = 20_000  #: longest a step waits for a transition, chart steps (40 s at 2 ms)
    max_depth: int = 80  #: longest path, steps
    max_nodes: int = 2_000  #: nodes expanded
    time_s: float = 120.0  #: wall-clock limit of one search: a safety net (the nodes bound the search)


def has_clock_spec(spec: Any) -> bool:
    """Whether a guard spec is a temporal operator or a ``duration``."""
    func = getattr(spec, "func", None)
    return temporal_of(func) is not None or duration_of(func) is not None


@dataclass(frozen=True)
class Candidate:
    """Inputs to set (and an event to post) before a step, with the reasons."""

    sets: tuple[tuple[str, Any], ...]
    events: tuple[str, ...]
    why: tuple[str, ...]


class Explorer:
    """The search over one chart class (see the module's docstring)."""

    def __init__(self, cls: type[TickChart], dt: float, bounds: Bounds | None = None) -> None:
        self.cls = cls
        self.dt = dt
        self.bounds = bounds or Bounds()
        self.structure = cls.structure()
        self.reader = GuardReader(cls)
        self.guards: dict[str, Node] = {t.label: self.reader.guard(t.transition) for t in self.structure.transitions}
        self.region = self._region_refs()
        self.junctions = {st.id for st in self.structure.states if st.junction}
        # comparisons of the chart's own data alone: what its actions will make of them is not known
        self.free = {a for g in self.guards.values() for a in atoms(g) if not refs(a) & self.reader.inputs}
        self._actions: dict[str, list[Node]] = {}
        self.nodes = 0
        self.complete = True  #: the search ended by exhausting the nodes, not a bound
        self.last_sim: Sim | None = None  #: a search stopped at its first find: the chart at its path's end
        self.start = self._start_step()
        self.seen_states: set[str] = set()  #: states active on some explored path (of every search)
        self._states_here: set[str] = set()  # ... of the current search

    def _start_step(self) -> Step | None:
        """Every path's first step: the inputs that only actions read (no guard, no comparison of an
        action) get values other than their defaults, so that what the actions do with them shows in
        the outputs the steps check (a dropped ``set_home`` with ``index_pos`` 0 would change nothing)."""
        decided = set().union(*(refs(g) for g in self.guards.values()))
        for state in self.structure.states:
            decided |= set().union(*(refs(a) for a in self._action_atoms(state.id)))
        values: dict[str, Any] = {}
        for d in self.cls.declarations():
            if d.kind != "input" or d.name in decided or isinstance(d.default, bool):
                continue
            if isinstance(d.default, float):
                values[d.name] = d.default * 1.25 if d.default else 0.125
            elif isinstance(d.default, int):
                values[d.name] = d.default + 1
        if not values:
            return None
        why = ("inputs that only actions read get values other than their defaults: what the actions"
               " do with them shows in the outputs",)
        return Sim(self.cls, self.dt).hold(Step(tuple(sorted(values.items())), why=why))

    # -- candidates ---------------------------------------------------------------------

    def outgoing(self, active: Iterable[str]) -> dict[tuple[str, str], list[TransitionInfo]]:
        """The transitions that may leave the active states, by (source, trigger), in priority order.

        A transition to a connective junction brings the junction's segments in, as a decision of their
        own under the trigger that leads there (docs/runtime.md, "Junctions").
        """
        active = set(active)
        groups: dict[tuple[str, str], list[TransitionInfo]] = {}
        reach: list[tuple[str, str]] = []
        for t in self.structure.transitions:
            if t.source in active:
                groups.setdefault((t.source, t.trigger), []).append(t)
                if t.target in self.junctions:
                    reach.append((t.target, t.trigger))
        while reach:
            junction, trigger = reach.pop()
            if (junction, trigger) in groups:
                continue
            for t in self.structure.transitions:
                if t.source == junction:
                    groups.setdefault((junction, trigger), []).append(t)
                    if t.target in self.junctions:
                        reach.append((t.target, trigger))
        for ts in groups.values():
            ts.sort(key=lambda t: ({"outer": 0, "inner": 1, "segment": 2, "action": 3}[t.scope], t.priority))
        return groups

    def candidates(self, chart: TickChart, covered: Container[str] = ()) -> list[Candidate]:
        """The steps to try from where ``chart`` stands (see the module's docstring).

        A setting whose first transition is sure, already ``covered`` and leads where the search has
        been (a button ignored once more, ``finish`` from one more drawing state) is left out.
        """
        data = dict(chart.data_mapping())
        found: dict[tuple[Any, ...], Candidate] = {}
        groups = self.outgoing(chart.configuration_values)

        waiting = self._predict(groups, None, data)

        def add(values: dict[str, Any], events: tuple[str, ...], why: Iterable[str], action: bool = False) -> None:
            sets = tuple(sorted((k, v) for k, v in values.items() if not same_value(v, data.get(k))))
            # settings that change no decision the same way are one candidate (the first: the fewest changes);
            # one that changes what an action does is its own
            trial = {**data, **dict(sets)}
            prediction = self._predict(groups, events[0] if events else None, trial)
            key = (sets, events) if action else (events, tuple(prediction.items()))
            changed = {g: truths for g, truths in prediction.items() if waiting.get(g) != truths}
            if key in found or (not action and (sets or events) and self._known(groups, changed, covered)):
                return
            found[key] = Candidate(sets, events, tuple(dict.fromkeys(why)))

        add({}, (), ())
        for (_source, trigger), ts in groups.items():
            events = () if trigger == "tick" else (trigger.split()[0],)
            if events:
                add({}, events, ())
                if self._again(ts, events[0], covered):
                    add({}, events * 2, ("the event twice in one chart step",))
            for values, why in self._decision(ts, data):
                add(values, events, why)
        for state in chart.configuration_values:
            for atom in self._action_atoms(state):
                for setting in settings_for(atom, self.reader, data).values():
                    add(dict(setting.values), (), (f"{setting.why} (an action of {state})",), action=True)
        return list(found.values())

    def _predict(self, groups: dict[tuple[str, str], list[TransitionInfo]], event: str | None,
                 data: dict[str, Any]) -> dict[tuple[str, str], tuple[bool | None, ...]]:
        """Per decision of the tick (and of ``event``), whether each transition's guard holds with these
        data (None: it may)."""
        out = {}
        for (source, trigger), ts in groups.items():
            if trigger != "tick" and (event is None or trigger.split()[0] != event):
                continue
            out[(source, trigger)] = tuple(kleene(self.guards[t.label], data, self.free) for t in ts)
        return out

    def _known(self, groups: dict[tuple[str, str], list[TransitionInfo]],
               changed: dict[tuple[str, str], tuple[bool | None, ...]], covered: Container[str]) -> bool:
        """Whether in each decision a step changes (from waiting), the first transition is sure, covered,
        and stays or goes to a state seen: the step would only repeat what the search did."""
        if not changed:
            return False
        for group, truths in changed.items():
            ts = groups[group]
            first = next((t for t, truth in zip(ts, truths, strict=True) if truth is not False), None)
            if first is None:
                continue
            if truths[ts.index(first)] is not True or first.label not in covered:
                return False
            if first.target is not None and first.target not in self._states_here:
                return False
        return True

    def _again(self, ts: list[TransitionInfo], event: str, covered: Container[str]) -> bool:
        """Whether posting ``event`` twice may take, the second time, a transition not yet covered: one
        on the same event from the state the first one enters (a double click)."""
        inside = {t.target for t in ts if t.target is not None}
        for s in self.structure.states:
            if s.parent in inside:
                inside.add(s.id)
        return any(t.source in inside and event in t.events and t.label not in covered
                   for t in self.structure.transitions)

    def _decision(self, ts: list[TransitionInfo], data: dict[str, Any]) -> list[tuple[dict[str, Any], list[str]]]:
        """Input values that let each transition of one decision go first (the truth table), and
        each comparison on inputs alone just true and just false."""
        table: list[Node] = []
        for t in ts:
            for a in atoms(self.guards[t.label]):
                if a[0] != "opaque" and refs(a) & self.reader.inputs and a not in table:
                    table.append(a)
        settings = {a: settings_for(a, self.reader, data) for a in table}
        out: list[tuple[dict[str, Any], list[str]]] = []
        for opts in settings.values():
            for setting in opts.values():
                out.append((dict(setting.values), [setting.why]))
        if len(table) <= MAX_TABLE_ATOMS:
            tables = [table]
        else:  # one table per transition, over its own comparisons
            tables = [own for t in ts
                      if len(own := [a for a in table if a in atoms(self.guards[t.label])]) <= MAX_TABLE_ATOMS]
        best: dict[str, tuple[Any, dict[str, Any], list[str]]] = {}
        for part in tables:
            self._table(ts, [settings[a] for a in part if settings[a]], data, best)
        out.extend((values, why) for _n, values, why in best.values())
        return out

    def _table(self, ts: list[TransitionInfo], options: list[dict[bool, Setting]], data: dict[str, Any],
               best: dict[str, tuple[Any, dict[str, Any], list[str]]]) -> None:
        """The truth table of some comparisons: per transition that goes first, the fewest changes."""
        choices = [[None, *opts.values()] for opts in options]  # None: leave the inputs as they are
        for combo in itertools.product(*choices):
            values: dict[str, Any] = {}
            why: list[str] = []
            conflict = False
            for setting in combo:
                if setting is None:
                    continue
                for k, v in setting.values:
                    conflict |= k in values and not same_value(values[k], v)
                    values[k] = v
                why.append(setting.why)
            if conflict:
                continue
            trial = {**data, **values}
            changes = sum(not same_value(v, data.get(k)) for k, v in values.items())
            blocked = False  # a transition before it may hold
            for t in ts:
                truth = kleene(self.guards[t.label], trial, self.free)
                if truth is False:
                    continue
                # best: the ones before it surely false, its own guard surely true, the fewest changes
                rank = (blocked, truth is not True, changes)
                if t.label not in best or rank < best[t.label][0]:
                    best[t.label] = (rank, values, why + [f"so '{t.label}' goes first"])
                if truth is True:
                    break
                blocked = True

    def _action_atoms(self, state: str) -> list[Node]:
        if state not in self._actions:
            info = next((s for s in self.structure.states if s.id == state), None)
            found: list[Node] = []
            for name in (info.during if info is not None else ()):
                func = getattr(self.cls, name, None)
                if callable(func):
                    found += [a for a in self.reader.action_atoms(func) if refs(a) & self.reader.inputs]
            self._actions[state] = found
        return self._actions[state]

    # -- search ---------------------------------------------------------------------------

    def _region_refs(self) -> dict[str, set[str]]:
        """Per top-level state, the data the guards inside it read (and the inputs)."""
        parent = {s.id: s.parent for s in self.structure.states}

        def top(state: str) -> str:
            while parent.get(state) is not None:
                state = parent[state]  # type: ignore[assignment]
            return state

        region: dict[str, set[str]] = {}
        for t in self.structure.transitions:
            region.setdefault(top(t.source), set()).update(refs(self.guards[t.label]))
        return region

    def key(self, chart: TickChart) -> tuple[Any, ...]:
        """What tells two nodes apart: the active states, and the data that the guards of the active
        top-level states' region read, floating-point values left out."""
        data = chart.data_mapping()
        active = frozenset(chart.configuration_values)
        names = set().union(*(self.region.get(s, set()) for s in active))
        kept = []
        for name in sorted(names):
            v = data[name]
            if isinstance(v, float):
                continue  # a measured quantity: it changes every tick, or has boundary values without end
            kept.append((name, v if not (isinstance(v, float) and math.isnan(v)) else "nan"))
        return (active, tuple(kept))

    def clock(self, active: Iterable[str]) -> float:
        """Ticks after which the temporal operators of the transitions leaving ``active`` change no more
        (0: there are none; infinite: ``every``, ``duration``, an event count)."""
        limit = 0.0
        for ts in self.outgoing(active).values():
            for t in ts:
                if not has_clock(self.guards[t.label]):
                    continue
                for spec in t.transition.cond:
                    temporal = temporal_of(getattr(spec, "func", None))
                    if temporal is None or temporal.op == "every" or temporal.event is not None:
                        limit = max(limit, math.inf) if has_clock_spec(spec) else limit
                    else:
                        limit = max(limit, temporal.ticks(self.dt))
        return limit

    def search(self, prefix: tuple[Step, ...] = (), wanted: set[str] | None = None,
               stop_at_first: bool = False, bounds: Bounds | None = None,
               root: Sim | None = None) -> dict[str, tuple[Step, ...]]:
        """Breadth-first from the end of ``prefix``: for each transition (of ``wanted``, default all)
        the first path found that takes it.  ``stop_at_first``: return at the first one (its chart, run
        to the path's end, is then :attr:`last_sim`); ``bounds``: other than the explorer's; ``root``:
        the chart already run through ``prefix`` (it is run on; without it, ``prefix`` is replayed)."""
        t0 = time.perf_counter()
        bounds = bounds or self.bounds
        if not prefix and self.start is not None:
            prefix = (self.start,)
        start_nodes = self.nodes
        labels = {t.label for t in self.structure.transitions}
        wanted = set(labels if wanted is None else wanted)
        found: dict[str, tuple[Step, ...]] = {}
        if root is None:
            root = Sim(self.cls, self.dt).replay(prefix)
        self.last_sim = None
        self._states_here = set(root.chart.configuration_values)
        self.seen_states |= self._states_here
        taken_here: set[str] = set()  # the transitions this search took: their children are in its queue
        seen = {self.key(root.chart)}
        queue: deque[tuple[tuple[Step, ...], Sim | None]] = deque([(prefix, root)])
        self.complete = True
        while queue and wanted - set(found):
            path, probe = queue.popleft()
            if len(path) - len(prefix) >= bounds.max_depth:
                self.complete = False
                continue
            if self.nodes - start_nodes >= bounds.max_nodes or time.perf_counter() - t0 > bounds.time_s:
                self.complete = False
                break
            self.nodes += 1
            if probe is None:
                probe = Sim(self.cls, self.dt).replay(path)
            active = tuple(probe.chart.configuration_values)
            clock = self.clock(active)
            watch = sorted(set().union(*(self.region.get(s, set()) for s in active)))
            covered = set(taken_here)
            for cand in self.candidates(probe.chart, covered):
                # the first candidate runs on the node's own chart, the others on replays of its path
                sim = probe if probe is not None else Sim(self.cls, self.dt).replay(path)
                probe = None
                step = sim.run(Step(cand.sets, cand.events, why=cand.why), bounds.max_ticks, clock, watch)
                if step is None and cand.sets and not cand.events:
                    # nothing happens with these inputs alone, but they may be half of what a later step needs
                    sim = Sim(self.cls, self.dt).replay(path)
                    step = sim.hold(Step(cand.sets, why=cand.why))
                if step is None:
                    continue
                new = [label for label in step.taken if label in wanted and label not in found]
                child = (*path, step)
                for label in new:
                    found[label] = child
                taken_here.update(step.taken)
                self._states_here |= set(sim.chart.configuration_values)
                self.seen_states |= self._states_here
                key = self.key(sim.chart)
                if key not in seen:
                    seen.add(key)
                    queue.append((child, sim))
                if new and stop_at_first:
                    self.last_sim = sim
                    return found
        return found
