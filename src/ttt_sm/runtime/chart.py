"""TickChart: a python-statemachine ``StateChart`` with Stateflow's clock.

A chart is written like any python-statemachine chart — states as attributes,
``source.to(target, cond=..., on=...)``, callbacks by name — and reads like its
diagram.  Two kinds of transition:

* **tick transitions**: written without an event (``off.to(on, cond="switch")``).
  Stateflow's eventless transitions: tried on every chart tick, guard only.
* **event transitions**: assigned to an event name (``button = off.to(on)``),
  taken when that event, posted from outside with :meth:`TickChart.post`, is
  handled at the next tick.

One :meth:`TickChart.tick`:

1. outputs are copied to ``<name>_p`` (their value one chart tick earlier; the
   copies are straight-line code made per chart class);
2. the events posted since the last tick are sent to the library, in order;
3. the tick transitions of the active states are tried in Stateflow order
   (outermost state first; within a state, outer transitions then inner ones,
   each in declaration order).  The first whose guard holds is taken through the
   library — exit actions, transition action, entry actions, listeners — and the
   tick ends: at most one tick transition per tick;
4. if none was taken, the during actions (``during_<state>`` methods) of the
   active states run, outermost first.

A quiet tick (step 4) never calls ``send()``: guards are compiled to plain calls
and cached per active configuration (see :mod:`.guards`).
"""

from __future__ import annotations

from array import array
from collections import deque
from collections.abc import Callable, Iterator, Mapping, MutableMapping, MutableSet, Sequence
from typing import TYPE_CHECKING, Any, ClassVar

from statemachine import StateChart
from statemachine.exceptions import StateMachineError
from statemachine.factory import StateMachineMetaclass
from statemachine.state import State
from statemachine.transition import Transition

from .data import KIND_ATTRS, PREVIOUS_SUFFIX, Data, buffers, check_values, collect_declarations, make_slot
from .errors import ChartDefinitionError, GuardMismatchError, TemporalLogicError, UnknownEventError
from .guards import Guard, compile_guard
from .structure import (
    DURING_PREFIX,
    ChartStructure,
    build_structure,
    states_entered_by,
    tag_tick_transitions,
)
from .temporal import temporal_of

_NO_PLAN = object()
# What a tick does in one configuration: the tick transitions to try (in order),
# the during actions, the active state ids, both run as one function (_plan_runner), and
# the whole quiet-queue tick as one function: the count, the previous values, then both.
_Plan = tuple[tuple[tuple[Guard | None, str, Transition], ...], tuple[Callable[[], Any], ...], frozenset[str],
              Callable[[], int], Callable[[dict[str, Any]], int]]


def _plan_runner(candidates: Sequence[tuple[Guard | None, str, Transition]],
                 durings: Sequence[Callable[[], Any]],
                 prev_pairs: Sequence[tuple[str, str]] | None = None,
                 slot_pairs: Sequence[tuple[int, int]] = ()) -> Callable[..., int]:
    """The tick of one configuration as straight-line code: the index of the first candidate whose guard
    holds, or -1 once every guard failed and the during actions ran.

    ``if g0(): return 0 ... d0(); return -1``: a loop over the candidates and the
    durings costs about a third more, and it runs on every tick of every chart.
    A candidate without a guard is taken unconditionally (nothing after it runs).

    With ``prev_pairs`` the function takes the chart's ``__dict__`` and first does
    steps 1 of a tick (see the module docstring) as well: counts the tick and copies
    every output to its previous value.  That is the whole tick when no event is
    queued, one call instead of three (the tick count, the copy and the guards).
    ``slot_pairs`` are the (output, previous) places of a buffered chart's outputs in its buffer;
    ``prev_pairs`` then names only the outputs kept as plain attributes.
    """
    lines, bound = [], {}
    if prev_pairs is not None:
        lines.append("    d['_ticks'] += 1")
        lines += _copy_lines(prev_pairs, slot_pairs)
    for k, (guard, _event, _transition) in enumerate(candidates):
        if guard is None:
            lines.append(f"    return {k}")
            break
        bound[f"g{k}"] = guard
        lines += [f"    if g{k}():", f"        return {k}"]
    else:
        for k, during in enumerate(durings):
            bound[f"d{k}"] = during
            lines.append(f"    d{k}()")
        lines.append("    return -1")
    args = ", ".join(["d"] * (prev_pairs is not None) + [f"{name}={name}" for name in bound])
    namespace: dict[str, Any] = dict(bound)
    exec(compile(f"def run_plan({args}):\n" + "\n".join(lines) + "\n", "<tick plan>", "exec"),  # noqa: S102
         namespace)
    return namespace["run_plan"]  # type: ignore[no-any-return]


class TickChartMeta(StateMachineMetaclass):
    """Builds the library's chart, then tags tick transitions and reads data and structure."""

    def __init__(cls, name: str, bases: tuple[type], attrs: dict[str, Any]) -> None:
        super().__init__(name, bases, attrs)
        if not cls.states:  # the abstract TickChart itself
            return
        tag_tick_transitions(cls)  # type: ignore[arg-type]
        structure = build_structure(cls)  # type: ignore[arg-type]
        decls = collect_declarations(cls)
        _check_during_names(cls, structure)
        _check_temporal_guards(cls, structure)
        cls._structure = structure
        events = getattr(cls, "_events", {})
        for state in structure.states:
            # (a state named like an event is reached through the event, as in the library)
            if state.id not in events and not isinstance(cls.__dict__.get(state.id), _StateName):
                setattr(cls, state.id, _StateName(state.id, getattr(cls, state.id, state)))
        cls._data_decls = decls
        cls._prev_pairs = tuple(
            (d.name, d.name + PREVIOUS_SUFFIX) for d in decls if d.kind == "output"
        )
        slots: dict[str, int] = {}
        if cls.buffered:  # type: ignore[attr-defined]
            for decl in decls:
                if buffers(decl):
                    names = [decl.name] + [decl.name + PREVIOUS_SUFFIX] * (decl.kind == "output")
                    for datum in names:
                        slots[datum] = len(slots)
                        setattr(cls, datum, make_slot(decl, slots[datum], name, datum))
        cls._slots = slots
        cls._slot_prev_pairs = tuple((slots[o], slots[p]) for o, p in cls._prev_pairs if o in slots)
        cls._dict_prev_pairs = tuple((o, p) for o, p in cls._prev_pairs if o not in slots)
        cls._copy_previous = staticmethod(_previous_copier(name, cls._dict_prev_pairs, cls._slot_prev_pairs))


def _copy_lines(pairs: Sequence[tuple[str, str]], slot_pairs: Sequence[tuple[int, int]]) -> list[str]:
    """``X_p = X`` as lines of code: plain attributes by name, a buffered chart's numbers by place."""
    lines = [f"    d[{prev!r}] = d[{out!r}]" for out, prev in pairs]
    if slot_pairs:
        lines.append("    b = d['_data_view']")
        lines += [f"    b[{prev}] = b[{out}]" for out, prev in slot_pairs]
    return lines


def _previous_copier(name: str, pairs: tuple[tuple[str, str], ...],
                     slot_pairs: tuple[tuple[int, int], ...] = ()) -> Callable[[dict[str, Any]], None]:
    """``X_p = X`` for every output of a chart class, as straight-line code.

    It runs at the start of every tick of every chart; a loop over the pairs
    costs about a third more per output.  The names are checked identifiers.
    """
    body = "".join(line + "\n" for line in _copy_lines(pairs, slot_pairs)) or "    pass\n"
    namespace: dict[str, Any] = {}
    exec(compile("def copy_previous(d):\n" + body, f"<{name}.copy_previous>", "exec"), namespace)  # noqa: S102
    return namespace["copy_previous"]  # type: ignore[no-any-return]


def _check_during_names(cls: type, structure: ChartStructure) -> None:
    state_ids = {s.id for s in structure.states}
    for attr in dir(cls):
        if attr.startswith(DURING_PREFIX) and callable(getattr(cls, attr, None)):
            if attr[len(DURING_PREFIX):] not in state_ids:
                raise ChartDefinitionError(
                    f"{cls.__name__}.{attr}: no state {attr[len(DURING_PREFIX):]!r} to run it in;"
                    f" states: {', '.join(sorted(state_ids))}"
                )


def _check_temporal_guards(cls: type, structure: ChartStructure) -> None:
    for info in structure.transitions:
        if info.kind == "event":
            for spec in info.transition.cond:
                if temporal_of(spec.func) is not None:
                    raise ChartDefinitionError(
                        f"{cls.__name__}: {info.label}: temporal guards belong on tick transitions"
                        " (written without an event); an event transition is only tried when"
                        " its event arrives"
                    )


class _StateName:
    """A chart class's attribute named after a state: reads as the state, refuses assignment.

    python-statemachine refuses ``chart.some_state = value`` in a Python-level
    ``__setattr__``, which every attribute assignment then pays for (0.4 us:
    during actions assign outputs on every tick).  A data descriptor per state
    name gives the same protection and leaves every other assignment plain.
    """

    __slots__ = ("name", "state")

    def __init__(self, name: str, state: Any) -> None:
        self.name = name
        self.state = state

    def __get__(self, instance: Any, owner: type | None = None) -> Any:
        if instance is None:
            return self.state
        # the library keeps each instance's own copy of the state in its __dict__
        return instance.__dict__.get(self.name, self.state)

    def __set__(self, instance: Any, value: Any) -> None:
        raise StateMachineError(
            f"State overriding is not allowed. Trying to add {value!r} to {self.name}")


class _Clock:
    """Internal listener: records when states are (re-)entered and which transitions ran.

    It uses ``after_transition`` rather than ``on_enter_state`` so that the
    library's own instance diagrams do not list a hook on every state.
    """

    def __init__(self, chart: TickChart) -> None:
        self.chart = chart

    def after_transition(self, transition: Transition) -> None:
        chart = self.chart
        now = chart._ticks
        entered_at = chart._entered_at
        for state in states_entered_by(chart, transition):
            entered_at[state.id] = now
        if chart._recording:
            chart._taken.append(transition)


class TickChart(StateChart, metaclass=TickChartMeta):
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
    _plans: dict[Any, _Plan]
    _plan_key: Any
    _plan: _Plan | None
    _guards: dict[int, Guard | None]
    _taken: list[Transition]
    _recording: bool

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
        d["_entered_at"] = {}
        d["_queue"] = deque()
        d["_plans"] = {}
        d["_plan_key"] = _NO_PLAN
        d["_plan"] = None
        d["_guards"] = {}
        d["_taken"] = []
        d["_recording"] = False
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
        super().__init__(listeners=[_Clock(self), *(listeners or [])], **kwargs)
        for state in self.configuration:
            self._entered_at[state.id] = 0

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
        """Advance the chart by one chart tick; return the tick transition taken, if any."""
        d = self.__dict__
        if d["_queue"]:
            d["_ticks"] += 1
            self._copy_previous(d)
            self._handle_posted_events()  # they may change the configuration
            raw = getattr(d["model"], d["state_field"])
            plan = d["_plan"] if raw is d["_plan_key"] else self._load_plan(raw)
            k = plan[3]()  # the guards in order, then the durings if none held
        else:
            raw = getattr(d["model"], d["state_field"])
            plan = d["_plan"] if raw is d["_plan_key"] else self._load_plan(raw)
            k = plan[4](d)  # the count and previous values, then as plan[3]
        if k < 0:
            return None
        _, event, transition = plan[0][k]
        self._take(event, transition)
        return transition

    @property
    def active_ids(self) -> frozenset[str]:
        """The ids of the active states: ``configuration_values`` as a frozenset, cached per
        configuration (a tenth of its cost: wiring code asks every chart step)."""
        d = self.__dict__
        raw = getattr(d["model"], d["state_field"])
        if raw is d["_plan_key"]:
            return d["_plan"][2]
        return self._load_plan(raw)[2]

    def run_ticks(self, n: int) -> int:
        """Tick ``n`` times; return how many tick transitions were taken."""
        return sum(self.tick() is not None for _ in range(n))

    def post(self, event: str, **data: Any) -> None:
        """Queue an event from outside, with its data; it is handled at the next tick.

        The data are passed as keyword arguments to the transition's guards and actions.
        """
        if event not in self._structure.user_events:
            raise UnknownEventError(
                f"{self.chart_name}: no transition handles event {event!r};"
                f" events: {', '.join(self._structure.user_events) or '(none)'}"
            )
        self._queue.append((event, data))

    def handles(self, event: str) -> bool:
        """Whether some transition of this chart is triggered by ``event``."""
        return event in self._structure.user_events

    @property
    def pending_events(self) -> list[tuple[str, dict[str, Any]]]:
        """Events posted and not yet handled, oldest first."""
        return [(e, dict(data)) for e, data in self._queue]

    @property
    def tick_count(self) -> int:
        """Chart ticks since construction (or since :meth:`start_clock_at`'s tick)."""
        return self._ticks

    def start_clock_at(self, tick: int) -> None:
        """Count this chart's ticks from ``tick``: a chart that takes another's place mid-run keeps
        the run's clock (its trace and timeline go on where the other's stopped).  Before its first tick only."""
        d = self.__dict__
        if d["_ticks"]:
            raise TemporalLogicError(f"{self.chart_name}: its clock has run {d['_ticks']} ticks already;"
                                     " start_clock_at is for a chart not yet ticked")
        d["_ticks"] = int(tick)
        for state in d["_entered_at"]:
            d["_entered_at"][state] = int(tick)

    @property
    def time_s(self) -> float | None:
        """Chart time: ticks times the tick period (``None`` without a period)."""
        period = self.tick_period_s
        return None if period is None else self._ticks * period

    def ticks_in(self, state: State | str) -> int:
        """Ticks since ``state`` was last entered (0 during the tick that entered it)."""
        state_id = state if isinstance(state, str) else state.id
        return self._ticks - self._entered_at[state_id]

    def _handle_posted_events(self) -> None:
        queue = self._queue
        # Only those posted before this tick: an action that posts waits for the next one.
        for _ in range(len(queue)):
            event, data = queue.popleft()
            self.send(event, **data)

    def _take(self, event: str, transition: Transition) -> None:
        d = self.__dict__
        taken = d["_taken"]
        taken.clear()
        d["_recording"] = True
        try:
            self.send(event)
        finally:
            d["_recording"] = False
        if transition not in taken:
            info = self._structure.info(transition)
            raise GuardMismatchError(
                f"{self.chart_name}: the guard of '{info.label}' held on the fast path but"
                " python-statemachine did not take the transition; guards must be pure"
                " functions of the chart's inputs and data (no side effects, no event data)"
            )

    def _load_plan(self, raw: Any) -> _Plan:
        d = self.__dict__
        key = frozenset(raw) if isinstance(raw, MutableSet) else raw
        plan = d["_plans"].get(key)
        if plan is None:
            plan = self._build_plan()
            d["_plans"][key] = plan
        d["_plan_key"] = raw
        d["_plan"] = plan
        return plan

    def _build_plan(self) -> _Plan:
        active = set(self.configuration_values)
        guards = self._guards
        candidates: list[tuple[Guard | None, str, Transition]] = []
        durings: list[Callable[[], Any]] = []
        for state in self._structure.states:
            if state.id not in active:
                continue
            for info in self._structure.tick_by_state[state.id]:
                t = info.transition
                if id(t) not in guards:
                    guards[id(t)] = compile_guard(self, t)[0]
                assert info.tick_event is not None
                candidates.append((guards[id(t)], info.tick_event, t))
            for name in state.during:
                durings.append(getattr(self, name))
        return (tuple(candidates), tuple(durings), frozenset(active), _plan_runner(candidates, durings),
                _plan_runner(candidates, durings, self._dict_prev_pairs, self._slot_prev_pairs))

    def guard_paths(self) -> dict[str, str]:
        """For each tick transition, whether its guard runs as a plain call (``fast``) or
        through the library (``library``): a chart author checks the fast path is used."""
        return {
            info.label: "fast" if compile_guard(self, info.transition)[1] else "library"
            for info in self._structure.transitions if info.kind == "tick"
        }

    # -- data ----------------------------------------------------------------

    @classmethod
    def declarations(cls) -> tuple[Data, ...]:
        """The chart's inputs, outputs and local data, in declaration order."""
        return cls._data_decls

    @classmethod
    def structure(cls) -> ChartStructure:
        """States and transitions of the chart, as diagrams and coverage read them."""
        return cls._structure

    def snapshot(self, kinds: tuple[str, ...] = ("input", "output", "local")) -> dict[str, Any]:
        """Current values of the declared data of the given kinds, by name."""
        d = self.data_mapping()
        return {decl.name: d[decl.name] for decl in self._data_decls if decl.kind in kinds}

    def previous_outputs(self) -> dict[str, Any]:
        """Each output's value one chart tick earlier, by output name."""
        d = self.data_mapping()
        return {name: d[prev] for name, prev in self._prev_pairs}

    def set_inputs(self, **values: Any) -> None:
        """Set inputs by name; an unknown name raises :class:`UnknownDataError`."""
        check_values(type(self).__name__, self._data_decls, values, {"input"})
        self.data_mapping().update(values)

    def reset_data(self, kinds: tuple[str, ...] = ("input", "output", "local")) -> None:
        """Put the declared data of the given kinds back to their defaults."""
        for decl in self._data_decls:
            if decl.kind in kinds:
                setattr(self, decl.name, decl.fresh_default())
                if decl.kind == "output":
                    setattr(self, decl.name + PREVIOUS_SUFFIX, decl.fresh_default())

    def data_mapping(self) -> MutableMapping[str, Any]:
        """The chart's data (and each output's previous value) as a mapping by name, read and written live.

        The instance's ``__dict__`` itself, where the data are plain attributes; for a
        buffered chart, a view that reads and writes its buffer's numbers by name.
        """
        return self.__dict__ if not self._slots else _BufferedData(self)

    def data_buffer(self) -> array:
        """A buffered chart's float buffer (``array('d')``): :meth:`data_slots` says which datum is where.

        Compiled code wraps it without a copy (``numpy.frombuffer``) and reads and writes
        the chart's numbers in place; a flag is 1.0 or 0.0.
        """
        if not self._slots:
            raise TypeError(f"{self.chart_name}: the chart is not buffered (buffered = True keeps its"
                            " numbers in one buffer)")
        return self.__dict__["_data_buffer"]  # type: ignore[no-any-return]

    @classmethod
    def data_slots(cls) -> dict[str, int]:
        """Where each number of a buffered chart lies in :meth:`data_buffer`, by datum (``X_p`` too)."""
        return dict(cls._slots)


def entered_states(chart: StateChart, transition: Transition) -> list[State]:
    """Alias of :func:`.structure.states_entered_by`, for listeners written by users."""
    return states_entered_by(chart, transition)


class _BufferedData(MutableMapping[str, Any]):
    """A buffered chart's data as a mapping: a number by its slot, anything else in the instance dict."""

    __slots__ = ("_chart", "_d")

    def __init__(self, chart: TickChart) -> None:
        self._chart = chart
        self._d = chart.__dict__

    def __getitem__(self, name: str) -> Any:
        if name in self._chart._slots:
            return getattr(self._chart, name)
        return self._d[name]

    def __setitem__(self, name: str, value: Any) -> None:
        if name in self._chart._slots:
            setattr(self._chart, name, value)
        else:
            self._d[name] = value

    def __delitem__(self, name: str) -> None:
        raise TypeError(f"{self._chart.chart_name}: a chart's data cannot be deleted ({name})")

    def __contains__(self, name: object) -> bool:
        return name in self._chart._slots or name in self._d

    def __iter__(self) -> Iterator[str]:
        yield from self._chart._slots
        yield from (k for k in self._d if k not in self._chart._slots)

    def __len__(self) -> int:
        return len(self._chart._slots) + sum(k not in self._chart._slots for k in self._d)
