"""Guards compiled for the fast path agree with python-statemachine's own evaluation."""

from __future__ import annotations

import itertools

from statemachine import State

from ttt_sm.runtime import Data, TickChart
from ttt_sm.runtime.guards import compile_guard


def free_guard(machine) -> bool:
    return machine.a and machine.b


class Guards(TickChart):
    inputs = (
        Data("a", "bool", False, "first flag"),
        Data("b", "bool", False, "second flag"),
        Data("x", "m", 0.0, "a position"),
    )

    s = State(initial=True)

    class box(State.Compound):
        t = State(initial=True)
        u = State()
        t.to(u, cond="In('t') and a")
        u.to(t, unless="a")

    def both(self) -> bool:
        return self.a and self.b

    def sees(self, machine, source, target) -> bool:
        return machine is self and source.id == "s" and target.id == "box" and self.a

    @property
    def far(self) -> bool:
        return self.x > 1.0

    def wants_event(self, event_data) -> bool:  # needs the event: the library evaluates it
        return self.a

    s.to(box, cond="a")
    s.to(box, cond="a and not b")
    s.to(box, cond="!a ^ b")  # the library's operators: not a and b
    s.to(box, cond="x >= 2.5")
    s.to(box, cond="both")
    s.to(box, cond=both)
    s.to(box, cond="sees")
    s.to(box, cond="far")
    s.to(box, cond=lambda: True)
    s.to(box, cond=free_guard)
    s.to(box, cond=["a", "b"], unless="far")
    s.to(box, cond="wants_event")
    box.to(s)


def _library_says(chart, transition) -> bool:
    return chart._callbacks.all(
        transition.cond.key, machine=chart, model=chart.model, event=None, transition=transition,
        state=transition.source, source=transition.source, target=transition.target,
        event_data=None,
    )


def test_every_guard_form_agrees_with_the_library():
    chart = Guards(start_value="t")
    transitions = [info.transition for info in Guards.structure().transitions if info.kind == "tick"]
    for a, b, x in itertools.product([False, True], [False, True], [0.0, 2.0, 3.0]):
        chart.set_inputs(a=a, b=b, x=x)
        for t in transitions:
            guard, _fast = compile_guard(chart, t)
            holds = True if guard is None else bool(guard())
            assert holds == bool(_library_says(chart, t)), (t, a, b, x)


def test_guards_run_as_plain_calls_unless_they_need_the_event():
    paths = Guards().guard_paths()
    slow = [label for label, path in paths.items() if path == "library"]
    assert slow == ["s -> box: tick [wants_event]"]


def test_guards_read_data_live():
    chart = Guards()
    chart.a = True
    assert chart.tick().target.id == "box"
