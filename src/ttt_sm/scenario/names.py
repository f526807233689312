"""The names and values a scenario file may use, checked: charts, states, data, conditions, numbers.

:class:`NameChecker` is the base of the loader's checker (:mod:`.loader`): it
knows the catalog (the charts and signals there are), names a mistake by file
and line (:class:`~.errors.ScenarioError`, with the names there are and a guess
at what was meant) and lets checking go on after a mistake in one part of the
file (:meth:`NameChecker.going_on`).  :mod:`.steps` reads each step kind with
it; :mod:`.loader` reads the file as a whole.
"""

from __future__ import annotations

import contextlib
import math
import reprlib
from collections.abc import Iterable, Iterator, Mapping
from typing import Any

from ..runtime import TickChart
from ..runtime.conditions import ExprError, Expression, parse
from ..runtime.errors import suggest
from .errors import ScenarioError, ScenarioErrors
from .model import DEFAULT_MAX_STEP_S, BareCharts, Catalog, ChartRef, chart_data, chart_states
from .source import MarkedDict

#: The signals a bare-chart scenario may read: the chart time, s.
BARE_SIGNALS: Mapping[str, int | None] = {"t": None}


def short_repr(value: Any, limit: int = 60) -> str:
    """``repr(value)`` cut to ``limit`` characters: a message never formats a huge value whole."""
    text = reprlib.repr(value) if isinstance(value, (list, dict, tuple)) else repr(value)
    return text if len(text) <= limit else text[:limit] + f"...({len(text)} characters)"


def type_name(value: Any) -> str:
    """How a message names a value of the file: ``number 3``, ``text 'x'``, ``an empty list``."""
    if value is None:
        return "nothing"
    if isinstance(value, (list, dict)) and not value:
        return f"an empty {'list' if isinstance(value, list) else 'mapping'}"
    if isinstance(value, bool):
        return f"boolean {str(value).lower()}"
    if isinstance(value, (int, float)):
        return f"number {value}"
    if isinstance(value, str):
        return f"text {short_repr(value)}"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, dict):
        return "a mapping"
    return type(value).__name__


def is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)

class NameChecker:
    """Checks the names and values one scenario file uses; collects its mistakes in :attr:`mistakes`."""

    def __init__(self, file: str, catalog: Catalog) -> None:
        self.file = file
        self.catalog = catalog
        self.mistakes: list[ScenarioError] = []
        self.bare: BareCharts | None = None
        self.max_step_s = DEFAULT_MAX_STEP_S
        #: The charts the steps may name: the robot's, or the bare ones.
        robot = catalog.robot_charts
        self.charts: Mapping[str, type[TickChart]] = {
            name: cls for name, cls in catalog.charts.items() if robot is None or name in robot}

    @property
    def signals(self) -> Mapping[str, int | None]:
        """The signals a condition may read: the robot's, or in bare-chart mode only ``t``."""
        return BARE_SIGNALS if self.bare is not None else self.catalog.signals

    @property
    def bare_mode(self) -> str:
        """How messages name the mode: ``this bare-chart scenario (line 2) runs only Game``."""
        assert self.bare is not None
        return f"this bare-chart scenario (line {self.bare.where.line}) runs only {self.bare}"

    def error(self, line: int, message: str) -> ScenarioError:
        return ScenarioError(self.file, line, message)

    @contextlib.contextmanager
    def going_on(self) -> Iterator[None]:
        """A part of the file checked on its own: a mistake in it is noted, and checking goes on after it."""
        try:
            yield
        except ScenarioError as exc:
            self.mistakes.extend(exc.errors)

    def keys(self, mapping: MarkedDict, allowed: Iterable[str], what: str) -> None:
        """Raise at the unknown keys of ``mapping``, all of them."""
        allowed = tuple(allowed)
        unknown = [self.error(mapping.key_lines[key], f"{what}: unknown key {short_repr(key)}{suggest(key, allowed)};"
                                                      f" keys: {', '.join(allowed)}")
                   for key in mapping if key not in allowed]
        if unknown:
            raise ScenarioErrors.of(unknown)

    def text(self, mapping: MarkedDict, key: str) -> str:
        value = mapping[key]
        if not isinstance(value, str) or not value.strip():
            raise self.error(mapping.line_of(key), f"{key}: expected text, got {type_name(value)}")
        return value.strip()

    def number(self, mapping: MarkedDict, key: str, what: str, positive: bool = True, bounded: bool = True) -> float:
        """A number of seconds; ``bounded``: at most ``max_step_s`` (simulated time a step may run)."""
        value = mapping[key]
        line = mapping.line_of(key)
        if not is_number(value):
            raise self.error(line, f"{what}: {key} expected a number, got {type_name(value)}")
        if positive and value <= 0:
            raise self.error(line, f"{what}: {key} must be > 0, got {value}")
        if not positive and value < 0:
            raise self.error(line, f"{what}: {key} must be >= 0, got {value}")
        if bounded and value > self.max_step_s:
            raise self.error(line, f"{what}: {key} {value:g} s is beyond {self.max_step_s:g} s of simulated time,"
                                   f" the longest a step may run; if it is meant, put 'max_step_s: {value:g}'"
                                   " at the top of the file")
        return float(value)

    # -- names -------------------------------------------------------------------------

    def chart_name(self, name: Any, line: int, what: str) -> str:
        charts = self.charts
        if isinstance(name, str) and name in self.catalog.charts and name not in charts:
            if self.bare is not None:
                raise self.error(line, f"{what}: {name} is not run: {self.bare_mode}")
            raise self.error(line, f"{what}: {name} is not part of the simulated robot (its charts:"
                                   f" {', '.join(charts)}); run it alone: put 'chart: {name}' at the top"
                                   " of the file")
        if not isinstance(name, str) or name not in charts:
            raise self.error(line, f"{what}: unknown chart {short_repr(name)}{suggest(name, charts)};"
                                   f" charts: {', '.join(charts)}")
        return name

    def state_name(self, chart: str, name: Any, line: int, what: str,
                   states: dict[str, str] | None = None) -> str:
        states = states if states is not None else chart_states(self.charts[chart])
        if not isinstance(name, str) or name not in states:
            real = [s for s, k in states.items() if k != "history"]
            raise self.error(line, f"{what}: {chart} has no state {short_repr(name)}{suggest(name, real)};"
                                   f" states: {', '.join(real)}")
        if states[name] == "history":
            raise self.error(line, f"{what}: {chart}.{name} is a history pseudo-state: it is never entered"
                                   " itself; name the state it restores")
        return name

    def chart_ref(self, text: Any, line: int, what: str, want: str) -> ChartRef:
        """``Chart.name`` where name must be an ``input`` or a ``state``."""
        if not isinstance(text, str) or text.count(".") != 1:
            example = "DriveInit1.stop" if want == "input" else "DriveInit1.turn_back"
            raise self.error(line, f"{what}: expected Chart.{want} like {example}, got {type_name(text)}")
        chart, name = text.split(".")
        self.chart_name(chart, line, what)
        cls = self.charts[chart]
        if want == "state":
            self.state_name(chart, name, line, what)
            return ChartRef(chart, name)
        data = chart_data(cls)
        inputs = [n for n, k in data.items() if k == "input"]
        if name not in inputs:
            if name in data:
                problem = f"{chart}.{name} is an {data[name]}, not an input"
            else:
                problem = f"{chart} has no input {short_repr(name)}{suggest(name, inputs)}"
            raise self.error(line, f"{what}: {problem}; inputs: {', '.join(inputs)}")
        return ChartRef(chart, name)

    def condition(self, text: Any, line: int, what: str) -> Expression:
        try:
            expr = parse(text)
        except ExprError as exc:
            raise self.error(line, f"{what}: {exc}") from None
        for ref in dict.fromkeys(expr.refs):
            with self.going_on():  # each name on its own: two typos, two messages
                self.expr_ref(ref, expr, line, what)
        return expr

    def expr_ref(self, ref: Any, expr: Expression, line: int, what: str) -> None:
        at = f" in {short_repr(expr.text, 120)}"
        if ref.chart is not None:
            self.chart_name(ref.chart, line, what)
            cls = self.charts[ref.chart]
            data, states = chart_data(cls), chart_states(cls)
            if ref.name in states and states[ref.name] == "history":
                raise self.error(line, f"{what}: {ref.chart}.{ref.name} is a history pseudo-state, never"
                                       f" active{at}")
            if ref.name not in data and ref.name not in states:
                names = [*data, *(s for s, k in states.items() if k != "history")]
                raise self.error(line, f"{what}: {ref.chart} has no datum or state {short_repr(ref.name)}"
                                       f"{suggest(ref.name, names)}{at}; data: {', '.join(data)}")
            if ref.index is not None:
                raise self.error(line, f"{what}: {ref.chart}.{ref.name} is not a list: no [{ref.index}]{at}")
            return
        signals = self.signals
        if self.bare is not None and ref.name not in signals and ref.name in self.catalog.signals:
            raise self.error(line, f"{what}: {ref.name} is a signal of the simulated arm; {self.bare_mode},"
                                   f" without the arm: a condition reads the charts' data and states, and"
                                   f" t (chart time){at}")
        if ref.name not in signals:
            raise self.error(line, f"{what}: unknown name {short_repr(ref.name)}{suggest(ref.name, signals)}{at};"
                                   f" a chart datum is Chart.name; signals: {', '.join(signals)}")
        size = signals[ref.name]
        if size is None and ref.index is not None:
            raise self.error(line, f"{what}: signal {ref.name} is a single value: no [{ref.index}]{at}")
        if size is not None and ref.index is None:
            raise self.error(line, f"{what}: signal {ref.name} has {size} values: pick one, e.g."
                                   f" {ref.name}[1]{at}")
        if size is not None and ref.index is not None and not 1 <= ref.index <= size:
            raise self.error(line, f"{what}: {ref.name}[{ref.index}] out of range: {ref.name} has {size}"
                                   f" values, numbered from 1 as the thesis numbers joints: [1] to"
                                   f" [{size}]{at}")
