"""Listeners that watch charts: a :class:`Trace` of transitions and a :class:`Coverage` report.

Both are python-statemachine listeners: attach them with ``listeners=[...]`` when
building a chart, ``chart.add_listener(...)``, or their ``observe(*charts)``
method, which also records the states active at that moment.  They hook
``after_transition`` (called once per transition taken, with the configuration
already updated), not ``on_enter_state``: a generic hook on states would show on
every state of the library's own instance diagrams.
"""

from __future__ import annotations

import json
from collections import deque
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import IO, Any, overload

from statemachine import StateChart
from statemachine.transition import Transition

from ..files import write_atomic
from .jsonable import dumps, jsonable
from .structure import TICK_EVENT_NAME, TICK_EVENT_PREFIX, build_structure, states_entered_by


def _chart_name(machine: StateChart) -> str:
    return str(getattr(machine, "chart_name", type(machine).__name__))


def _structure_of(machine: StateChart | type[StateChart]) -> Any:
    cls = machine if isinstance(machine, type) else type(machine)
    structure = getattr(cls, "_structure", None)
    return structure if structure is not None else build_structure(cls)


@dataclass(frozen=True)
class TraceRecord:
    """One transition taken by a chart.

    ``trigger`` is ``"tick"`` for a tick transition, else the event's name;
    ``data`` is the chart's declared data just after the transition, and
    ``event_args`` the data the event carried.
    """

    tick: int | None
    time_s: float | None
    chart: str
    source: str
    target: str | None
    trigger: str
    data: dict[str, Any] = field(default_factory=dict)
    event_args: dict[str, Any] = field(default_factory=dict)

    def to_json(self) -> str:
        return dumps(asdict(self), sort_keys=True)

    @classmethod
    def from_json(cls, line: str) -> TraceRecord:
        return cls(**json.loads(line))


class KeptRecords(Sequence[TraceRecord]):
    """The newest ``limit`` records of a trace, oldest first: a ring buffer a list compares equal to."""

    def __init__(self, limit: int) -> None:
        if limit < 1:
            raise ValueError(f"a trace keeps at least one record, not {limit}")
        self._items: deque[TraceRecord] = deque(maxlen=limit)

    @property
    def limit(self) -> int:
        assert self._items.maxlen is not None
        return self._items.maxlen

    def append(self, record: TraceRecord) -> None:
        self._items.append(record)

    def clear(self) -> None:
        self._items.clear()

    def __len__(self) -> int:
        return len(self._items)

    def __iter__(self) -> Iterator[TraceRecord]:
        return iter(self._items)

    @overload
    def __getitem__(self, index: int) -> TraceRecord: ...

    @overload
    def __getitem__(self, index: slice) -> list[TraceRecord]: ...

    def __getitem__(self, index: int | slice) -> TraceRecord | list[TraceRecord]:
        if isinstance(index, slice):
            return list(self._items)[index]
        return self._items[index]

    def __eq__(self, other: object) -> bool:
        if isinstance(other, (list, tuple, KeptRecords)):
            return list(self._items) == list(other)
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]


class Trace:
    """Records every transition of the charts it observes; writes JSON Lines.

    Parameters
    ----------
    sink : text stream, optional
        If given, each record is also written to it as one JSON line when it
        happens, and flushed, so a long run keeps its whole trace on disk
        (a :class:`~.recordfile.RecordFile`) without holding it in memory.
        A write that fails (the disk full) raises from the chart's step,
        which ends a run; with ``keep_going`` the sink is let go instead:
        the charts run on, :attr:`sink_error` says why, the records are kept
        in memory still (the debugger's and the cockpit's sessions).
    keep : bool
        Keep the records in :attr:`records`.
    limit : int, optional
        Keep only the newest ``limit`` records (a ring buffer); :attr:`count`
        still counts them all.  None: keep every record.
    """

    def __init__(self, sink: IO[str] | Any | None = None, keep: bool = True, limit: int | None = None,
                 keep_going: bool = False) -> None:
        self.records: list[TraceRecord] | KeptRecords = [] if limit is None else KeptRecords(limit)
        self.sink = sink
        self.keep = keep
        #: Every record this trace has seen, kept or not.
        self.count = 0
        #: Why the sink was let go (an ``OSError`` writing it: the disk full), or None.
        self.sink_error: OSError | None = None
        self.keep_going = keep_going

    @property
    def dropped(self) -> int:
        """Records seen but no longer kept (the ring buffer's oldest)."""
        return self.count - len(self.records) if self.keep else self.count

    def since(self, count: int) -> list[TraceRecord]:
        """The records seen after the first ``count`` ones (as :attr:`count` was), those still kept."""
        new = self.count - count
        if new <= 0 or not self.keep:
            return []
        return list(self.records[-new:]) if new < len(self.records) else list(self.records)

    def observe(self, *charts: StateChart) -> Trace:
        """Attach to charts already built."""
        for chart in charts:
            chart.add_listener(self)
        return self

    def after_transition(self, machine: StateChart, transition: Transition, event: Any,
                         event_data: Any = None) -> None:
        event_id = str(event) if event is not None else ""
        trigger = TICK_EVENT_NAME if event_id.startswith(TICK_EVENT_PREFIX) else event_id
        snapshot = getattr(machine, "snapshot", None)
        kwargs = event_data.trigger_data.kwargs if event_data is not None else {}
        record = TraceRecord(
            tick=getattr(machine, "tick_count", None),
            time_s=getattr(machine, "time_s", None),
            chart=_chart_name(machine),
            source=transition.source.id,
            target=transition.target.id if transition.target is not None else None,
            trigger=trigger,
            data=jsonable(snapshot()) if callable(snapshot) else {},
            event_args=jsonable(dict(kwargs)),
        )
        self.count += 1
        if self.keep:
            self.records.append(record)
        if self.sink is not None:
            try:
                self.sink.write(record.to_json() + "\n")
                self.sink.flush()
            except OSError as exc:
                self.sink_error, self.sink = exc, None
                if not self.keep_going:
                    raise

    def write_jsonl(self, path: str | Path) -> Path:
        """Write the kept records to ``path``, one JSON object per line: the whole file or, if the disk
        refuses it, the file as it was (:func:`~.files.write_atomic`)."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        return write_atomic(path, "".join(record.to_json() + "\n" for record in self.records))

    @staticmethod
    def read_jsonl(path: str | Path) -> list[TraceRecord]:
        """Read records written by :meth:`write_jsonl` or a ``sink``.

        Lines with an ``event`` (the record's head, a replay mark, its ending:
        :mod:`.recordfile`) are not transitions and are passed over.
        """
        with Path(path).open(encoding="utf-8") as f:
            rows = [json.loads(line) for line in f if line.strip()]
        return [TraceRecord(**row) for row in rows if "event" not in row]


@dataclass(frozen=True)
class ChartCoverage:
    """Coverage of one chart class: what was entered/taken and what never was."""

    chart: str
    states: tuple[str, ...]
    entered: tuple[str, ...]
    transitions: tuple[str, ...]
    taken: tuple[str, ...]

    @property
    def missing_states(self) -> tuple[str, ...]:
        return tuple(s for s in self.states if s not in self.entered)

    @property
    def missing_transitions(self) -> tuple[str, ...]:
        return tuple(t for t in self.transitions if t not in self.taken)

    @property
    def complete(self) -> bool:
        return not self.missing_states and not self.missing_transitions


@dataclass(frozen=True)
class CoverageReport:
    """Coverage of every observed chart class."""

    charts: tuple[ChartCoverage, ...]

    @property
    def complete(self) -> bool:
        return all(c.complete for c in self.charts)

    def to_dict(self) -> dict[str, Any]:
        return {
            c.chart: {
                "states": f"{len(c.entered)}/{len(c.states)}",
                "transitions": f"{len(c.taken)}/{len(c.transitions)}",
                "missing_states": list(c.missing_states),
                "missing_transitions": list(c.missing_transitions),
            }
            for c in self.charts
        }

    def to_text(self) -> str:
        lines: list[str] = []
        for c in self.charts:
            lines.append(f"{c.chart}: states {len(c.entered)}/{len(c.states)},"
                         f" transitions {len(c.taken)}/{len(c.transitions)}")
            lines += [f"  never entered: {s}" for s in c.missing_states]
            lines += [f"  never taken:   {t}" for t in c.missing_transitions]
        return "\n".join(lines) + "\n"


class Coverage:
    """Records, per chart class, the states entered and the transitions taken.

    Instances of the same class add up.  Transitions are named by their stable
    label (``"off -> on: tick [sw]"``), the same as in the diagrams' tables.
    """

    def __init__(self) -> None:
        self._entered: dict[str, set[str]] = {}
        self._taken: dict[str, set[str]] = {}
        self._classes: dict[str, type[StateChart]] = {}

    def observe(self, *charts: StateChart) -> Coverage:
        """Attach to charts already built and count their active states as entered."""
        for chart in charts:
            chart.add_listener(self)
            self._register(chart)
            self._entered[type(chart).__name__].update(s.id for s in chart.configuration)
        return self

    def include(self, *chart_classes: type[StateChart]) -> Coverage:
        """List chart classes in the report even if no instance was observed."""
        for cls in chart_classes:
            self._classes.setdefault(cls.__name__, cls)
            self._entered.setdefault(cls.__name__, set())
            self._taken.setdefault(cls.__name__, set())
        return self

    def _register(self, chart: StateChart) -> str:
        self.include(type(chart))
        return type(chart).__name__

    def after_transition(self, machine: StateChart, transition: Transition) -> None:
        name = self._register(machine)
        info = _structure_of(machine).by_transition.get(id(transition))
        if info is not None:
            self._taken[name].add(info.label)
        self._entered[name].update(s.id for s in states_entered_by(machine, transition))

    def report(self) -> CoverageReport:
        charts = []
        for name in sorted(self._classes):
            structure = _structure_of(self._classes[name])
            states = tuple(s.id for s in structure.states if not s.history)
            transitions = tuple(t.label for t in structure.transitions)
            charts.append(ChartCoverage(
                chart=name,
                states=states,
                entered=tuple(s for s in states if s in self._entered[name]),
                transitions=transitions,
                taken=tuple(t for t in transitions if t in self._taken[name]),
            ))
        return CoverageReport(tuple(charts))


def attach(listener: Any, charts: Iterable[StateChart]) -> None:
    """Add one listener to several charts."""
    for chart in charts:
        chart.add_listener(listener)
