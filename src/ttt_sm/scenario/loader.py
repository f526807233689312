"""Read a scenario file and check it against the format and the charts it names.

Every mistake is a :class:`~.errors.ScenarioError` naming the file and the line:
an unknown step kind, chart, state, datum, event or signal (with the names
there are, and a guess at what was meant), a value of the wrong type, a missing
``timeout_s``, a condition that does not parse.  As a compiler does, the loader
reads the whole file and reports every mistake in one pass
(:class:`~.errors.ScenarioErrors`, one ``FILE:LINE: message`` each): a mistake
in one step does not hide those of the next; a mistake within a step stops
only that part of it (one key, one name of a list).  Only a mistake the rest
cannot be read without stops the reading: YAML that does not parse, a file
that is no mapping, ``chart:``/``charts:`` naming no chart.  Nothing runs before
the whole file is known to be right.

A scenario with ``chart: Name`` or ``charts: [A, B]`` (or ``charts: {a: A, b: A}``,
instances named by the scenario) runs those charts alone
(bare-chart mode): its steps may name only them, read only ``t`` of the
signals, and neither pose an arm (``start``) nor force inputs (nothing feeds
them).
"""

from __future__ import annotations

import contextlib
import math
import reprlib
from collections.abc import Callable, Iterable, Iterator, Mapping
from pathlib import Path
from typing import Any, Literal, cast

from ..runtime import TickChart
from ..runtime.chart import check_event_data
from ..runtime.conditions import KEYWORDS, ExprError, Expression, parse
from ..runtime.errors import EventDataError, suggest
from .errors import ScenarioError, ScenarioErrors
from .model import (
    DEFAULT_MAX_STEP_S,
    BareCharts,
    Catalog,
    ChartRef,
    ExpectEventsStep,
    ExpectStatesStep,
    ExpectStep,
    MarkStep,
    PostStep,
    ReleaseStep,
    RunStep,
    RunUntilStep,
    Scenario,
    SetStep,
    Start,
    Step,
    Where,
    chart_data,
    chart_states,
)
from .source import MarkedDict, MarkedList, load_yaml, load_yaml_file

TOP_KEYS = ("name", "description", "chart", "charts", "seed", "max_step_s", "start", "steps")
#: Step kinds, and the extra keys each allows beside its own.
STEP_OPTIONS: dict[str, tuple[str, ...]] = {
    "set": ("force",),
    "release": (),
    "post": (),
    "run": (),
    "run_until": (),
    "expect": (),
    "expect_states": (),
    "expect_events": (),
    "mark": (),
}
MATCH_MODES = ("subsequence", "exact")
#: The signals a bare-chart scenario may read: the chart time, s.
BARE_SIGNALS: Mapping[str, int | None] = {"t": None}


def _r(value: Any, limit: int = 60) -> str:
    """``repr(value)`` cut to ``limit`` characters: a message never formats a huge value whole."""
    text = reprlib.repr(value) if isinstance(value, (list, dict, tuple)) else repr(value)
    return text if len(text) <= limit else text[:limit] + f"...({len(text)} characters)"


def _type_name(value: Any) -> str:
    if value is None:
        return "nothing"
    if isinstance(value, (list, dict)) and not value:
        return f"an empty {'list' if isinstance(value, list) else 'mapping'}"
    if isinstance(value, bool):
        return f"boolean {str(value).lower()}"
    if isinstance(value, (int, float)):
        return f"number {value}"
    if isinstance(value, str):
        return f"text {_r(value)}"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, dict):
        return "a mapping"
    return type(value).__name__


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


class _Checker:
    """Turns the YAML data of one file into a :class:`Scenario`, or raises with every mistake in it."""

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

    # -- top level -------------------------------------------------------------------

    def scenario(self, doc: Any) -> Scenario:
        """The scenario, or :class:`ScenarioError` (one mistake) / :class:`ScenarioErrors` (several)."""
        scenario: Scenario | None = None
        with self.going_on():  # a mistake that stops the reading is the last one noted
            scenario = self.whole(doc)
        if self.mistakes or scenario is None:
            raise ScenarioErrors.of(self.mistakes)
        return scenario

    def whole(self, doc: Any) -> Scenario | None:
        if not isinstance(doc, MarkedDict):
            line = getattr(doc, "line", 1)
            raise self.error(line, "a scenario file is a mapping with name: and steps: (got "
                                   f"{_type_name(doc)})")
        unknown = [k for k in doc if k not in TOP_KEYS]
        with self.going_on():
            self.keys(doc, TOP_KEYS, "scenario")
        for key in ("name", "steps"):
            if key not in doc and not any(suggest(k, (key,)) for k in unknown):  # 'step:' is told once
                self.mistakes.append(self.error(doc.line, f"missing {key}:"))
        name, description, seed, start = "", "", 0, Start()
        with self.going_on():
            name = self.text(doc, "name") if "name" in doc else ""
        with self.going_on():
            description = self.text(doc, "description") if "description" in doc else ""
        with self.going_on():
            seed = doc.get("seed", 0)
            if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
                raise self.error(doc.line_of("seed"),
                                 f"seed: expected a whole number >= 0, got {_type_name(seed)}")
        with self.going_on():
            if "max_step_s" in doc:
                self.max_step_s = self.number(doc, "max_step_s", "max_step_s", bounded=False)
        self.bare = self.bare_charts(doc)  # the steps cannot be checked without knowing their charts
        with self.going_on():
            if self.bare is not None:
                self.charts = self.bare.charts
                if "start" in doc:
                    raise self.error(doc.line_of("start"), f"start: {self.bare_mode}, without the arm: there"
                                                           " is no pose to start from")
            start = self.start(doc["start"], doc.line_of("start")) if "start" in doc else Start()
        if "steps" not in doc:
            return None
        steps_data = doc["steps"]
        if not isinstance(steps_data, MarkedList) or not steps_data:
            raise self.error(doc.line_of("steps"), "steps: expected a list of steps, each starting with '- '")
        steps = []
        for item, line in zip(steps_data, steps_data.item_lines, strict=True):
            with self.going_on():  # each step on its own: a mistake in one does not hide the next's
                steps.append(self.step(item, line))
        if self.mistakes:
            return None
        return Scenario(name=name, file=self.file, steps=tuple(steps), description=description, seed=seed,
                        start=start, where=Where(self.file, doc.line), bare=self.bare, max_step_s=self.max_step_s)

    def bare_charts(self, doc: MarkedDict) -> BareCharts | None:
        """The charts to run alone, or None for the robot.

        ``chart: Game``; ``charts: [AlgorithmActivator, Game]``; or, for several
        instances of one chart, names of one's own: ``charts: {early: Game, late: Game}``.
        """
        given = [k for k in ("chart", "charts") if k in doc]
        if not given:
            return None
        if len(given) == 2:
            raise self.error(doc.line_of("charts"), "chart: and charts: exclude each other: one chart is"
                                                    " chart: Name, several are charts: [A, B]")
        key = given[0]
        value, line = doc[key], doc.line_of(key)
        pairs: list[tuple[Any, Any, int]]  # (name in the steps, chart class name, line)
        if key == "chart" and isinstance(value, str):
            pairs = [(value, value, line)]
        elif key == "charts" and isinstance(value, MarkedList) and value:
            pairs = [(n, n, n_line) for n, n_line in zip(value, value.item_lines, strict=True)]
        elif key == "charts" and isinstance(value, MarkedDict) and value:
            pairs = [(n, c, value.line_of(n)) for n, c in value.items()]
        else:
            raise self.error(line, f"{key}: expected a chart name like chart: Game, a list like charts:"
                                   " [AlgorithmActivator, Game], or names of one's own like charts:"
                                   f" {{early: Game, late: Game}}; got {_type_name(value)}")
        known = self.catalog.charts
        charts: dict[str, type[TickChart]] = {}
        for name, chart, n_line in pairs:
            if not isinstance(chart, str) or chart not in known:
                raise self.error(n_line, f"{key}: unknown chart {_r(chart)}{suggest(chart, known)};"
                                         f" charts: {', '.join(known)}")
            if not isinstance(name, str) or not name.isidentifier() or name in KEYWORDS:
                raise self.error(n_line, f"charts: {_r(name)} cannot name a chart in a condition: use letters,"
                                         " digits and _")
            if name in known and name != chart:
                raise self.error(n_line, f"charts: {name} is the name of a chart: name the {chart} otherwise")
            if name in charts:
                raise self.error(n_line, f"charts: {name} is listed twice")
            charts[name] = known[chart]
        return BareCharts(charts, Where(self.file, line))

    def keys(self, mapping: MarkedDict, allowed: Iterable[str], what: str) -> None:
        """Raise at the unknown keys of ``mapping``, all of them."""
        allowed = tuple(allowed)
        unknown = [self.error(mapping.key_lines[key], f"{what}: unknown key {_r(key)}{suggest(key, allowed)};"
                                                      f" keys: {', '.join(allowed)}")
                   for key in mapping if key not in allowed]
        if unknown:
            raise ScenarioErrors.of(unknown)

    def text(self, mapping: MarkedDict, key: str) -> str:
        value = mapping[key]
        if not isinstance(value, str) or not value.strip():
            raise self.error(mapping.line_of(key), f"{key}: expected text, got {_type_name(value)}")
        return value.strip()

    def number(self, mapping: MarkedDict, key: str, what: str, positive: bool = True, bounded: bool = True) -> float:
        """A number of seconds; ``bounded``: at most ``max_step_s`` (simulated time a step may run)."""
        value = mapping[key]
        line = mapping.line_of(key)
        if not _is_number(value):
            raise self.error(line, f"{what}: {key} expected a number, got {_type_name(value)}")
        if positive and value <= 0:
            raise self.error(line, f"{what}: {key} must be > 0, got {value}")
        if not positive and value < 0:
            raise self.error(line, f"{what}: {key} must be >= 0, got {value}")
        if bounded and value > self.max_step_s:
            raise self.error(line, f"{what}: {key} {value:g} s is beyond {self.max_step_s:g} s of simulated time,"
                                   f" the longest a step may run; if it is meant, put 'max_step_s: {value:g}'"
                                   " at the top of the file")
        return float(value)

    def start(self, data: Any, line: int) -> Start:
        if not isinstance(data, MarkedDict):
            raise self.error(line, "start: expected a mapping with q_deg: and settle_s:,"
                                   f" got {_type_name(data)}")
        self.keys(data, ("q_deg", "settle_s"), "start")
        q_deg: tuple[float, ...] | None = None
        if "q_deg" in data:
            q = data["q_deg"]
            if not isinstance(q, list) or len(q) not in (3, 4) or not all(_is_number(v) for v in q):
                raise self.error(data.line_of("q_deg"), "start: q_deg expected a list of 3 or 4 joint"
                                                        f" angles in degrees (q1, q2, q3[, q4]), got {_r(q)}")
            q_deg = tuple(float(v) for v in q) + ((0.0,) if len(q) == 3 else ())
        settle = self.number(data, "settle_s", "start", positive=False) if "settle_s" in data else 0.0
        return Start(q_deg=q_deg, settle_s=settle, where=Where(self.file, data.line))

    # -- steps -------------------------------------------------------------------------

    def step(self, item: Any, line: int) -> Step:
        if not isinstance(item, MarkedDict) or not item:
            raise self.error(line, f"a step is a mapping like 'run: {{seconds: 1}}', got {_type_name(item)};"
                                   f" step kinds: {', '.join(STEP_OPTIONS)}")
        kinds = [k for k in item if k in STEP_OPTIONS]
        if not kinds:
            key = next(iter(item))
            raise self.error(item.key_lines[key], f"unknown step kind {_r(key)}{suggest(key, STEP_OPTIONS)};"
                                                  f" step kinds: {', '.join(STEP_OPTIONS)}")
        if len(kinds) > 1:
            raise self.error(item.key_lines[kinds[1]], f"one step, two actions ({_r(kinds[0])} and"
                                                       f" {_r(kinds[1])}): start a new step with '- '")
        kind = kinds[0]
        self.keys(item, (kind, *STEP_OPTIONS[kind]), kind)
        where = Where(self.file, item.key_lines[kind])
        handler: Callable[[Any, int, Where, MarkedDict], Step] = getattr(self, f"step_{kind}")
        return handler(item[kind], item.line_of(kind), where, item)

    def step_set(self, value: Any, line: int, where: Where, item: MarkedDict) -> Step:
        if not isinstance(value, MarkedDict) or not value:
            raise self.error(line, "set: expected a mapping like {DriveInit1.stop: true}, got "
                                   f"{_type_name(value)}")
        force = item.get("force", False)
        if self.bare is not None and "force" in item:
            raise self.error(item.line_of("force"), f"force: {self.bare_mode}: nothing feeds the charts' inputs,"
                                                    " so a set value stays until the next set; remove force:")
        if not isinstance(force, bool):
            raise self.error(item.line_of("force"), f"force: expected true or false, got {_type_name(force)}")
        values = []
        for key, v in value.items():
            with self.going_on():  # each input on its own
                values.append(self.set_value(key, v, value))
        return SetStep(where, tuple(values), force)

    def set_value(self, key: Any, v: Any, value: MarkedDict) -> tuple[ChartRef, Any]:
        ref = self.chart_ref(key, value.key_lines[key], "set", want="input")
        decl = next(d for d in self.charts[ref.chart].declarations() if d.name == ref.name)
        default = decl.default
        if isinstance(default, bool) and not isinstance(v, bool):
            raise self.error(value.line_of(key), f"set: {ref} is a flag: expected true or false,"
                                                 f" got {_type_name(v)}")
        if _is_number(default) and not isinstance(default, bool) and not _is_number(v):
            raise self.error(value.line_of(key), f"set: {ref} is a number ({decl.unit}): expected a"
                                                 f" number, got {_type_name(v)}")
        return ref, float(v) if _is_number(default) and not isinstance(default, bool) else v

    def step_release(self, value: Any, line: int, where: Where, item: MarkedDict) -> Step:
        if self.bare is not None:
            raise self.error(where.line, f"release: {self.bare_mode}: nothing feeds the charts' inputs, so none is"
                                         " forced and there is nothing to release")
        names = value if isinstance(value, list) else [value]
        lines = value.item_lines if isinstance(value, MarkedList) else [line]
        if not names:
            raise self.error(line, "release: expected Chart.input or a list of them")
        refs = []
        for n, n_line in zip(names, lines, strict=True):
            with self.going_on():  # each name on its own
                refs.append(self.chart_ref(n, n_line, "release", want="input"))
        return ReleaseStep(where, tuple(refs))

    def step_post(self, value: Any, line: int, where: Where, item: MarkedDict) -> Step:
        if not isinstance(value, MarkedDict):
            raise self.error(line, "post: expected {chart: ..., event: ..., data: {...}},"
                                   f" got {_type_name(value)}")
        self.keys(value, ("chart", "event", "data"), "post")
        for key in ("chart", "event"):
            if key not in value:
                raise self.error(value.line, f"post: missing {key}:")
        chart = self.chart_name(value["chart"], value.line_of("chart"), "post")
        event = value["event"]
        events = self.charts[chart].structure().user_events
        if event not in events:
            listed = ", ".join(events) or "(none: all its transitions are tick transitions)"
            raise self.error(value.line_of("event"), f"post: {chart} handles no event {_r(event)}"
                                                     f"{suggest(event, events)}; events: {listed}")
        data = value.get("data", {})
        if not isinstance(data, dict) or not all(isinstance(k, str) and k.isidentifier() for k in data):
            raise self.error(value.line_of("data"), "post: data expected a mapping of names to values")
        try:
            check_event_data(chart, str(event), data)
        except EventDataError as exc:
            raise self.error(value.line_of("data"), f"post: {exc}") from None
        return PostStep(where, chart, str(event), dict(data))

    def step_run(self, value: Any, line: int, where: Where, item: MarkedDict) -> Step:
        if not isinstance(value, MarkedDict) or len(value) != 1:
            raise self.error(line, "run: expected {seconds: S} or {chart_steps: N},"
                                   f" got {_type_name(value)}")
        self.keys(value, ("seconds", "chart_steps"), "run")
        if "seconds" in value:
            return RunStep(where, seconds=self.number(value, "seconds", "run"))
        steps = value["chart_steps"]
        if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
            raise self.error(value.line_of("chart_steps"), f"run: chart_steps expected a whole number >= 1,"
                                                           f" got {_type_name(steps)}")
        return RunStep(where, chart_steps=steps)

    def step_run_until(self, value: Any, line: int, where: Where, item: MarkedDict) -> Step:
        goals = ("entered", "active", "condition")
        if not isinstance(value, MarkedDict):
            raise self.error(line, "run_until: expected {entered: Chart.state, timeout_s: T}, {active: ...}"
                                   f" or {{condition: \"...\", timeout_s: T}}, got {_type_name(value)}")
        self.keys(value, (*goals, "timeout_s"), "run_until")
        given = [g for g in goals if g in value]
        if len(given) != 1:
            raise self.error(value.line, f"run_until: give exactly one of {', '.join(goals)}"
                                         f" (got {', '.join(given) or 'none'})")
        if "timeout_s" not in value:
            raise self.error(value.line, "run_until: missing timeout_s: (seconds of simulated time after"
                                         " which the step fails)")
        timeout = self.number(value, "timeout_s", "run_until")
        goal = given[0]
        if goal == "condition":
            cond = self.condition(value["condition"], value.line_of("condition"), "run_until")
            return RunUntilStep(where, timeout, condition=cond)
        ref = self.chart_ref(value[goal], value.line_of(goal), "run_until", want="state")
        if goal == "entered":
            return RunUntilStep(where, timeout, entered=ref)
        return RunUntilStep(where, timeout, active=ref)

    def step_expect(self, value: Any, line: int, where: Where, item: MarkedDict) -> Step:
        if isinstance(value, str):
            return ExpectStep(where, self.condition(value, line, "expect"))
        if not isinstance(value, MarkedDict):
            raise self.error(line, f"expect: expected a condition or {{condition: ..., within_s: T}},"
                                   f" got {_type_name(value)}")
        self.keys(value, ("condition", "within_s", "for_s"), "expect")
        if "condition" not in value:
            raise self.error(value.line, "expect: missing condition:")
        if "within_s" in value and "for_s" in value:
            raise self.error(value.line_of("for_s"), "expect: within_s (holds at some moment) and for_s"
                                                     " (holds all the time) exclude each other")
        cond = self.condition(value["condition"], value.line_of("condition"), "expect")
        within = self.number(value, "within_s", "expect") if "within_s" in value else None
        for_s = self.number(value, "for_s", "expect") if "for_s" in value else None
        return ExpectStep(where, cond, within_s=within, for_s=for_s)

    def sequence_step(self, kind: str, value: Any, line: int, what: str,
                      empty_ok: bool) -> tuple[str, Literal["subsequence", "exact"], MarkedList]:
        """The chart, match and sequence of an ``expect_states`` / ``expect_events`` step, checked."""
        if not isinstance(value, MarkedDict):
            raise self.error(line, f"{kind}: expected {{chart: ..., sequence: [...]}}, got {_type_name(value)}")
        self.keys(value, ("chart", "sequence", "match"), kind)
        for key in ("chart", "sequence"):
            if key not in value:
                raise self.error(value.line, f"{kind}: missing {key}:")
        chart = self.chart_name(value["chart"], value.line_of("chart"), kind)
        match = value.get("match", "subsequence")
        if match not in MATCH_MODES:
            raise self.error(value.line_of("match"), f"{kind}: match expected one of"
                                                     f" {', '.join(MATCH_MODES)}, got {_type_name(match)}")
        seq = value["sequence"]
        if not isinstance(seq, MarkedList) or not (seq or empty_ok):
            raise self.error(value.line_of("sequence"), f"{kind}: sequence expected a list of {what}"
                                                        f" names, got {_type_name(seq)}")
        return chart, cast(Literal["subsequence", "exact"], match), seq

    def step_expect_states(self, value: Any, line: int, where: Where, item: MarkedDict) -> Step:
        chart, match, seq = self.sequence_step("expect_states", value, line, "state", empty_ok=False)
        states = chart_states(self.charts[chart])
        for name, n_line in zip(seq, seq.item_lines, strict=True):
            with self.going_on():  # each name on its own
                self.state_name(chart, name, n_line, "expect_states", states)
                if match == "exact" and states[name] == "compound":
                    raise self.error(n_line, f"expect_states: {chart}.{name} is a compound state; an exact"
                                             " sequence lists the leaf states entered (use match: subsequence"
                                             " to include compound states)")
        return ExpectStatesStep(where, chart, tuple(seq), match)

    def step_expect_events(self, value: Any, line: int, where: Where, item: MarkedDict) -> Step:
        chart, match, seq = self.sequence_step("expect_events", value, line, "event", empty_ok=True)
        events = self.charts[chart].structure().user_events
        for name, n_line in zip(seq, seq.item_lines, strict=True):
            if name not in events:
                with self.going_on():
                    listed = ", ".join(events) or "(none)"
                    raise self.error(n_line, f"expect_events: {chart} has no event {_r(name)}"
                                             f"{suggest(name, events)}; events: {listed}")
        return ExpectEventsStep(where, chart, tuple(seq), match)

    def step_mark(self, value: Any, line: int, where: Where, item: MarkedDict) -> Step:
        if value is not None and not isinstance(value, str):
            raise self.error(line, f"mark: expected a label (text) or nothing, got {_type_name(value)}")
        return MarkStep(where, value or "")

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
            raise self.error(line, f"{what}: unknown chart {_r(name)}{suggest(name, charts)};"
                                   f" charts: {', '.join(charts)}")
        return name

    def state_name(self, chart: str, name: Any, line: int, what: str,
                   states: dict[str, str] | None = None) -> str:
        states = states if states is not None else chart_states(self.charts[chart])
        if not isinstance(name, str) or name not in states:
            real = [s for s, k in states.items() if k != "history"]
            raise self.error(line, f"{what}: {chart} has no state {_r(name)}{suggest(name, real)};"
                                   f" states: {', '.join(real)}")
        if states[name] == "history":
            raise self.error(line, f"{what}: {chart}.{name} is a history pseudo-state: it is never entered"
                                   " itself; name the state it restores")
        return name

    def chart_ref(self, text: Any, line: int, what: str, want: str) -> ChartRef:
        """``Chart.name`` where name must be an ``input`` or a ``state``."""
        if not isinstance(text, str) or text.count(".") != 1:
            example = "DriveInit1.stop" if want == "input" else "DriveInit1.turn_back"
            raise self.error(line, f"{what}: expected Chart.{want} like {example}, got {_type_name(text)}")
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
                problem = f"{chart} has no input {_r(name)}{suggest(name, inputs)}"
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
        at = f" in {_r(expr.text, 120)}"
        if ref.chart is not None:
            self.chart_name(ref.chart, line, what)
            cls = self.charts[ref.chart]
            data, states = chart_data(cls), chart_states(cls)
            if ref.name in states and states[ref.name] == "history":
                raise self.error(line, f"{what}: {ref.chart}.{ref.name} is a history pseudo-state, never"
                                       f" active{at}")
            if ref.name not in data and ref.name not in states:
                names = [*data, *(s for s, k in states.items() if k != "history")]
                raise self.error(line, f"{what}: {ref.chart} has no datum or state {_r(ref.name)}"
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
            raise self.error(line, f"{what}: unknown name {_r(ref.name)}{suggest(ref.name, signals)}{at};"
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


def load_scenario_text(text: str, file: str = "<scenario>", catalog: Catalog | None = None) -> Scenario:
    """Load a scenario from YAML text (``file`` names it in errors)."""
    return _Checker(file, catalog or Catalog.default()).scenario(load_yaml(text, file))


def load_scenario(path: str | Path, catalog: Catalog | None = None) -> Scenario:
    """Load and check a scenario file; raise :class:`ScenarioError` naming the file and line."""
    return _Checker(str(path), catalog or Catalog.default()).scenario(load_yaml_file(path))


def scenario_files(paths: Iterable[str | Path]) -> list[Path]:
    """The scenario files named: files as given, folders as their ``*.yaml``/``*.yml`` files, sorted."""
    out: list[Path] = []
    for p in map(Path, paths):
        try:
            folder = p.is_dir()
        except OSError:  # a name too long: reading it as a file says so
            folder = False
        if folder:
            out += sorted(f for f in p.iterdir() if f.suffix in (".yaml", ".yml") and f.is_file())
        else:
            out.append(p)
    return out
