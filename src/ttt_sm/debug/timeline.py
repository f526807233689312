"""When each state of each chart was entered and left: the debugger's timeline.

:class:`Timeline` is a python-statemachine listener (``on_enter_state`` /
``on_exit_state``), so it sees every state the library enters and exits,
compound states and the states a history pseudo-state restores included,
with the chart tick it happened in.  It keeps a bounded history per chart
(:data:`KEEP`): a long session forgets its oldest intervals, and says how
many.  :meth:`Timeline.window` gives the intervals of the last seconds;
:func:`~.views.timeline_lines` draws them as a text Gantt chart and a table.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable
from dataclasses import dataclass

from statemachine import StateChart
from statemachine.state import State

#: Intervals kept per chart; older ones are dropped (and counted).
KEEP = 20_000


@dataclass(frozen=True)
class Interval:
    """A state active from chart tick ``entered`` to chart tick ``left`` (None: still active).

    A state entered in tick *k* and exited in tick *m* was active for *m − k*
    ticks; entered and left in the same tick, for 0 (it ran no during action).
    """

    chart: str
    state: str
    entered: int
    left: int | None

    def ticks(self, now: int) -> int:
        """Ticks active: until it was left, or until chart tick ``now`` if it is still active."""
        return (self.left if self.left is not None else now) - self.entered


@dataclass(frozen=True)
class TimelineWindow:
    """The intervals of one chart overlapping chart ticks ``first`` .. ``last`` (``last``: now)."""

    chart: str
    first: int
    last: int
    period_s: float
    intervals: tuple[Interval, ...]
    #: Intervals of this chart the bounded history no longer holds (all older than the window's).
    dropped: int

    def seconds(self, tick: int) -> float:
        """Chart time of a chart tick, s: ticks times the period, as the trace's ``time_s``."""
        return tick * self.period_s


class Timeline:
    """Listener recording, per chart, when each state was entered and left (in chart ticks)."""

    def __init__(self, keep: int = KEEP) -> None:
        self.keep = keep
        self._open: dict[tuple[str, str], int] = {}
        self._closed: dict[str, deque[Interval]] = {}
        self._dropped: dict[str, int] = {}
        self._order: dict[str, list[str]] = {}

    def observe(self, charts: Iterable[StateChart]) -> Timeline:
        """Attach to charts; the states active now count as entered at the chart's current tick.

        A chart observed under a name already observed takes the old one's
        place (the Safety chart's reset builds new drive-initialisation and
        Control charts): the states the old one left active are left now.
        """
        for chart in charts:
            name = _name(chart)
            self._closed.setdefault(name, deque())
            self._dropped.setdefault(name, 0)
            self._order[name] = [s.id for s in type(chart).structure().states]  # type: ignore[attr-defined]
            tick = _tick(chart)
            for key in [k for k in self._open if k[0] == name]:
                self._close(name, key[1], self._open.pop(key), tick)
            for state in chart.configuration:
                self._open[(name, state.id)] = tick
            chart.add_listener(self)
        return self

    # -- the listener --------------------------------------------------------------

    def on_enter_state(self, machine: StateChart, target: State) -> None:
        self._open[(_name(machine), target.id)] = _tick(machine)

    def on_exit_state(self, machine: StateChart, source: State) -> None:
        name = _name(machine)
        entered = self._open.pop((name, source.id), None)
        if entered is None:
            return
        self._close(name, source.id, entered, _tick(machine))

    def _close(self, name: str, state: str, entered: int, left: int) -> None:
        closed = self._closed.setdefault(name, deque())
        if len(closed) >= self.keep:
            closed.popleft()
            self._dropped[name] = self._dropped.get(name, 0) + 1
        closed.append(Interval(name, state, entered, left))

    # -- reading -------------------------------------------------------------------

    def states(self, chart: str) -> list[str]:
        """The chart's states in document order (outermost first)."""
        return list(self._order.get(chart, []))

    def intervals(self, chart: str) -> list[Interval]:
        """Every interval kept for the chart, the active states' too, by the tick they were entered."""
        active = [Interval(chart, state, tick, None) for (c, state), tick in self._open.items() if c == chart]
        order = {s: i for i, s in enumerate(self._order.get(chart, []))}
        return sorted([*self._closed.get(chart, ()), *active],
                      key=lambda iv: (iv.entered, order.get(iv.state, 0)))

    def window(self, chart: str, now: int, period_s: float, seconds: float | None = None) -> TimelineWindow:
        """The intervals overlapping the last ``seconds`` of chart time before chart tick ``now``
        (None: everything kept)."""
        # a window longer than the run is the whole run (and 1e308 s is no overflow)
        first = 0 if seconds is None or seconds / period_s >= now else max(0, now - int(round(seconds / period_s)))
        kept = [iv for iv in self.intervals(chart)
                if (iv.left is None or iv.left >= first) and iv.entered <= now]
        if seconds is None and kept and self._dropped.get(chart, 0):
            first = min(iv.entered for iv in kept)
        return TimelineWindow(chart, first, now, period_s, tuple(kept), self._dropped.get(chart, 0))


def _name(chart: StateChart) -> str:
    return str(getattr(chart, "chart_name", type(chart).__name__))


def _tick(chart: StateChart) -> int:
    return int(getattr(chart, "tick_count", 0))
