"""The Stateflow clock of TickChart: quiet ticks, one wake-up per tick, execution order, events."""

from __future__ import annotations

import pytest
from statemachine import State

from ttt_sm.runtime import (
    Data,
    TickChart,
    UnknownEventError,
)


class Lamp(TickChart):
    """A lamp with a dimmer: ``on`` nests ``dim`` and ``bright``."""

    inputs = (
        Data("switch", "bool", False, "wall switch"),
        Data("bright_req", "bool", False, "dimmer turned up"),
    )
    outputs = (Data("level", "1", 0.0, "light level"),)
    local = (Data("presses", "1", 0, "button presses seen"),)

    off = State(initial=True)

    class on(State.Compound):
        dim = State(initial=True)
        bright = State()
        dim.to(bright, cond="bright_req")
        bright.to(dim, cond="not bright_req")

        def during_dim(self) -> None:
            self.level = self.level_p + 1
            self.calls.append("during dim")

        def during_bright(self) -> None:
            self.level = self.level_p + 10

    off.to(on, cond="switch", on="count_on")
    on.to(off, cond="not switch")
    button = off.to(on) | on.to(off)

    def __init__(self, **kwargs):
        self.calls: list[str] = []
        super().__init__(**kwargs)

    def count_on(self) -> None:
        self.calls.append("count_on")

    def on_enter_on(self) -> None:
        self.calls.append("enter on")

    def on_exit_off(self) -> None:
        self.calls.append("exit off")

    def on_button(self, presses: int = 1) -> None:
        self.presses += presses

    def during_on(self) -> None:
        self.calls.append("during on")


class SendSpy:
    """Counts the chart's calls to ``send`` without changing them."""

    def __init__(self, chart: TickChart) -> None:
        self.events: list[str] = []
        original = chart.send

        def send(event, *args, **kwargs):
            self.events.append(event)
            return original(event, *args, **kwargs)

        chart.send = send  # instance attribute shadows the method


class TransitionSpy:
    """A python-statemachine listener recording the transitions taken."""

    def __init__(self) -> None:
        self.taken: list[tuple[str, str]] = []

    def after_transition(self, source, target) -> None:
        self.taken.append((source.id, target.id))


def test_quiet_tick_runs_during_actions_and_never_calls_send():
    lamp = Lamp(start_value="dim")
    lamp.switch = True  # no guard holds: on stays on, dim stays dim
    lamp.calls.clear()
    spy = SendSpy(lamp)
    for _ in range(5):
        assert lamp.tick() is None
    assert spy.events == []
    assert lamp.level == 5
    # outermost first: during_on of the parent before during_dim of the child
    assert lamp.calls == ["during on", "during dim"] * 5


def test_a_guard_that_holds_takes_one_transition_without_the_librarys_send():
    listener = TransitionSpy()
    lamp = Lamp(listeners=[listener])
    spy = SendSpy(lamp)
    lamp.switch = True
    lamp.bright_req = True  # dim -> bright would also hold, but only next tick
    taken = lamp.tick()
    assert taken is not None and (taken.source.id, taken.target.id) == ("off", "on")
    assert listener.taken == [("off", "on")]
    assert lamp.configuration_values == {"on", "dim"}
    assert lamp.calls == ["exit off", "count_on", "enter on"]  # exit, transition, entry
    assert spy.events == []  # the runtime takes it itself: exit, transition action, entry, listeners
    assert lamp.level == 0  # no during action in a tick that took a transition
    lamp.tick()
    assert listener.taken == [("off", "on"), ("dim", "bright")]
    assert lamp.configuration_values == {"on", "bright"}


def test_parent_outer_transition_beats_the_childs():
    lamp = Lamp(start_value="dim")
    lamp.switch = False  # on -> off holds
    lamp.bright_req = True  # dim -> bright holds too
    taken = lamp.tick()
    assert (taken.source.id, taken.target.id) == ("on", "off")
    assert lamp.configuration_values == {"off"}


class Order(TickChart):
    """Transitions of one state tried in declaration order; outer before inner."""

    inputs = (Data("go", "bool", False, "enable"),)

    class box(State.Compound):
        a = State(initial=True)
        b = State()
        c = State()
        a.to(b, cond="go")
        a.to(c, cond="go")

    done = State()
    box.to(box.c, cond="go", internal=True)  # inner: declared first, tried after the outer one
    box.to(done, cond="go")
    done.to(box)


def test_within_a_state_outer_transitions_first_then_declaration_order():
    chart = Order()
    structure = Order.structure()
    order = [(t.target, t.scope, t.priority) for t in structure.tick_by_state["box"]]
    # outer and inner transitions are tried in different phases: each group has its own order
    assert order == [("done", "outer", 1), ("c", "inner", 1)]
    chart.go = True
    assert chart.tick().target.id == "done"
    chart.tick()  # done -> box (unguarded)
    chart.go = False
    chart.tick()
    chart.go = True
    # box's own outer transition wins over its inner one and over a's
    assert chart.tick().target.id == "done"


def test_within_a_leaf_the_first_declared_transition_wins():
    chart = Order(start_value="a")
    chart.__dict__["go"] = True
    plan = chart._build_plan()
    candidates = [getattr(chain[-1], phase)[i].target.id for chain, phase, i in plan.resume]
    assert candidates == ["done", "c", "b", "c"]  # box: outer, inner; then a: in order


class Toggle(TickChart):
    """Only events move it: button toggles, with the presses it carries."""

    local = (Data("presses", "1", 0, "button presses seen"),)
    off = State(initial=True)
    on = State()
    button = off.to(on) | on.to(off)

    def on_button(self, presses: int = 1) -> None:
        self.presses += presses


def test_events_posted_between_ticks_are_handled_at_the_next_tick_in_order_with_data():
    toggle = Toggle()
    toggle.post("button", presses=2)
    toggle.post("button", presses=3)
    assert toggle.configuration_values == {"off"}  # nothing until the tick
    assert [e for e, _ in toggle.pending_events] == ["button", "button"]
    toggle.tick()  # one wake-up per event, in order
    assert toggle.pending_events == []
    assert toggle.presses == 5  # both, in order: off -> on (2), on -> off (3)
    assert toggle.configuration_values == {"off"}


def test_a_tick_with_a_posted_event_is_one_wake_up_on_it_where_eventless_transitions_compete():
    lamp = Lamp()
    lamp.bright_req = True
    lamp.switch = True
    lamp.post("button")
    # off's transitions in the order written: [switch] (no event, valid on any wake-up) before button
    taken = lamp.tick()
    assert (taken.source.id, taken.target.id) == ("off", "on")
    assert [str(e) for e in taken.events][0].startswith("_tick_off_")
    assert lamp.calls == ["exit off", "count_on", "enter on"] and lamp.presses == 0
    assert lamp.configuration_values == {"on", "dim"}  # one wake-up: dim -> bright waits for the next
    taken = lamp.tick()
    assert (taken.source.id, taken.target.id) == ("dim", "bright")


def test_an_event_posted_by_an_action_waits_for_the_next_tick():
    class Relay(TickChart):
        a = State(initial=True)
        b = State()
        c = State()
        go = a.to(b)
        more = b.to(c)

        def on_go(self) -> None:
            self.post("more")

    relay = Relay()
    relay.post("go")
    relay.tick()
    assert relay.configuration_values == {"b"}
    relay.tick()
    assert relay.configuration_values == {"c"}


def test_unknown_event_is_refused_when_posted():
    lamp = Lamp()
    with pytest.raises(UnknownEventError, match="no transition handles event 'buton'"):
        lamp.post("buton")
    assert lamp.handles("button") and not lamp.handles("tick")


def test_a_guard_is_evaluated_once_per_try():
    class Counting(TickChart):
        a = State(initial=True)
        b = State()
        a.to(b, cond="flip")

        def __init__(self):
            self.n = 0
            super().__init__()

        def flip(self) -> bool:
            self.n += 1
            return self.n == 3

    chart = Counting()
    assert [chart.tick() is not None for _ in range(3)] == [False, False, True]
    assert chart.n == 3 and chart.configuration_values == {"b"}


def test_start_mid_way_and_ticks_count():
    lamp = Lamp(start_value="bright", tick_period_s=0.002)
    assert lamp.configuration_values == {"on", "bright"}
    lamp.bright_req = True
    lamp.switch = True
    assert lamp.run_ticks(3) == 0
    assert lamp.tick_count == 3 and lamp.time_s == pytest.approx(0.006)
    assert lamp.level == 30


def test_for_an_event_both_a_state_and_its_parent_handle_the_parents_outer_transition_wins():
    class Nested(TickChart):
        class outer(State.Compound):
            inner = State(initial=True)
            done = State()
            stop = inner.to(done)

        idle = State()
        stop = outer.to(idle)
        idle.to(outer)

    # Stateflow tries the outer transitions of the active states outermost first
    chart = Nested()
    chart.post("stop")
    chart.tick()
    assert chart.configuration_values == {"idle"}


def test_a_chain_of_guards_that_all_hold_is_walked_one_transition_per_tick():
    class Chain(TickChart):
        a = State(initial=True)
        b = State()
        c = State()
        a.to(b)
        b.to(c)

    listener = TransitionSpy()
    chain = Chain(listeners=[listener])
    chain.tick()
    assert chain.configuration_values == {"b"} and listener.taken == [("a", "b")]
    chain.tick()
    assert chain.configuration_values == {"c"} and listener.taken == [("a", "b"), ("b", "c")]
    assert chain.tick() is None


def test_active_ids_follow_the_configuration_through_ticks_sends_and_posted_events():
    lamp = Lamp()
    seen = []

    def check() -> None:
        assert lamp.active_ids == frozenset(lamp.configuration_values)
        seen.append(lamp.active_ids)

    check()  # before the first tick
    lamp.switch = True
    lamp.tick()
    check()  # a tick transition into the compound
    lamp.bright_req = True
    lamp.tick()
    check()
    lamp.send("button")  # a wake-up on the event now, between ticks
    check()
    lamp.post("button")
    lamp.tick()  # the wake-up on the posted event: off's [switch] first, into on.dim
    check()
    lamp.button()  # the library's own way of sending an event: a wake-up too
    check()
    assert seen == [frozenset({"off"}), frozenset({"on", "dim"}), frozenset({"on", "bright"}),
                    frozenset({"off"}), frozenset({"on", "dim"}), frozenset({"off"})]
