"""A path of input steps, run on one bare chart from power-on: what the search of :mod:`.explore` extends.

A :class:`Step` sets some inputs, maybe posts an event, then ticks the chart
until it takes a transition (or what the guards read stood still for
:data:`STILL_TICKS` chart steps); :class:`Sim` runs the chart alone, as
bare-chart mode does (docs/scenarios.md, "Bare-chart mode"), and notes what
each step did.  A chart cannot be copied, so a path is replayed from
power-on each time it is extended (:meth:`Sim.replay`); that is exact, and it
is what the generated scenario file does too.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

from ..runtime import TickChart
from .model import chart_states
from .runner import StateLog

#: A step that takes no transition ends once what the guards read stood still this many chart steps.
STILL_TICKS = 512


@dataclass(frozen=True)
class Step:
    """One step of a path: inputs set, an event posted, then ``ticks`` chart steps.

    ``why`` says where each input value came from; ``taken`` (the labels of the
    transitions the step took), ``active`` (the leaf states after it) and
    ``outputs`` (the outputs it changed, and the local data other than measured
    quantities, with their new values) are what running it did.
    """

    sets: tuple[tuple[str, Any], ...] = ()
    events: tuple[str, ...] = ()
    ticks: int = 0
    why: tuple[str, ...] = ()
    taken: tuple[str, ...] = ()
    active: tuple[str, ...] = ()
    outputs: tuple[tuple[str, Any], ...] = ()
    entered: tuple[str, ...] = ()  #: the leaf states it entered, in order


@dataclass
class Sim:
    """One bare chart, run from power-on through steps."""

    cls: type[TickChart]
    dt: float
    chart: TickChart = field(init=False)
    log: StateLog = field(init=False)
    taken: list[str] = field(init=False, default_factory=list)
    _log_start: int = field(init=False, default=0)

    def __post_init__(self) -> None:
        self.log = StateLog()
        labels = self.cls.structure().by_transition

        class Taken:
            @staticmethod
            def after_transition(machine: TickChart, transition: Any) -> None:
                info = labels.get(id(transition))
                if info is not None:
                    self.taken.append(info.label)

        self.chart = self.cls(tick_period_s=self.dt, chart_name=self.cls.__name__, listeners=[self.log, Taken()])
        self.log.record_initial([self.chart])

    def replay(self, path: Iterable[Step]) -> Sim:
        for step in path:
            self._start(step)
            for _ in range(step.ticks):
                self.chart.tick()
        return self

    def _start(self, step: Step) -> None:
        if step.sets:
            self.chart.set_inputs(**dict(step.sets))
        for event in step.events:
            self.chart.post(event)

    def run(self, step: Step, max_ticks: int, clock: float, watch: Sequence[str] = ()) -> Step | None:
        """Run a new step: tick until a transition is taken; None if none is within ``max_ticks``.

        Past ``clock`` ticks (when the temporal operators of the active states change no more) a step
        also ends without a transition once the data its guards read (``watch``; all data if empty)
        stood still for :data:`STILL_TICKS` chart steps: waiting longer would change nothing they see.
        """
        before = self.chart.snapshot(("output", "local"))
        self._start(step)
        start = len(self.taken)
        self._log_start = len(self.log.entries[self.cls.__name__])
        data = self.chart.data_mapping()
        names = tuple(watch) or tuple(data)
        previous: tuple[Any, ...] | None = None
        still_since = 0
        for n in range(1, max_ticks + 1):
            self.chart.tick()
            if len(self.taken) > start:
                return self._done(step, n, start, before)
            if n > clock and n % 64 == 0:
                now = tuple("nan" if isinstance(v, float) and math.isnan(v) else v
                            for v in map(data.__getitem__, names))
                if now != previous:
                    previous, still_since = now, n
                elif n - still_since >= STILL_TICKS:
                    return None
        return None

    def hold(self, step: Step) -> Step:
        """A step that only sets inputs: no chart step runs (what a later step needs may be more)."""
        before = self.chart.snapshot(("output", "local"))
        self._log_start = len(self.log.entries[self.cls.__name__])
        self._start(step)
        return self._done(step, 0, len(self.taken), before)

    def _done(self, step: Step, ticks: int, start: int, before: dict[str, Any]) -> Step:
        kinds = chart_states(self.cls)
        outputs = {d.name for d in self.cls.declarations() if d.kind == "output"}
        after = self.chart.snapshot(("output", "local"))
        # what a step is checked by: the outputs it changed, and the counters and flags of its own data
        changed = tuple((k, v) for k, v in after.items() if not same_value(v, before.get(k))
                        and (k in outputs or not isinstance(v, float)))
        leaves = tuple(s for s in self.chart.configuration_values if kinds.get(s) == "leaf")
        entered = tuple(e.state for e in self.log.entries[self.cls.__name__][self._log_start:]
                        if kinds.get(e.state) == "leaf")
        return Step(step.sets, step.events, ticks, step.why, tuple(dict.fromkeys(self.taken[start:])),
                    leaves, changed, entered)

    def leaf_sequence(self) -> list[str]:
        """The leaf states entered since power-on, as ``expect_states`` with ``match: exact`` sees them."""
        kinds = chart_states(self.cls)
        return [e.state for e in self.log.entries[self.cls.__name__] if kinds.get(e.state) == "leaf"]


def same_value(a: Any, b: Any) -> bool:
    """Whether two values of the chart's data are the same: of one type and equal, or both NaN."""
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return bool(a == b) and type(a) is type(b)
