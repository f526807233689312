"""TickChart: a python-statemachine ``StateChart`` run with Stateflow's semantics and clock.

A chart is written like any python-statemachine chart — states as attributes,
``source.to(target, cond=..., on=...)``, callbacks by name — and reads like its
diagram.  The runtime (:mod:`.engine`) executes it as Stateflow executes a
chart: one **wake-up** per tick (or per event), outer transitions of the
active state first, then its during and ``on`` actions, its inner
transitions, its active children (docs/runtime.md, "One wake-up").

* a transition **without an event** (``off.to(on, cond="switch")``) is tried at
  every wake-up: Stateflow's eventless transition;
* a transition **with an event** (``button = off.to(on)``) only when that event
  wakes the chart: :meth:`TickChart.post` queues it for the next tick,
  :meth:`TickChart.send` wakes the chart on it now (from an action: a local
  event, handled at once).

One :meth:`TickChart.tick`: outputs are copied to ``<name>_p`` (their value one
chart tick earlier), then the chart wakes once for each event posted since the
last tick, in order, or once with no event if none was posted.

A quiet tick (no transition taken) never builds event data: the guards and
actions of the active configuration run as one generated function, cached per
configuration (the *plan*).
"""

from __future__ import annotations

from array import array
from collections import deque
from collections.abc import Mapping, MutableSet, Sequence
from functools import partial
from typing import TYPE_CHECKING, Any, ClassVar

from statemachine import StateChart
from statemachine.engines.sync import SyncEngine
from statemachine.state import State
from statemachine.transition import Transition

from .chart_class import TickChartMeta
from .chart_clock import ChartClock
from .chart_data import ChartData
from .data import KIND_ATTRS, Data, check_values
from .engine import EarlyReturn, Execution
from .errors import EventDataError, TemporalLogicError, UnknownEventError
from .guards import Guard, compile_condition, compile_guard
from .plan import Plan, Resume, plan_runner
from .program import Node, Seg
from .structure import (
    ChartStructure,
    states_entered_by,
)
from .temporal import DurationSpec

#: Names an event's data may not take: python-statemachine gives the chart's guards and actions these
#: keyword arguments itself (``self`` is the callback's own), so a datum so named would clash or be
#: silently replaced.
RESERVED_EVENT_DATA = frozenset({"self", "event", "event_data", "machine", "model", "transition", "state",
                                 "source", "target"})

_NO_PLAN = object()
#: The key of the chart's own clock in ``_entered_at``: temporal logic on a junction outside every state.
_CHART_CLOCK = "<chart>"


class TickChart(ChartClock, ChartData, Execution, StateChart, metaclass=TickChartMeta):
    """Base class of a Stateflow-style chart: subclass it and declare states and data.

    Parameters
    ----------
    tick_period_s : float, optional
        Chart time per tick in seconds: the scheduler's chart period.  Needed by
        ``after_s`` and by a chart whose actions read it (``timed``); defaults to
        the class attribute ``tick_period_s``.
    chart_name : str, optional
        Name of this instance in traces and coverage; defaults to the class name.
    data : mapping, optional
        Initial values overriding the declared defaults.
    listeners : list, optional
        python-statemachine listeners (e.g. :class:`~.listeners.Trace`).
    **kwargs
        Passed to ``StateChart`` (``start_value=...`` starts the chart mid-way).
    """

    catch_errors_as_events = False  # a bug in an action raises, as in Stateflow
    # A state with only a during action and no way out (DriveInit's pass-through) is
    # normal in Stateflow; python-statemachine calls it a trap state by default.
    validate_trap_states = False
    tick_period_s: float | None = None
    #: The chart's actions read ``tick_period_s`` (a per-tick step is a per-second
    #: datum times the period): building it without a period is an error.
    timed: ClassVar[bool] = False
    #: Keep the numeric data (every datum whose default is a number or a flag) in one float buffer:
    #: compiled code reads and writes them in place (:meth:`data_buffer`, :meth:`data_slots`).
    buffered: ClassVar[bool] = False
    inputs: ClassVar[tuple[Data, ...]] = ()
    outputs: ClassVar[tuple[Data, ...]] = ()
    local: ClassVar[tuple[Data, ...]] = ()

    chart_name: str
    _ticks: int
    _entered_at: dict[str, int]
    _queue: deque[tuple[str, dict[str, Any]]]
    _plans: dict[Any, Plan]
    _plan_key: Any
    _plan: Plan | None
    _guards: dict[int, Guard | None]
    _taken: list[Transition]

    _structure: ClassVar[ChartStructure]
    _data_decls: ClassVar[tuple[Data, ...]] = ()
    _prev_pairs: ClassVar[tuple[tuple[str, str], ...]] = ()
    _dict_prev_pairs: ClassVar[tuple[tuple[str, str], ...]] = ()
    _slot_prev_pairs: ClassVar[tuple[tuple[int, int], ...]] = ()
    _slots: ClassVar[dict[str, int]] = {}
    _copy_previous: ClassVar[Any] = staticmethod(lambda d: None)  # per chart class: see _previous_copier

    def __init__(
        self,
        *,
        tick_period_s: float | None = None,
        chart_name: str | None = None,
        data: Mapping[str, Any] | None = None,
        listeners: list[object] | None = None,
        **kwargs: Any,
    ) -> None:
        d = self.__dict__
        d["_ticks"] = 0
        d["_entered_at"] = {_CHART_CLOCK: 0}
        d["_queue"] = deque()
        d["_plans"] = {}
        d["_plan_key"] = _NO_PLAN
        d["_plan"] = None
        d["_guards"] = {}
        d["_taken"] = []
        # the engine's own (docs: engine.Execution)
        d["_active"] = set()
        d["_counts"] = {}
        d["_since"] = {}
        d["_recorded"] = {}
        d["_runners"] = {}
        d["_frames"] = []
        d["_event"] = None
        d["_event_kwargs"] = {}
        d["_stepping"] = 0
        d["_depth"] = 0
        d["_cur"] = None
        d["_entered_log"] = []
        d["_entered_path"] = ((), [])
        d["_durations"] = {}
        if tick_period_s is not None:
            if not tick_period_s > 0:
                raise ValueError(f"tick_period_s must be > 0 s, got {tick_period_s!r}")
            d["tick_period_s"] = float(tick_period_s)
        elif self.timed and self.tick_period_s is None:
            raise TemporalLogicError(
                f"{type(self).__name__} needs tick_period_s=... (the scheduler's chart period):"
                " its actions turn per-second data into per-tick steps"
            )
        d["chart_name"] = chart_name or type(self).__name__
        if self._slots:
            d["_data_buffer"] = buffer = array("d", bytes(8 * len(self._slots)))
            d["_data_view"] = memoryview(buffer)
        # Data must exist before the library resolves guards that name it.
        self.reset_data()
        if data:
            check_values(type(self).__name__, self._data_decls, data, set(KIND_ATTRS))
            for name, value in data.items():
                setattr(self, name, value)
            for name, prev in self._prev_pairs:
                setattr(self, prev, getattr(self, name))
        super().__init__(listeners=list(listeners or []), **kwargs)
        # The library's engine does not start the chart (_Engine.start): the runtime enters
        # it with Stateflow's default transitions, running entry actions and listeners.
        self._activate()

    def _get_engine(self) -> SyncEngine:
        return _Engine(self)

    def add_listener(self, *listeners: Any) -> Any:
        """Attach listeners (python-statemachine's ``add_listener``); the runtime looks callbacks up again."""
        result = super().add_listener(*listeners)
        self._forget_runners()
        return result

    if TYPE_CHECKING:
        # Declared data are instance attributes made from ``inputs``/``outputs``/``local``;
        # a type checker cannot see them.  Annotate them in the chart body
        # (``X_out: float``) for precise types.
        def __getattr__(self, name: str) -> Any: ...

    if TYPE_CHECKING:
        def __setattr__(self, name: str, value: Any) -> None: ...  # declared data, as __getattr__
    else:
        # Plain assignment: a state's name is protected by its _StateName descriptor instead
        # of StateChart.__setattr__ (during actions assign outputs on every quiet tick).
        __setattr__ = object.__setattr__

    # -- the clock ---------------------------------------------------------

    def tick(self) -> Transition | None:
        """Advance the chart by one chart tick; return the first transition taken, if any.

        The chart wakes once per event posted since the last tick, in order, or
        once with no event when none was posted.
        """
        d = self.__dict__
        if d["_queue"]:
            d["_ticks"] += 1
            self._copy_previous(d)
            d["_taken"].clear()
            queue = d["_queue"]
            # only those posted before this tick: an event posted by an action waits for the next one
            for _ in range(len(queue)):
                event, data = queue.popleft()
                self._wake(event, data)
            taken = d["_taken"]
            return taken[0] if taken else None
        raw = getattr(d["model"], d["state_field"])
        plan = d["_plan"] if raw is d["_plan_key"] else self._load_plan(raw)
        try:
            k = plan.run_tick(d)  # the count and previous values, then the quiet wake-up
        except EarlyReturn:
            d["_cur"] = None
            return None
        except BaseException:
            d["_cur"] = None
            raise
        if k < 0:
            return None
        d["_cur"] = None
        d["_taken"].clear()
        self._resume(plan.resume[k])
        taken = d["_taken"]
        return taken[0] if taken else None

    def _resume(self, resume: Resume) -> None:
        """Go on with a wake-up where the plan found a transition whose guard holds."""
        chain, phase, index = resume
        d = self.__dict__
        d["_stepping"] += 1
        try:
            self._exec(chain[-1], phase, index, held=True)
            # the parallel regions after the one that took the transition still run their step
            for parent, child in zip(reversed(chain[:-1]), reversed(chain[1:]), strict=True):
                if parent.parallel and parent.id in d["_active"]:
                    self._exec_children(parent, after=child)
        finally:
            d["_stepping"] -= 1

    def send(self, event: str, *args: Any, **data: Any) -> None:  # type: ignore[override]
        """Wake the chart on `event` now; from an action, broadcast it as a local event.

        ``self.send("E")`` in an action is Stateflow's ``send(E)``: the whole chart
        handles E at once, as a nested wake-up, and the action goes on after it
        (unless the broadcast made its state inactive: early return).
        ``self.send("E", "B")`` sends it to state ``B`` and what is inside it only
        (a directed broadcast; nothing happens if B is not active).  From outside
        a tick, ``chart.send("E")`` is one wake-up on the input event E, now, that
        does not advance chart time (:meth:`post` queues it for the next tick).
        The keyword arguments are the event's data, as with :meth:`post`.
        """
        if event not in self._structure.user_events:
            raise UnknownEventError(
                f"{self.chart_name}: no transition handles event {event!r};"
                f" events: {', '.join(self._structure.user_events) or '(none)'}"
            )
        receiver = None
        if args:
            if len(args) > 1:
                raise TypeError(f"send({event!r}, state): one state to send to, got {args!r}")
            name = args[0].id if isinstance(args[0], State) else args[0]
            receiver = self._program.nodes.get(name)
            if receiver is None or not receiver.is_state:
                raise UnknownEventError(f"{self.chart_name}: send({event!r}, {name!r}): no state {name!r}")
        d = self.__dict__
        if d["_stepping"] or d["_cur"] is not None:
            if not d["_frames"] and d["_cur"] is not None:
                d["_frames"].append(("during", d["_cur"], None))
                try:
                    self._broadcast(event, receiver, data)
                finally:
                    d["_frames"].pop()
            else:
                self._broadcast(event, receiver, data)
            return
        d["_taken"].clear()
        self._wake(event, data, receiver)

    @property
    def active_ids(self) -> frozenset[str]:
        """The ids of the active states: ``configuration_values`` as a frozenset, cached per
        configuration (a tenth of its cost: wiring code asks every chart step)."""
        d = self.__dict__
        raw = getattr(d["model"], d["state_field"])
        if raw is d["_plan_key"]:
            return d["_plan"].active  # type: ignore[no-any-return]
        return self._load_plan(raw).active

    def run_ticks(self, n: int) -> int:
        """Tick ``n`` times; return how many ticks took a transition."""
        return sum(self.tick() is not None for _ in range(n))

    def post(self, event: str, /, **data: Any) -> None:
        """Queue an event from outside, with its data; it is handled at the next tick.

        The data are passed as keyword arguments to the transition's guards and actions.
        """
        if event not in self._structure.user_events:
            raise UnknownEventError(
                f"{self.chart_name}: no transition handles event {event!r};"
                f" events: {', '.join(self._structure.user_events) or '(none)'}"
            )
        check_event_data(self.chart_name, event, data)
        self._queue.append((event, data))

    def handles(self, event: str) -> bool:
        """Whether some transition of this chart is triggered by ``event``."""
        return event in self._structure.user_events

    @property
    def pending_events(self) -> list[tuple[str, dict[str, Any]]]:
        """Events posted and not yet handled, oldest first."""
        return [(e, dict(data)) for e, data in self._queue]

    def _load_plan(self, raw: Any) -> Plan:
        d = self.__dict__
        key = frozenset(raw) if isinstance(raw, MutableSet) else raw
        plan = d["_plans"].get(key)
        if plan is None:
            plan = self._build_plan()
            d["_plans"][key] = plan
        d["_plan_key"] = raw
        d["_plan"] = plan
        return plan

    def _build_plan(self) -> Plan:
        """The quiet wake-up of the active configuration, in Stateflow's order (see :mod:`.engine`)."""
        active = self.__dict__["_active"]
        steps: list[tuple[str, Any]] = []
        resume: list[Resume] = []
        if self._program.has_durations:
            steps.append(("act", (None, self._sample_durations)))

        def transitions(chain: tuple[Node, ...], segs: Sequence[Seg], phase: str) -> bool:
            for i, seg in enumerate(segs):
                if seg.events is not None:
                    continue  # only an event wakes it
                guard = self._guard_of(seg)
                steps.append(("guard", (len(resume), guard)))
                resume.append((chain, phase, i))
                if guard is None:
                    return True  # always taken: nothing after it runs
            return False

        def walk(chain: tuple[Node, ...]) -> bool:
            node = chain[-1]
            if transitions(chain, node.outer, "outer"):
                return True
            if any(seg.events is None for seg in node.actions):
                # an `on` action without an event (on after(...), on every(...)) may run at a tick
                steps.append(("act", (node, partial(self._during, node))))
            elif node.during is not None:
                steps.append(("act", (node, getattr(self, node.during))))
            if transitions(chain, node.inner, "inner"):
                return True
            for child in node.children:
                if child.id in active:
                    if walk((*chain, child)):
                        return True
                    if not node.parallel:
                        break
            return False

        for node in self._program.top:
            if node.id in active:
                walk((node,))
                break
        return Plan(frozenset(active), plan_runner(steps),
                     plan_runner(steps, self._dict_prev_pairs, self._slot_prev_pairs), resume)

    def _guard_of(self, seg: Seg) -> Guard | None:
        guards = self.__dict__["_guards"]
        t = seg.transition
        if id(t) not in guards:
            guards[id(t)] = self._compile_guard(seg)
        return guards[id(t)]

    def _compile_guard(self, seg: Seg) -> Guard | None:
        return compile_guard(self, seg.transition, _clock_of(seg))[0]

    def _duration_condition(self, node: Node, spec: DurationSpec) -> Guard:
        conds = self.__dict__["_durations"]
        fn = conds.get(spec)
        if fn is None:
            fn = conds[spec] = compile_condition(self, spec.condition, node.state)
        return fn  # type: ignore[no-any-return]

    def guard_paths(self) -> dict[str, str]:
        """For each tick transition, whether its guard runs as a plain call (``fast``) or
        through the library (``library``): a chart author checks the fast path is used."""
        segs = self._program.segs
        return {
            info.label: "fast" if compile_guard(self, info.transition, _clock_of(segs[id(info.transition)]))[1]
            else "library"
            for info in self._structure.transitions if info.scope != "action" and id(info.transition) in segs
        }



if TYPE_CHECKING:  # to the type checker, a class of actions is the chart it is mixed into (its data, helpers)
    ChartActions = TickChart
else:
    class ChartActions:
        """Base of a class of a chart's actions kept in a module of their own and mixed into the chart class
        (``class Control(PenMoves, XDrawing, ..., TickChart)``): at run time a plain class whose methods the
        chart inherits; to a type checker the chart itself, so the actions read and write its data."""


def _clock_of(seg: Seg) -> str:
    """The state whose clock a segment's temporal guards read (the chart's own at the top level)."""
    return seg.clock.id if seg.clock is not None else _CHART_CLOCK


class _Engine(SyncEngine):
    """python-statemachine's engine, with the execution handed to the runtime.

    It does not start the chart (the runtime enters it with Stateflow's default
    transitions) and it hands every event sent through the library's API
    (``chart.some_event()``, ``StateChart.send``) to the chart as a wake-up.
    """

    def start(self, **kwargs: Any) -> None:
        return None

    def processing_loop(self) -> Any:
        sm: Any = self.sm
        while not self.external_queue.is_empty():
            trigger = self.external_queue.pop()
            sm.send(str(trigger.event), **trigger.kwargs)
        return None


def entered_states(chart: StateChart, transition: Transition) -> list[State]:
    """Alias of :func:`.structure.states_entered_by`, for listeners written by users."""
    return states_entered_by(chart, transition)


def check_event_data(chart: str, event: str, data: Mapping[str, Any]) -> None:
    """Refuse event data a chart's callbacks cannot take: names of :data:`RESERVED_EVENT_DATA`, or not
    identifiers (:class:`~.errors.EventDataError`, one line)."""
    for name in data:
        if not (isinstance(name, str) and name.isidentifier()):
            raise EventDataError(f"{chart}: the data of event {event!r} must be named by identifiers, got {name!r}")
        if name in RESERVED_EVENT_DATA:
            raise EventDataError(f"{chart}: event {event!r} may not carry a datum named {name!r}: python-statemachine"
                                 f" gives the chart's guards and actions {', '.join(sorted(RESERVED_EVENT_DATA))}"
                                 " itself; choose another name")
