"""Declared chart data: listing, defaults, previous outputs, reset, definition errors."""

from __future__ import annotations

import pytest
from statemachine import State

from ttt_sm.runtime import ChartDefinitionError, Data, TickChart, UnknownDataError


class Pen(TickChart):
    """Moves X by ``inc`` per tick while ``drawing``: X_out = X_out_p + inc."""

    inputs = (Data("go", "bool", False, "start drawing"), Data("inc", "m", 0.001, "step per tick"))
    outputs = (Data("X_out", "m", 0.0, "tool X"), Data("fr_sw", "bool", False, "fast filter"))
    local = (Data("path", "m", [0.0], "points drawn"),)

    idle = State(initial=True)
    drawing = State()
    idle.to(drawing, cond="go")
    drawing.to(idle, cond="not go")

    def during_drawing(self) -> None:
        self.X_out = self.X_out_p + self.inc
        self.path.append(self.X_out)


def test_declarations_are_listed_with_kind_unit_default_and_doc():
    rows = [(d.kind, d.name, d.unit, d.default, d.doc) for d in Pen.declarations()]
    assert rows == [
        ("input", "go", "bool", False, "start drawing"),
        ("input", "inc", "m", 0.001, "step per tick"),
        ("output", "X_out", "m", 0.0, "tool X"),
        ("output", "fr_sw", "bool", False, "fast filter"),
        ("local", "path", "m", [0.0], "points drawn"),
    ]


def test_data_are_attributes_with_their_defaults_and_a_snapshot():
    pen = Pen(data={"inc": 0.5})
    assert pen.go is False and pen.inc == 0.5 and pen.X_out == 0.0 and pen.X_out_p == 0.0
    assert pen.snapshot() == {"go": False, "inc": 0.5, "X_out": 0.0, "fr_sw": False, "path": [0.0]}
    assert pen.snapshot(("output",)) == {"X_out": 0.0, "fr_sw": False}


def test_previous_output_is_the_value_one_chart_tick_earlier():
    pen = Pen(data={"inc": 1.0})
    pen.set_inputs(go=True)
    pen.tick()  # idle -> drawing
    seen = []
    for _ in range(3):
        pen.tick()
        seen.append((pen.X_out_p, pen.X_out))
    assert seen == [(0.0, 1.0), (1.0, 2.0), (2.0, 3.0)]
    pen.X_out = 10.0  # someone else writes the output between ticks
    pen.tick()
    assert (pen.X_out_p, pen.X_out) == (10.0, 11.0)
    assert pen.previous_outputs() == {"X_out": 10.0, "fr_sw": False}


class Stamp(TickChart):
    """An event's action writes the output: ``stamp`` sets X to the tick it was handled at."""

    outputs = (Data("X", "1", 0, "tick of the last stamp"),)

    waiting = State(initial=True)
    stamped = State()
    stamp = waiting.to(stamped, on="write") | stamped.to(stamped, on="write")

    def write(self) -> None:
        self.X = self.tick_count


def test_a_tick_with_a_posted_event_counts_and_copies_previous_values_before_the_event():
    chart = Stamp()
    chart.tick()
    chart.tick()  # two quiet ticks
    chart.post("stamp")
    chart.tick()  # the third: X_p is copied before the event's action writes X
    assert (chart.tick_count, chart.X_p, chart.X) == (3, 0, 3)
    chart.post("stamp")
    chart.tick()
    assert (chart.tick_count, chart.X_p, chart.X) == (4, 3, 4)
    chart.tick()  # quiet again: the previous value catches up
    assert (chart.tick_count, chart.X_p, chart.X) == (5, 4, 4)
    assert chart.ticks_in("stamped") == 1


def test_reset_data_restores_defaults_and_mutable_defaults_are_not_shared():
    a, b = Pen(), Pen()
    a.go = True
    a.tick()
    a.tick()
    assert a.path == [0.0, 0.001] and b.path == [0.0]
    a.reset_data(("local",))
    assert a.path == [0.0] and a.go is True
    a.reset_data()
    assert a.go is False and a.X_out == 0.0 and a.X_out_p == 0.0


def test_unknown_data_names_are_refused():
    pen = Pen()
    with pytest.raises(UnknownDataError, match="declares no input named X_out"):
        pen.set_inputs(X_out=1.0)
    with pytest.raises(UnknownDataError, match="spped"):
        Pen(data={"spped": 1.0})


def _define(**attrs):
    body = {"a": State(initial=True), "b": State()}
    body["a"].to(body["b"])
    body.update(attrs)
    return type("Bad", (TickChart,), body)


@pytest.mark.parametrize("attrs, message", [
    ({"inputs": (Data("a", "1", 0),)}, "also a state"),
    ({"inputs": (Data("x", "1", 0),), "local": (Data("x", "1", 0),)}, "already declared"),
    ({"inputs": (Data("tick", "1", 0),)}, "clashes with the chart attribute"),
    ({"outputs": (Data("y", "1", 0),), "inputs": (Data("y_p", "1", 0),)}, "already declared"),
    ({"inputs": (Data("2x", "1", 0),)}, "not a Python identifier"),
    ({"local": (Data("model", "1", 0),)}, "used by the chart itself"),
    ({"inputs": ("x",)}, "is not a Data"),
    ({"during_c": lambda self: None}, "no state 'c'"),
])
def test_definition_errors_say_what_and_where(attrs, message):
    with pytest.raises(ChartDefinitionError, match=message):
        _define(**attrs)


def test_states_cannot_be_overwritten():
    pen = Pen()
    with pytest.raises(Exception, match="State overriding is not allowed"):
        pen.idle = 3
    assert pen.idle.id == "idle" and Pen.idle.id == "idle" and pen.idle.is_active
    pen.X_out = 0.5  # data are plain attributes
    assert pen.X_out == 0.5


def test_nested_states_cannot_be_overwritten_and_events_stay_callable():
    from tests.runtime.test_chart_clock import Lamp

    lamp = Lamp()
    for name in ("on", "dim", "bright", "off"):
        with pytest.raises(Exception, match="State overriding is not allowed"):
            setattr(lamp, name, 1)
    lamp.button()  # an event is still a method of the instance
    assert lamp.on.is_active and lamp.dim.is_active and not lamp.bright.is_active
