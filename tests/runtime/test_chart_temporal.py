"""Temporal guards count chart ticks since the source state was entered."""

from __future__ import annotations

import pytest
from statemachine import State

from ttt_sm.runtime import Data, TemporalLogicError, TickChart, after, after_s
from ttt_sm.runtime.structure import states_entered_by


class Counter(TickChart):
    """Counts in ``counting``; leaves after 3 ticks; ``reset`` re-enters ``counting``."""

    outputs = (Data("n", "1", 0, "ticks counted"),)

    counting = State(initial=True)
    done = State()
    counting.to(done, cond=after(3))
    done.to(counting, cond=after_s(0.05))
    reset = counting.to.itself() | done.to(counting)

    def during_counting(self) -> None:
        self.n = self.n_p + 1


def test_after_n_fires_at_exactly_the_nth_tick():
    chart = Counter(tick_period_s=0.01)
    fired = [chart.tick() is not None for _ in range(5)]
    assert fired == [False, False, True, False, False]
    assert chart.configuration_values == {"done"}
    assert chart.n == 2  # during ran on the two quiet ticks


def test_after_s_counts_chart_ticks_times_the_period_not_wall_time():
    chart = Counter(tick_period_s=0.01, start_value="done")
    # 0.05 s at 0.01 s per tick is 5 ticks
    fired = [chart.tick() is not None for _ in range(6)]
    assert fired == [False, False, False, False, True, False]


def test_after_s_rounds_up_to_whole_ticks():
    chart = Counter(tick_period_s=0.02, start_value="done")  # 0.05 s -> 3 ticks (0.06 s)
    fired = [chart.tick() is not None for _ in range(3)]
    assert fired == [False, False, True]


def test_re_entering_the_state_restarts_the_count():
    chart = Counter(tick_period_s=0.01)
    chart.tick()
    chart.post("reset")  # self-transition: exit and enter counting, at tick 2
    taken = chart.tick()
    assert (taken.source.id, taken.target.id) == ("counting", "counting")
    assert chart.ticks_in("counting") == 0
    fired = [chart.tick() is not None for _ in range(3)]
    assert fired == [False, False, True]


def test_a_state_entered_by_an_event_counts_from_that_tick():
    chart = Counter(tick_period_s=0.01, start_value="done")
    chart.post("reset")
    chart.tick()  # done -> counting by the event, during this tick
    assert chart.ticks_in("counting") == 0
    fired = [chart.tick() is not None for _ in range(3)]
    assert fired == [False, False, True]


def test_after_s_needs_a_tick_period():
    chart = Counter(start_value="done")
    with pytest.raises(TemporalLogicError, match="tick_period_s"):
        chart.tick()


def test_bad_temporal_arguments_are_refused():
    with pytest.raises(TemporalLogicError):
        after(-1)
    with pytest.raises(TemporalLogicError):
        after(2.5)  # type: ignore[arg-type]
    with pytest.raises(TemporalLogicError):
        after_s(float("nan"))


def test_an_event_wake_up_tries_the_eventless_temporal_transition_first_when_it_is_written_first():
    chart = Counter(tick_period_s=0.01)
    chart.tick()
    chart.tick()
    chart.post("reset")  # tick 3: after(3) holds and is written before the reset self-transition
    taken = chart.tick()
    assert (taken.source.id, taken.target.id) == ("counting", "done")


class Phases(TickChart):
    """Nested states and the transition kinds whose entered states are tracked."""

    class outer(State.Compound):
        class mid(State.Compound):
            x = State(initial=True)
            y = State()
            to_y = x.to(y)

        z = State()
        to_z = mid.to(z)
        restart = mid.to.itself()
        inner_restart = mid.to.itself(internal=True)
        back = z.to(mid.y)

    idle = State()
    leave = outer.to(idle)
    enter_deep = idle.to(outer.mid.y)
    self_outer = outer.to.itself()
    loop = idle.to.itself(internal=True)


class EnteredSpy:
    def __init__(self) -> None:
        self.entered: list[str] = []

    def on_enter_state(self, state) -> None:
        self.entered.append(state.id)


@pytest.mark.parametrize("start, event", [
    ("x", "to_y"), ("x", "to_z"), ("y", "restart"), ("y", "inner_restart"), ("z", "back"),
    ("x", "leave"), ("idle", "enter_deep"), ("y", "self_outer"), ("idle", "loop"),
])
def test_entered_states_match_the_librarys_entry_actions(start, event):
    spy = EnteredSpy()
    chart = Phases(start_value=start, listeners=[spy])
    spy.entered.clear()
    seen: list[list[str]] = []

    class AfterSpy:
        def after_transition(self, machine, transition) -> None:
            seen.append(sorted(s.id for s in states_entered_by(machine, transition)))

    chart.add_listener(AfterSpy())
    chart.send(event)
    assert seen == [sorted(spy.entered)]
