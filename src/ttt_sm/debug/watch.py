"""What the debugger sees of the robot's charts: the listeners on them, by name, tick by tick.

:class:`ChartWatch` attaches the listeners to every chart of the robot, and
again to the charts a Safety reset brings (:meth:`Robot.reinitialise
<ttt_sm.app.robot.Robot.reinitialise>`): the trace (the newest transitions in
memory, all of them streamed to the trace file if there is one), the
breakpoints' listener, the :class:`~.timeline.Timeline` of states and any a
view adds (:meth:`ChartWatch.add_listener`).  It keeps the charts' data as
they were just before the last chart tick (:meth:`ChartWatch.data_diff`) and
finds charts by name for every command.  A replay rebuilds the robot:
:meth:`ChartWatch.attach` starts the trace and the timeline anew on it.
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from ..app.robot import Robot
from ..files import write_atomic
from ..runtime import TickChart
from ..runtime.errors import GraphvizMissingError
from ..runtime.export import render_active
from ..runtime.listeners import Trace
from ..runtime.recordfile import RecordFile
from .breakpoints import ChartIndex
from .errors import DebugError
from .names import RobotNames
from .records import DataChange, DataDiff
from .replay import GameRecipe
from .timeline import Timeline, TimelineWindow


class ChartWatch:
    """The listeners on every chart of the robot, and what the debugger reads of the charts by name.

    ``listeners``: attached to every chart after the trace (the breakpoints'
    listener); ``trace_file``: where the whole trace streams (None: the
    newest ``trace_keep`` transitions in memory only).
    """

    def __init__(self, names: RobotNames, listeners: Sequence[object], trace_file: RecordFile | None,
                 trace_keep: int) -> None:
        self._names = names
        self._listeners = list(listeners)
        self.trace_file = trace_file
        self.trace_keep = trace_keep

    def attach(self, robot: Robot) -> None:
        """Watch a robot's charts from its power-on: a new trace and timeline, the listeners on every chart."""
        self.robot = robot
        # a full disk stops the trace file, not the session (trace_failure says so)
        self.trace = Trace(sink=self.trace_file, limit=self.trace_keep, keep_going=True)
        self.state_history = Timeline()
        for chart in robot.charts.values():
            chart.add_listener(self.trace, *self._listeners)
        self.state_history.observe(robot.charts.values())
        self._index_charts(robot)
        self._before: list[Any] | None = None
        self._before_tick = 0
        robot.charts_replaced.append(self._charts_replaced)

    def _index_charts(self, robot: Robot) -> None:
        self.index = ChartIndex(dict(robot.charts))
        self._names.forget()
        # The charts' data just before the last chart tick (for data_diff): one
        # itemgetter per chart over its data (the instance dict, or a buffered chart's view).
        self._data_getters = [(name, [d.name for d in c.declarations()], c.data_mapping())
                              for name, c in robot.charts.items()]
        self._getters = [(_values_of(names), d) for _, names, d in self._data_getters]

    def _charts_replaced(self, charts: Sequence[TickChart]) -> None:
        """The Safety chart's reset gave the robot new drive-initialisation and Control charts
        (:meth:`Robot.reinitialise`): the trace, the breakpoints, the timeline and every view see them."""
        for chart in charts:
            chart.add_listener(self.trace, *self._listeners)
        self.state_history.observe(charts)
        self._index_charts(self.robot)

    def add_listener(self, listener: object) -> None:
        """Attach a python-statemachine listener to every chart, now and after each replay's rebuild.

        A view over the session (a GUI counting the transitions taken) sees
        the charts the debugger runs, whichever robot that is.
        """
        self._listeners.append(listener)
        for chart in self.robot.charts.values():
            chart.add_listener(listener)

    # -- charts by name ------------------------------------------------------------

    def chart(self, name: str) -> TickChart:
        """A chart by name; :class:`DebugError` names the charts there are."""
        self.index.structure(name)
        return self.robot.charts[name]

    def where(self) -> dict[str, list[str]]:
        """Each chart's active states, outermost first (document order)."""
        out = {}
        for name, chart in self.robot.charts.items():
            active = set(chart.configuration_values)
            out[name] = [s.id for s in type(chart).structure().states if s.id in active]
        return out

    def timeline(self, chart: str, seconds: float | None = None) -> TimelineWindow:
        """When the chart's states were entered and left, over the last ``seconds`` of chart
        time (None: all the bounded history holds); see :class:`~.timeline.Timeline`."""
        c = self.chart(chart)
        if seconds is not None and not (isinstance(seconds, (int, float)) and math.isfinite(seconds)
                                        and seconds > 0):
            raise DebugError(f"timeline: the time must be a positive number of seconds, got {seconds!r}")
        period = c.tick_period_s or self.robot.params.control.chart_dt
        return self.state_history.window(chart, c.tick_count, period, seconds)

    def diagram(self, chart: str, path: str | Path | None = None) -> Path:
        """Write the chart's diagram with its active states highlighted.

        The format follows the extension: ``.svg``, ``.png`` (Graphviz), ``.dot``,
        ``.md``/``.mmd`` (Mermaid).  Default: ``out/debug/<Chart>-tick<N>.svg``.
        """
        c = self.chart(chart)
        if path is None:
            path = Path("out/debug") / f"{chart}-tick{self.robot.chart_ticks}.svg"
        path = Path(path)
        formats = {".svg": "svg", ".png": "png", ".dot": "dot", ".gv": "dot", ".md": "mermaid",
                   ".mmd": "mermaid"}
        fmt = formats.get(path.suffix.lower())
        if fmt is None:
            raise DebugError(f"diagram: unknown extension {path.suffix or '(none)'!r} of {str(path)!r};"
                             f" use {', '.join(formats)}")
        try:
            picture = render_active(c, fmt)
        except GraphvizMissingError as exc:
            raise DebugError(str(exc)) from None
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            write_atomic(path, picture)
        except OSError as exc:
            raise DebugError(f"diagram: cannot write {str(path)!r}: {exc.strerror or exc}") from None
        return path

    # -- the data before a chart tick ----------------------------------------------

    def keep_before_tick(self) -> None:
        """Keep every chart's declared data as it is now: a chart tick is about to run."""
        self._before = [get(d) for get, d in self._getters]
        self._before_tick = self.robot.chart_ticks + 1

    def data_diff(self, chart: str | None = None) -> DataDiff | None:
        """The chart data that changed since just before the last chart tick (None: no tick run yet).

        ``chart``: one chart, or every chart.  The values before the tick are
        kept as the debugger runs each chart tick, at the cost of one copy of
        the declared data per tick.
        """
        if chart is not None:
            self.chart(chart)
        if self._before is None:
            return None
        changes: list[DataChange] = []
        for (name, names, d), before in zip(self._data_getters, self._before, strict=True):
            if chart is not None and name != chart:
                continue
            decls = {x.name: x for x in self.robot.charts[name].declarations()}
            for datum, old in zip(names, before, strict=True):
                new = d[datum]
                if not _same(old, new):
                    decl = decls[datum]
                    changes.append(DataChange(name, datum, decl.kind, decl.unit, old, new))
        return DataDiff(self._before_tick, tuple(changes))

    # -- the trace -----------------------------------------------------------------

    def save_trace(self, path: str | Path) -> Path:
        """Write the transitions the trace keeps (the newest :attr:`trace_keep`) as JSON Lines.

        All of them since power-on (or the last replay) while no more have
        happened; :attr:`trace.dropped <ttt_sm.runtime.listeners.Trace.dropped>`
        says how many older ones were let go (the trace file has them).
        """
        if not str(path).strip():
            raise DebugError("trace save: the file name is empty; e.g. trace save out/trace.jsonl")
        try:
            return self.trace.write_jsonl(path)
        except (OSError, ValueError) as exc:  # ValueError: a NUL in the name
            raise DebugError(f"trace save: cannot write {str(path)!r}: {getattr(exc, 'strerror', None) or exc}"
                             ) from None

    def where_now(self) -> dict[str, Any]:
        """Where the session stands: chart tick, control steps, simulated time (for a record's lines)."""
        robot = self.robot
        return {"tick": robot.chart_ticks, "steps": robot.steps, "t": round(robot.t, 6)}

    def mark(self, event: str, **data: Any) -> None:
        """A line in the trace file (if any) saying what the session did here (a replay, a start over)."""
        if self.trace_file is not None:
            try:
                self.trace_file.add({"event": event, **self.where_now(), **data})
            except OSError as exc:  # the disk is full: the trace file stops (trace_failure), the session goes on
                self.trace.sink_error, self.trace.sink = exc, None

    @property
    def trace_failure(self) -> OSError | None:
        """Why the trace file stopped before the session's end (the disk full: it holds whole lines only), or
        None."""
        return self.trace_file.failed if self.trace_file is not None else None

    def end_trace(self, how: str = "finished", **data: Any) -> Path | None:
        """End the trace file (if any) with ``how`` (``finished``, ``interrupted``, ``error``) and where
        the session stood; its path.  Only the first call writes."""
        if self.trace_file is None:
            return None
        try:
            self.trace_file.end(how, **data, **self.where_now(), transitions=self.trace.count)
        except OSError:  # the disk full at the last line: the file holds whole lines, trace_failure says why
            pass
        return self.trace_file.path


def trace_head(robot: Robot, recipe: object, keep: int) -> dict[str, Any]:
    """The trace file's first line: how the robot was built, its step and tick, what memory keeps."""
    return {"event": "trace", "charts": list(robot.charts),
            "seed": getattr(recipe, "seed", None), "q_start": getattr(recipe, "q_start", None),
            "settle_s": getattr(recipe, "settle_s", None), "game": isinstance(recipe, GameRecipe),
            "dt_s": robot.params.control.dt, "chart_divider": robot.params.control.chart_divider,
            "kept_in_memory": keep}


def _values_of(names: Sequence[str]) -> Callable[[Mapping[str, Any]], tuple[Any, ...]]:
    """A fast reader of the named values of a chart's data, as a tuple (one C call per chart tick)."""
    if len(names) > 1:
        return operator.itemgetter(*names)
    return lambda d: tuple(d[n] for n in names)


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    try:
        return bool(a == b)
    except (TypeError, ValueError):  # arrays compare element-wise
        return a is b
