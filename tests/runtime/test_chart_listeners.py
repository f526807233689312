"""Trace and Coverage listeners."""

from __future__ import annotations

import io
import json

from statemachine import State

from ttt_sm.runtime import Data, TickChart, after
from ttt_sm.runtime.listeners import Coverage, Trace, TraceRecord


class Door(TickChart):
    """A door that opens on ``button`` and closes by itself after 2 ticks."""

    inputs = (Data("blocked", "bool", False, "something in the way"),)
    outputs = (Data("angle", "rad", 0.0, "door angle"),)

    closed = State(initial=True)

    class open(State.Compound):
        opening = State(initial=True)
        held = State()
        opening.to(held, cond=after(1))

    jammed = State()
    button = closed.to(open)
    open.to(closed, cond=[after(2), "not blocked"])
    open.to(jammed, cond="blocked")
    fix = jammed.to(closed)

    def on_enter_open(self) -> None:
        self.angle = 1.5


def test_trace_records_tick_time_chart_source_target_trigger_and_data():
    trace = Trace()
    door = Door(tick_period_s=0.1, chart_name="front door", listeners=[trace])
    door.post("button", who="tester")
    door.run_ticks(3)
    rows = [(r.tick, r.chart, r.source, r.target, r.trigger) for r in trace.records]
    assert rows == [
        (1, "front door", "closed", "open", "button"),
        (2, "front door", "opening", "held", "tick"),
        (3, "front door", "open", "closed", "tick"),
    ]
    first = trace.records[0]
    assert first.time_s == 0.1
    assert first.data == {"blocked": False, "angle": 1.5}
    assert first.event_args == {"who": "tester"}


def test_trace_json_lines_round_trip(tmp_path):
    trace = Trace()
    door = Door(tick_period_s=0.1)
    trace.observe(door)
    door.post("button")
    door.run_ticks(3)
    path = trace.write_jsonl(tmp_path / "trace.jsonl")
    lines = path.read_text().splitlines()
    assert len(lines) == 3 and all(isinstance(json.loads(line), dict) for line in lines)
    assert Trace.read_jsonl(path) == trace.records
    assert TraceRecord.from_json(lines[0]) == trace.records[0]


def test_trace_streams_to_a_sink_without_keeping_records():
    sink = io.StringIO()
    trace = Trace(sink=sink, keep=False)
    door = Door(listeners=[trace])
    door.post("button")
    door.tick()
    assert trace.records == []
    assert json.loads(sink.getvalue())["trigger"] == "button"


def test_coverage_lists_missing_states_and_transitions():
    coverage = Coverage()
    door = Door()
    coverage.observe(door)
    door.post("button")
    door.run_ticks(3)  # closed -> open.opening -> held -> closed
    chart = coverage.report().charts[0]
    assert chart.chart == "Door"
    assert chart.entered == ("closed", "open", "opening", "held")
    assert chart.missing_states == ("jammed",)
    assert chart.missing_transitions == ("open -> jammed: tick [blocked]", "jammed -> closed: fix")
    assert not coverage.report().complete
    text = coverage.report().to_text()
    assert "Door: states 4/5, transitions 3/5" in text
    assert "never entered: jammed" in text


def test_coverage_adds_up_instances_and_reaches_complete():
    coverage = Coverage()
    first, second = Door(), Door()
    coverage.observe(first, second)
    first.post("button")
    first.run_ticks(3)
    second.post("button")
    second.tick()
    second.blocked = True
    second.tick()
    second.post("fix")
    second.tick()
    report = coverage.report()
    assert report.complete, report.to_text()
    assert report.to_dict()["Door"]["transitions"] == "5/5"


def test_coverage_includes_charts_never_run():
    report = Coverage().include(Door).report()
    assert report.charts[0].entered == () and len(report.charts[0].missing_states) == 5
