"""A chart's clock: its ticks, the time in each state, and Stateflow's temporal logic over them.

A mixin of :class:`~.chart.TickChart` (docs/runtime.md, "Temporal logic"):
``after``/``before``/``at``/``every`` and ``temporalCount`` count ticks, seconds
(ticks times the chart's period) or events since a state was entered;
``duration(condition)`` the seconds since a condition became true.  The
execution (:mod:`.engine`) keeps the counters; this reads them.
"""

from __future__ import annotations

from typing import Any

from statemachine.state import State

from .errors import TemporalLogicError
from .temporal import DurationSpec, Temporal


class ChartClock:
    """The clock of a :class:`~.chart.TickChart` (a mixin of it): ticks, time in states, temporal logic."""

    # what the chart gives the mixin
    chart_name: str
    tick_period_s: float | None
    _ticks: int
    _entered_at: dict[str, int]

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


    def temporal_holds(self, spec: Temporal, state: Any) -> bool:
        """Whether a temporal operator holds for `state` (a state or its id) now."""
        state_id = getattr(state, "id", state)
        return spec.holds(int(self.temporal_count(spec.unit, state_id, raw=True)), spec.ticks(self.tick_period_s))

    def temporal_count(self, unit: str = "tick", state: Any = None, raw: bool = False) -> float:
        """Stateflow's ``temporalCount(unit)``: ticks, seconds (``sec``, ``msec``, ``usec``) or events E
        counted since `state` was entered (default: the state whose action or transition is running).

        With ``raw=True`` time units are counted in ticks.
        """
        from .temporal import TIME_UNITS

        d = self.__dict__
        if state is None:
            state = self._current_state_id()
        state_id = getattr(state, "id", state)
        if unit == "tick" or unit in TIME_UNITS:
            ticks = d["_ticks"] - d["_entered_at"][state_id]
            if unit == "tick" or raw:
                return ticks
            if self.tick_period_s is None:
                raise TemporalLogicError(f"temporal_count({unit!r}) needs the chart's tick period")
            return ticks * self.tick_period_s / TIME_UNITS[unit]
        return int(d["_counts"].get(state_id, {}).get(unit, 0))

    def _current_state_id(self) -> str:
        d = self.__dict__
        if d["_frames"]:
            kind, node, path = d["_frames"][-1]
            return str(node.id)
        if d["_cur"] is not None:
            return str(d["_cur"].id)
        raise TemporalLogicError(f"{self.chart_name}: temporal_count() without a state, outside an action:"
                                 " name the state (temporal_count(unit, state))")

    def duration_holds(self, spec: DurationSpec, state: Any) -> bool:
        """Whether ``duration(condition) <op> seconds`` holds for `state` now."""
        return spec.holds(self._duration_s(spec, getattr(state, "id", state)))

    def _duration_s(self, spec: DurationSpec, state_id: str) -> float:
        d = self.__dict__
        since = d["_since"].get((state_id, spec))
        if since is None or self.tick_period_s is None:
            return 0.0
        return (d["_ticks"] - since) * self.tick_period_s
