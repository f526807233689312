"""Reading the steps of a scenario file, one method per step kind (``step_<kind>``).

:class:`StepReader` turns one item of ``steps:`` into its :class:`~.model.Step`:
it checks the keys the kind allows (:data:`STEP_OPTIONS`), the names it uses
(:class:`~.names.NameChecker`) and the values, and raises
:class:`~.errors.ScenarioError` at the line of a mistake.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Literal, cast

from ..runtime.chart import check_event_data
from ..runtime.errors import EventDataError, suggest
from . import model
from .model import ChartRef, Step, Where, chart_states
from .names import NameChecker, is_number, short_repr, type_name
from .source import MarkedDict, MarkedList

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


class StepReader(NameChecker):
    """Reads each step of ``steps:``: :meth:`step` picks the ``step_<kind>`` method of the item's kind."""

    def step(self, item: Any, line: int) -> Step:
        if not isinstance(item, MarkedDict) or not item:
            raise self.error(line, f"a step is a mapping like 'run: {{seconds: 1}}', got {type_name(item)};"
                                   f" step kinds: {', '.join(STEP_OPTIONS)}")
        kinds = [k for k in item if k in STEP_OPTIONS]
        if not kinds:
            key = next(iter(item))
            raise self.error(item.key_lines[key], f"unknown step kind {short_repr(key)}{suggest(key, STEP_OPTIONS)};"
                                                  f" step kinds: {', '.join(STEP_OPTIONS)}")
        if len(kinds) > 1:
            raise self.error(item.key_lines[kinds[1]], f"one step, two actions ({short_repr(kinds[0])} and"
                                                       f" {short_repr(kinds[1])}): start a new step with '- '")
        kind = kinds[0]
        self.keys(item, (kind, *STEP_OPTIONS[kind]), kind)
        where = Where(self.file, item.key_lines[kind])
        handler: Callable[[Any, int, Where, MarkedDict], Step] = getattr(self, f"step_{kind}")
        return handler(item[kind], item.line_of(kind), where, item)

    def step_set(self, value: Any, line: int, where: Where, item: MarkedDict) -> Step:
        if not isinstance(value, MarkedDict) or not value:
            raise self.error(line, "set: expected a mapping like {DriveInit1.stop: true}, got "
                                   f"{type_name(value)}")
        force = item.get("force", False)
        if self.bare is not None and "force" in item:
            raise self.error(item.line_of("force"), f"force: {self.bare_mode}: nothing feeds the charts' inputs,"
                                                    " so a set value stays until the next set; remove force:")
        if not isinstance(force, bool):
            raise self.error(item.line_of("force"), f"force: expected true or false, got {type_name(force)}")
        values = []
        for key, v in value.items():
            with self.going_on():  # each input on its own
                values.append(self.set_value(key, v, value))
        return model.SetStep(where, tuple(values), force)

    def set_value(self, key: Any, v: Any, value: MarkedDict) -> tuple[ChartRef, Any]:
        ref = self.chart_ref(key, value.key_lines[key], "set", want="input")
        decl = next(d for d in self.charts[ref.chart].declarations() if d.name == ref.name)
        default = decl.default
        if isinstance(default, bool) and not isinstance(v, bool):
            raise self.error(value.line_of(key), f"set: {ref} is a flag: expected true or false,"
                                                 f" got {type_name(v)}")
        if is_number(default) and not isinstance(default, bool) and not is_number(v):
            raise self.error(value.line_of(key), f"set: {ref} is a number ({decl.unit}): expected a"
                                                 f" number, got {type_name(v)}")
        return ref, float(v) if is_number(default) and not isinstance(default, bool) else v

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
        return model.ReleaseStep(where, tuple(refs))

    def step_post(self, value: Any, line: int, where: Where, item: MarkedDict) -> Step:
        if not isinstance(value, MarkedDict):
            raise self.error(line, "post: expected {chart: ..., event: ..., data: {...}},"
                                   f" got {type_name(value)}")
        self.keys(value, ("chart", "event", "data"), "post")
        for key in ("chart", "event"):
            if key not in value:
                raise self.error(value.line, f"post: missing {key}:")
        chart = self.chart_name(value["chart"], value.line_of("chart"), "post")
        event = value["event"]
        events = self.charts[chart].structure().user_events
        if event not in events:
            listed = ", ".join(events) or "(none: all its transitions are tick transitions)"
            raise self.error(value.line_of("event"), f"post: {chart} handles no event {short_repr(event)}"
                                                     f"{suggest(event, events)}; events: {listed}")
        data = value.get("data", {})
        if not isinstance(data, dict) or not all(isinstance(k, str) and k.isidentifier() for k in data):
            raise self.error(value.line_of("data"), "post: data expected a mapping of names to values")
        try:
            check_event_data(chart, str(event), data)
        except EventDataError as exc:
            raise self.error(value.line_of("data"), f"post: {exc}") from None
        return model.PostStep(where, chart, str(event), dict(data))

    def step_run(self, value: Any, line: int, where: Where, item: MarkedDict) -> Step:
        if not isinstance(value, MarkedDict) or len(value) != 1:
            raise self.error(line, "run: expected {seconds: S} or {chart_steps: N},"
                                   f" got {type_name(value)}")
        self.keys(value, ("seconds", "chart_steps"), "run")
        if "seconds" in value:
            return model.RunStep(where, seconds=self.number(value, "seconds", "run"))
        steps = value["chart_steps"]
        if isinstance(steps, bool) or not isinstance(steps, int) or steps < 1:
            raise self.error(value.line_of("chart_steps"), f"run: chart_steps expected a whole number >= 1,"
                                                           f" got {type_name(steps)}")
        return model.RunStep(where, chart_steps=steps)

    def step_run_until(self, value: Any, line: int, where: Where, item: MarkedDict) -> Step:
        goals = ("entered", "active", "condition")
        if not isinstance(value, MarkedDict):
            raise self.error(line, "run_until: expected {entered: Chart.state, timeout_s: T}, {active: ...}"
                                   f" or {{condition: \"...\", timeout_s: T}}, got {type_name(value)}")
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
            return model.RunUntilStep(where, timeout, condition=cond)
        ref = self.chart_ref(value[goal], value.line_of(goal), "run_until", want="state")
        if goal == "entered":
            return model.RunUntilStep(where, timeout, entered=ref)
        return model.RunUntilStep(where, timeout, active=ref)

    def step_expect(self, value: Any, line: int, where: Where, item: MarkedDict) -> Step:
        if isinstance(value, str):
            return model.ExpectStep(where, self.condition(value, line, "expect"))
        if not isinstance(value, MarkedDict):
            raise self.error(line, f"expect: expected a condition or {{condition: ..., within_s: T}},"
                                   f" got {type_name(value)}")
        self.keys(value, ("condition", "within_s", "for_s"), "expect")
        if "condition" not in value:
            raise self.error(value.line, "expect: missing condition:")
        if "within_s" in value and "for_s" in value:
            raise self.error(value.line_of("for_s"), "expect: within_s (holds at some moment) and for_s"
                                                     " (holds all the time) exclude each other")
        cond = self.condition(value["condition"], value.line_of("condition"), "expect")
        within = self.number(value, "within_s", "expect") if "within_s" in value else None
        for_s = self.number(value, "for_s", "expect") if "for_s" in value else None
        return model.ExpectStep(where, cond, within_s=within, for_s=for_s)

    def sequence_step(self, kind: str, value: Any, line: int, what: str,
                      empty_ok: bool) -> tuple[str, Literal["subsequence", "exact"], MarkedList]:
        """The chart, match and sequence of an ``expect_states`` / ``expect_events`` step, checked."""
        if not isinstance(value, MarkedDict):
            raise self.error(line, f"{kind}: expected {{chart: ..., sequence: [...]}}, got {type_name(value)}")
        self.keys(value, ("chart", "sequence", "match"), kind)
        for key in ("chart", "sequence"):
            if key not in value:
                raise self.error(value.line, f"{kind}: missing {key}:")
        chart = self.chart_name(value["chart"], value.line_of("chart"), kind)
        match = value.get("match", "subsequence")
        if match not in MATCH_MODES:
            raise self.error(value.line_of("match"), f"{kind}: match expected one of"
                                                     f" {', '.join(MATCH_MODES)}, got {type_name(match)}")
        seq = value["sequence"]
        if not isinstance(seq, MarkedList) or not (seq or empty_ok):
            raise self.error(value.line_of("sequence"), f"{kind}: sequence expected a list of {what}"
                                                        f" names, got {type_name(seq)}")
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
        return model.ExpectStatesStep(where, chart, tuple(seq), match)

    def step_expect_events(self, value: Any, line: int, where: Where, item: MarkedDict) -> Step:
        chart, match, seq = self.sequence_step("expect_events", value, line, "event", empty_ok=True)
        events = self.charts[chart].structure().user_events
        for name, n_line in zip(seq, seq.item_lines, strict=True):
            if name not in events:
                with self.going_on():
                    listed = ", ".join(events) or "(none)"
                    raise self.error(n_line, f"expect_events: {chart} has no event {short_repr(name)}"
                                             f"{suggest(name, events)}; events: {listed}")
        return model.ExpectEventsStep(where, chart, tuple(seq), match)

    def step_mark(self, value: Any, line: int, where: Where, item: MarkedDict) -> Step:
        if value is not None and not isinstance(value, str):
            raise self.error(line, f"mark: expected a label (text) or nothing, got {type_name(value)}")
        return model.MarkStep(where, value or "")
