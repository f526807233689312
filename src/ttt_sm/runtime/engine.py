"""Stateflow's execution of a chart: one wake-up, step by step as MathWorks documents it.

A chart wakes up on a tick (no event) or on an event.  In one wake-up
(:meth:`Execution._wake`), for the active state at the top and then down its
active children:

1. its **outer transitions** are tried in execution order (a transition is
   tried when it has no event or the wake-up's event is one of its events,
   and its condition holds); a valid one is taken and ends the state's step;
2. otherwise its **during action** runs, then its ``on`` **actions** whose
   event (or temporal condition) matches;
3. its **inner transitions** are tried in execution order; a valid one is
   taken and ends the state's step;
4. otherwise its **active child** executes the same way (a parallel state's
   regions one after the other, in the order written, each a full step).

A transition is valid when its condition holds and its path ends at a state.
A path may run through connective junctions (:meth:`Execution._follow`): each
segment's condition action runs as soon as its condition holds; a junction
whose segments all fail sends the evaluation back to the junction before it
(backtracking; condition actions already run are not undone); a junction
with no segment at all ends the path there (a flow chart: no state is left
or entered).  Taking a path (:meth:`Execution._take`) exits the source (its
active children first, innermost first), runs the segments' transition
actions in order, and enters the destination (parents first, then default
transitions or history down to a leaf).

Local events (:meth:`Execution.send` from an action) are handled at once, as a
nested wake-up of the whole chart or of the state they are sent to; when it
returns, Stateflow's early-return rules end the action (and what it was part
of) if the broadcast made its state inactive.

python-statemachine holds the configuration: the engine writes it after every
transition, and calls the library's callbacks (the chart's own actions and
every listener's hooks: ``on_enter_state``, ``after_transition``, ...) with the
arguments the library would pass.  The chart's own actions that need no
arguments are called directly, which is what keeps a quiet tick under a
microsecond and a transition in a few.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from typing import Any

from statemachine.orderedset import OrderedSet
from statemachine.state import State

from .callbacks import LibraryCallbacks, no_action
from .errors import ChartExecutionError
from .program import Node, Program, Seg

#: The path of a transition ended at a terminal junction (a flow chart: nothing exited or entered).
TERMINAL = object()
#: How deep local events may nest before the chart is in an endless broadcast.
MAX_BROADCAST_DEPTH = 64


class EarlyReturn(Exception):
    """A local event made the state whose action sent it inactive: the rest of that step is skipped."""


class Execution(LibraryCallbacks):
    """The Stateflow execution of a :class:`~.chart.TickChart` instance (a mixin of it).

    Instance data (all in ``__dict__``): ``_active`` (ids of the active states),
    ``_entered_at`` (tick each state was last entered), ``_counts`` (events counted
    per state for event-based temporal logic), ``_since`` (when each duration
    condition became true), ``_recorded`` (history), ``_runners`` (callbacks per
    library key), ``_frames`` (what the actions now running belong to), ``_event``
    and ``_event_kwargs`` (the wake-up's event), ``_taken`` (transitions taken this tick).
    """

    # what the chart class gives the mixin (TickChart and python-statemachine's StateChart)
    _program: Program
    _callbacks: Any
    _config: Any
    _listeners: dict[int, Any]
    chart_name: str
    states_map: dict[Any, State]
    start_configuration_values: list[Any]

    def _compile_guard(self, seg: Seg) -> Callable[[], Any] | None:
        """The guard of a segment as a plain call (None: no guard); the chart compiles it."""
        raise NotImplementedError

    def _duration_condition(self, node: Node, spec: Any) -> Callable[[], Any]:
        """A ``duration`` condition as a plain call; the chart compiles it."""
        raise NotImplementedError

    # -- activation ----------------------------------------------------------------------------

    def _activate(self) -> None:
        """Enter the chart: its default transitions (or the states it was asked to start in)."""
        program = self._program
        starts = [self.states_map[v] for v in self.start_configuration_values]
        self.__dict__["_stepping"] += 1
        try:
            if starts:
                targets = {program.nodes[s.id] for s in starts}
                for node in program.top:
                    if any(node is t or node.contains(t) for t in targets):
                        self._enter(node, targets, None)
            else:
                self._enter_default_of(None, program.default, None)
        finally:
            self.__dict__["_stepping"] -= 1
        self._sync_configuration()

    # -- one wake-up ----------------------------------------------------------------------------

    def _wake(self, event: str | None, kwargs: dict[str, Any] | None = None,
              receiver: Node | None = None) -> None:
        """One wake-up of the chart on `event` (None: a tick), or of `receiver` (a directed event)."""
        d = self.__dict__
        saved = d["_event"], d["_event_kwargs"]
        d["_event"], d["_event_kwargs"] = event, kwargs or {}
        d["_stepping"] += 1
        try:
            if event is not None:
                self._count_event(event)
            if self._program.has_durations:
                self._sample_durations()
            if receiver is not None:
                if receiver.id in d["_active"]:
                    self._exec(receiver)
            else:
                for node in self._program.top:
                    if node.id in d["_active"]:
                        self._exec(node)
                        break
        finally:
            d["_stepping"] -= 1
            d["_event"], d["_event_kwargs"] = saved

    def _exec(self, node: Node, phase: str = "outer", start: int = 0, held: bool = False) -> None:
        """Execute an active state: outer transitions, during and on actions, inner transitions, children.

        `phase`, `start` and `held` resume a wake-up that a tick plan began: at the
        transition ``start`` of the outer or inner ones, whose guard held.
        """
        try:
            if phase == "outer":
                if node.outer and self._try(node, node.outer, start, held):
                    return
                self._during(node)
                start, held = 0, False
            if node.inner and self._try(node, node.inner, start, held):
                return
        except EarlyReturn:
            return
        self._exec_children(node)

    def _exec_children(self, node: Node, after: Node | None = None) -> None:
        """Execute the active children of `node` (a parallel state's regions after `after`, if given)."""
        active = self.__dict__["_active"]
        if node.parallel:
            regions = node.children
            if after is not None:
                regions = regions[regions.index(after) + 1:]
            for region in regions:
                if region.id in active:
                    self._exec(region)
                if node.id not in active:
                    return  # a region's transition left the parallel state
        elif after is None:
            for child in node.children:
                if child.id in active:
                    self._exec(child)
                    return

    def _during(self, node: Node) -> None:
        """The during action, then the ``on`` actions whose event or condition matches."""
        d = self.__dict__
        frames = d["_frames"]
        if node.during is not None:
            frames.append(("during", node, None))
            try:
                getattr(self, node.during)()
            finally:
                frames.pop()
        for seg in node.actions:
            if self._matches(seg) and self._guard(seg):
                frames.append(("during", node, None))
                try:
                    ctx = (seg.transition, node.state, self._event_object(seg))
                    t = seg.transition
                    self._runner(t.before.key)(ctx)
                    self._runner(t.on.key)(ctx)
                    self._runner(t.after.key)(ctx)
                finally:
                    frames.pop()
            if node.id not in d["_active"]:
                raise EarlyReturn

    # -- transitions ------------------------------------------------------------------------------

    def _matches(self, seg: Seg) -> bool:
        events = seg.events
        return events is None or self.__dict__["_event"] in events

    def _guard(self, seg: Seg) -> bool:
        guards = self.__dict__["_guards"]
        t = seg.transition
        guard = guards.get(id(t), _UNSET)
        if guard is _UNSET:
            guard = guards[id(t)] = self._compile_guard(seg)
        return guard is None or bool(guard())

    def _try(self, node: Node, segs: Sequence[Seg], start: int = 0, held: bool = False) -> bool:
        """Try `segs` of `node` in order from `start`; take the first valid path.

        `held`: the guard of ``segs[start]`` was evaluated already and held.
        Returns True when the state's step ended here (a path was taken).  A path
        that ends at a terminal junction ends the trying (no later transition of
        `segs` is tried, nothing is left): the state's step goes on.
        """
        d = self.__dict__
        for seg in segs[start:] if start else segs:
            if held:
                held = False
            elif not self._matches(seg) or not self._guard(seg):
                continue
            path = self._follow(node, [seg])
            if path is None:
                continue  # every way on from a junction failed: try the next transition
            if path is TERMINAL:
                return node.id not in d["_active"]
            assert isinstance(path, list)
            self._take(node, path)
            return True
        return node.id not in d["_active"]

    def _condition_action(self, node: Node | None, seg: Seg) -> None:
        key = seg.transition.before.key
        run = self._runner(key)
        if run is no_action:
            return
        frames = self.__dict__["_frames"]
        frames.append(("condition", node, None))
        try:
            run((seg.transition, seg.source.state, self._event_object(seg)))
        finally:
            frames.pop()

    def _follow(self, node: Node | None, path: list[Seg]) -> list[Seg] | object | None:
        """A path whose last segment's condition held: run its condition action, follow junctions.

        `node` is the state the path leaves (None: the chart's default transition).

        Returns the whole path to a state, :data:`TERMINAL` for a path that ended at a
        terminal junction (its transition actions run: the path is complete, as
        MathWorks' "Modeling Guidelines for Stateflow Charts" says), or None when every
        way on failed (the caller backtracks).
        """
        seg = path[-1]
        self._condition_action(node, seg)
        if node is not None and node.id not in self.__dict__["_active"]:
            raise EarlyReturn  # a condition action's broadcast left the source
        target = seg.target
        assert target is not None
        if target.kind != "junction":
            return path
        if not target.out:
            self._transition_actions(path)
            return TERMINAL
        for nxt in target.out:
            if self._matches(nxt) and self._guard(nxt):
                found = self._follow(node, [*path, nxt])
                if found is not None:
                    return found
        return None

    def _transition_actions(self, path: Sequence[Seg]) -> None:
        frames = self.__dict__["_frames"]
        for seg in path:
            run = self._runner(seg.transition.on.key)
            if run is no_action:
                continue
            frames.append(("transition", path[0].source, path))
            try:
                run((seg.transition, seg.source.state, self._event_object(seg)))
            finally:
                frames.pop()

    def _take(self, source: Node, path: list[Seg]) -> None:
        """Take a valid path: exit, transition actions, enter; then the library's after-callbacks."""
        d = self.__dict__
        active = d["_active"]
        end = path[-1].target
        assert end is not None
        via_history = end.kind == "history"
        target = end.parent if via_history else end
        assert target is not None
        inner = path[0].info.scope == "inner" and (target is source or source.contains(target))
        outer_log, d["_entered_log"] = d["_entered_log"], []
        try:
            if inner:
                domain: Node | None = source
                if target is source and not via_history:
                    # an inner transition to the state itself: nothing is exited or entered
                    self._transition_actions(path)
                    d["_entered_path"] = (path, [])
                    self._after(path)
                    return
                if source.parallel:
                    top_exit = top_enter = _child_towards(source, target)
                else:
                    top_exit = next((c for c in source.children if c.id in active), None)
                    top_enter = _child_towards(source, target) if target is not source else None
            else:
                domain = _domain(source, target)
                top_exit = _child_towards(domain, source)
                top_enter = _child_towards(domain, target)
            if domain is not None:
                self._record_history(domain)
            if top_exit is not None and top_exit.id in active:
                self._exit(top_exit, path)
            self._sync_configuration()
            self._transition_actions(path)
            if domain is not None and domain.id not in active:
                return  # a transition action's broadcast left the transition's parent
            if top_enter is None:
                self._enter_children(source, None, path)  # inner transition to the history junction
            else:
                self._enter(top_enter, {target}, path)
        except EarlyReturn:
            pass
        finally:
            self._sync_configuration()
            entered, d["_entered_log"] = d["_entered_log"], outer_log
            outer_log.extend(entered)
        d["_entered_path"] = (path, entered)
        self._after(path)

    def _after(self, path: Sequence[Seg]) -> None:
        """The library's after-transition callbacks of every segment (listeners, ``after=``)."""
        d = self.__dict__
        taken = d["_taken"]
        for seg in path:
            taken.append(seg.transition)
            run = self._runner(seg.transition.after.key)
            if run is not no_action:
                run((seg.transition, seg.transition.target, self._event_object(seg)))

    # -- entering and exiting -----------------------------------------------------------------------

    def _enter(self, node: Node, targets: set[Node], path: Sequence[Seg] | None) -> None:
        """Enter `node` (inactive) and below it towards `targets`, else by default or history."""
        d = self.__dict__
        d["_active"].add(node.id)
        d["_entered_at"][node.id] = d["_ticks"]
        d["_entered_log"].append(node.state)
        d["_counts"][node.id] = {}  # events counted since this entry (the one entering it is not)
        for spec in node.durations:
            # duration(C) counts from when C became true, but never from before the state was entered
            if self._duration_condition(node, spec)():
                d["_since"][(node.id, spec)] = d["_ticks"]
            else:
                d["_since"].pop((node.id, spec), None)
        run = self._runner(node.state.enter.key)
        if run is not no_action:
            d["_frames"].append(("entry", node, None))
            try:
                run((path[-1].transition if path else None, node.state,
                     self._event_object(path[-1]) if path else None, "enter"))
            finally:
                d["_frames"].pop()
            if node.id not in d["_active"]:
                raise EarlyReturn
        if node.children:
            self._enter_children(node, targets, path)

    def _enter_children(self, node: Node, targets: set[Node] | None,
                        path: Sequence[Seg] | None) -> None:
        if node.parallel:
            for region in node.children:
                self._enter(region, targets or set(), path)
            return
        for child in node.children:
            if targets and any(t is child or child.contains(t) for t in targets):
                self._enter(child, targets, path)
                return
        recorded = self.__dict__["_recorded"].get(node.id) if node.history is not None else None
        if recorded:
            child = self._program.nodes[recorded[0]]
            self._enter(child, {self._program.nodes[i] for i in recorded[1:]} if node.deep else set(), path)
            return
        self._enter_default_of(node, node.default, path)

    def _enter_default_of(self, node: Node | None, default: Node | None,
                          path: Sequence[Seg] | None) -> None:
        """Follow the default transition of `node` (None: the chart) into a state."""
        if default is None:
            return
        if default.kind == "state":
            self._enter(default, set(), path)
            return
        # a default transition through junctions: conditions decide, actions run, as for any path
        for seg in default.out:
            if self._matches(seg) and self._guard(seg):
                found = self._follow(node, [seg])
                if isinstance(found, list):
                    end = found[-1].target
                    assert end is not None
                    self._transition_actions(found)
                    top = _child_towards(node, end)
                    assert top is not None
                    self._enter(top, {end}, found)
                    self._after(found)
                    return
        where = node.id if node is not None else "the chart"
        raise ChartExecutionError(
            f"{self.chart_name}: no default transition of {where} is valid (from junction {default.id!r}):"
            " a state must enter one of its sub-states; add a segment without a condition")

    def _exit(self, node: Node, path: Sequence[Seg] | None = None) -> None:
        """Exit an active state: its active children first (a parallel state's in reverse order)."""
        d = self.__dict__
        active = d["_active"]
        if node.children:
            self._record_history(node)
            for child in reversed(node.children) if node.parallel else node.children:
                if child.id in active:
                    self._exit(child, path)
        run = self._runner(node.state.exit.key)
        if run is not no_action:
            d["_frames"].append(("exit", node, None))
            try:
                run((path[0].transition if path else None, node.state,
                     self._event_object(path[0]) if path else None, "exit"))
            finally:
                d["_frames"].pop()
            if node.id not in active:
                raise EarlyReturn
        active.discard(node.id)

    def _record_history(self, node: Node) -> None:
        """Remember the active child of a state with a history junction (all below it, for deep history)."""
        if node.history is None:
            return
        active = self.__dict__["_active"]
        child = next((c for c in node.children if c.id in active), None)
        if child is None:
            return
        rest = [i for i in _ids_below(child) if i in active] if node.deep else []
        self.__dict__["_recorded"][node.id] = (child.id, *rest)

    def _sync_configuration(self) -> None:
        """Write the active states to python-statemachine's configuration (document order)."""
        nodes = self._program.nodes
        active = sorted((nodes[i] for i in self.__dict__["_active"]), key=_by_index)
        self._config._write_to_model(OrderedSet(n.state.value for n in active))

    # -- local events -------------------------------------------------------------------------------

    def _broadcast(self, event: str, receiver: Node | None, kwargs: dict[str, Any]) -> None:
        """A local event from an action: a nested wake-up now; then Stateflow's early return."""
        d = self.__dict__
        if d["_depth"] >= MAX_BROADCAST_DEPTH:
            raise ChartExecutionError(
                f"{self.chart_name}: local event {event!r} nested {MAX_BROADCAST_DEPTH} deep: the chart"
                " broadcasts events without end (an action sends an event whose handling sends it again)")
        frame = d["_frames"][-1] if d["_frames"] else None
        self._tell_local_event(event, frame[1] if frame is not None else None, receiver)
        d["_depth"] += 1
        frames, d["_frames"] = d["_frames"], []
        try:
            self._wake(event, kwargs, receiver)
        finally:
            d["_frames"] = frames
            d["_depth"] -= 1
        if frame is not None and self._returns_early(frame):
            raise EarlyReturn

    def _tell_local_event(self, event: str, sender: Node | None, receiver: Node | None) -> None:
        """Listeners with ``on_local_event(machine, event, source, target)`` hear every local event
        (a trace, the debugger's event breakpoints, a scenario's ``expect_events``)."""
        for listener in list(self._listeners.values()):
            hook = getattr(listener, "on_local_event", None)
            if hook is not None:
                hook(machine=self, event=event, source=sender.state if sender is not None else None,
                     target=receiver.state if receiver is not None else None)

    def _returns_early(self, frame: tuple[str, Node, Any]) -> bool:
        """Stateflow's early-return rule for the action that just broadcast."""
        kind, node, path = frame
        active = self.__dict__["_active"]
        if node is None:
            return False  # the chart's own default transition: the chart stays active
        if kind in ("entry", "during", "exit", "condition"):
            return node.id not in active
        # a transition action: the path's parent must be active and have no active child
        # among those the path was going to enter
        source: Node = node
        end = path[-1].target if path else None
        target = end.parent if end is not None and end.kind == "history" else end
        parent = source if target is not None and path[0].info.scope == "inner" else (
            _domain(source, target) if target is not None else source.parent)
        if parent is not None and parent.id not in active:
            return True
        siblings = parent.children if parent is not None else self._program.top
        return not (parent is not None and parent.parallel) and any(c.id in active for c in siblings)

    # -- temporal logic ---------------------------------------------------------------------------------

    def _count_event(self, event: str) -> None:
        """Count `event` for every active state (``after(n, E)``, ``temporal_count(E)``)."""
        counts = self.__dict__["_counts"]
        for state_id in self.__dict__["_active"]:
            seen = counts[state_id]
            seen[event] = seen.get(event, 0) + 1

    def _sample_durations(self) -> None:
        d = self.__dict__
        since, active = d["_since"], d["_active"]
        for node in self._program.ordered:
            if not node.durations or node.id not in active:
                continue
            for spec in node.durations:
                holds = self._duration_condition(node, spec)()
                key = (node.id, spec)
                if not holds:
                    since.pop(key, None)
                elif key not in since:
                    since[key] = d["_ticks"]

    # -- helpers ------------------------------------------------------------------------------------------

    def _event_object(self, seg: Seg) -> Any:
        """The event a callback of `seg` is told about: the wake-up's, or the tick event of an eventless one."""
        event = self.__dict__["_event"]
        if event is not None and seg.events is not None:
            return event
        return seg.info.tick_event or event


_UNSET = object()


def _by_index(node: Node) -> int:
    return node.index


def _child_towards(ancestor: Node | None, node: Node | None) -> Node | None:
    """The child of `ancestor` (None: the top level) that is `node` or contains it."""
    while node is not None and node.parent is not ancestor:
        node = node.parent
    return node


def _domain(source: Node, target: Node | None) -> Node | None:
    """The lowest state strictly above `source` that contains `target` (None: the chart).

    An outer transition exits everything below its domain on the source's side.
    A transition from one region of a parallel state to another leaves the
    parallel state itself (its regions are never entered one without the others).
    """
    if target is None:
        return source.parent
    for anc in source.ancestors():
        if anc.contains(target) and not anc.parallel:
            return anc
    return None


def _ids_below(node: Node) -> Iterable[str]:
    for child in node.children:
        yield child.id
        yield from _ids_below(child)
