"""A buffered chart: its numbers in one float buffer, read and written by name and in place."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest
from statemachine import State

from ttt_sm.runtime import Data, TickChart, UnknownDataError


def _declared() -> dict[str, object]:
    return dict(
        inputs=(Data("go", "bool", False, "start counting"), Data("inc", "m", 0.25, "step per tick")),
        outputs=(Data("X_out", "m", 0.0, "tool X"), Data("n", "1", 0, "ticks counted"),
                 Data("note", "text", "", "what happened")),
        local=(Data("limit", "m", 1.0, "stop counting here"), Data("path", "m", [0.0], "points")),
    )


class Counter(TickChart):
    """Counts X_out up by ``inc`` per tick while ``go``, until ``limit``."""

    inputs, outputs, local = _declared().values()

    idle = State(initial=True)
    counting = State()
    full = State()
    idle.to(counting, cond="go")
    counting.to(full, cond="X_out >= limit", on="say_full")
    counting.to(idle, cond="not go")
    full.to(idle, cond="not go")

    def during_counting(self) -> None:
        self.X_out = self.X_out_p + self.inc
        self.n = self.n_p + 1
        self.path.append(self.X_out)

    def say_full(self) -> None:
        self.note = f"full after {self.n} ticks"


class BufferedCounter(Counter):
    """The same chart with its numbers in a buffer."""

    buffered = True


def test_the_numbers_have_places_in_the_buffer_and_the_rest_stays_attributes():
    chart = BufferedCounter()
    slots = chart.data_slots()
    # numbers and flags, each output with its previous value; text and lists are not numbers
    assert list(slots) == ["go", "inc", "X_out", "X_out_p", "n", "n_p", "limit"]
    buffer = np.frombuffer(chart.data_buffer(), dtype=np.float64)
    assert buffer.tolist() == [0.0, 0.25, 0.0, 0.0, 0.0, 0.0, 1.0]
    chart.inc = 0.5
    assert buffer[slots["inc"]] == 0.5
    buffer[slots["limit"]] = 3.0  # compiled code writes in place: the chart reads it
    assert chart.limit == 3.0
    buffer[slots["go"]] = 1.0
    assert chart.go is True
    buffer[slots["n"]] = 7.0
    assert chart.n == 7 and type(chart.n) is int
    assert chart.note == "" and chart.path == [0.0] and "note" in vars(chart)
    with pytest.raises(TypeError, match="the chart is not buffered"):
        Counter().data_buffer()


def test_a_buffered_chart_runs_as_its_unbuffered_twin():
    plain, buffered = Counter(data={"limit": 2.0}), BufferedCounter(data={"limit": 2.0})
    assert plain.snapshot() == buffered.snapshot()
    rng = random.Random(3)
    for _ in range(300):
        go = rng.random() < 0.8
        for chart in (plain, buffered):
            chart.set_inputs(go=go)
            chart.tick()
        assert plain.active_ids == buffered.active_ids
        assert plain.snapshot() == buffered.snapshot()
        assert plain.previous_outputs() == buffered.previous_outputs()
    assert buffered.note.startswith("full after") and buffered.n > 0


def test_data_of_a_buffered_chart_are_set_reset_and_checked_by_name():
    chart = BufferedCounter(data={"go": True, "X_out": 0.75})
    assert chart.go is True and chart.X_out == 0.75 and chart.X_out_p == 0.75
    chart.set_inputs(inc=2.0)
    assert chart.data_mapping()["inc"] == 2.0
    with pytest.raises(UnknownDataError, match="BufferedCounter declares no input named X_out"):
        chart.set_inputs(X_out=1.0)
    with pytest.raises(TypeError, match=r"BufferedCounter\.limit is a number in the chart's data buffer; got 'far'"):
        chart.limit = "far"
    assert chart.limit == 1.0  # the refused value left it as it was
    chart.limit = math.nan
    assert math.isnan(chart.limit)
    chart.reset_data()
    assert chart.snapshot() == BufferedCounter().snapshot()
    view = chart.data_mapping()
    assert "n_p" in view and "note" in view and "nothing" not in view
    assert set(view) >= {"go", "inc", "X_out", "X_out_p", "n", "n_p", "limit", "note", "path"}


def test_each_instance_has_its_own_buffer():
    a, b = BufferedCounter(), BufferedCounter()
    a.inc = 9.0
    assert b.inc == 0.25
    assert a.data_buffer() is not b.data_buffer()
