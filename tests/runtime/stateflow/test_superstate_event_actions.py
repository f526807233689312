"""Conformance: "Control Chart Execution by Using Event Actions in a Superstate" (Stateflow).

https://mathworks.com/help/stateflow/ug/event-actions-in-a-superstate-example.html
(mirror: https://uk.mathworks.com/help/stateflow/ug/event-actions-in-a-superstate-example.html)

The page has one narrated example.  Its figure is missing; the chart below is rebuilt from the
narrative: top-level states A and B, A holding A1 (default) and A2.  A has a during action durA
and an ``on E_three`` action A_one; A1 has a during action durA1.  The figure's other transitions
are not narrated; A1 -> A2 on E_one and A -> B on E_two are added so that "no valid transition
for E_three" is a real check (neither is triggered by E_three).
"""

from statemachine import State

from ttt_sm.runtime import Data, TickChart, action_on

from ._log import act

URL = "https://mathworks.com/help/stateflow/ug/event-actions-in-a-superstate-example.html"


class SuperstateEventAction(TickChart):
    """A superstate with a during action and an ``on E_three`` action.  <URL above>"""

    local = (Data("log", "list", [], "actions in the order they ran"),)

    class A(State.Compound):
        A1 = State(initial=True)
        A2 = State()
        E_one = A1.to(A2)

    B = State()

    E_two = A.to(B)
    E_three = action_on(A, "A_one")   # state A label:  on E_three: A_one();

    on_enter_A = act("entA")
    during_A = act("durA")
    on_exit_A = act("exitA")
    on_enter_A1 = act("entA1")
    during_A1 = act("durA1")
    on_exit_A1 = act("exitA1")
    on_enter_A2 = act("entA2")
    during_A2 = act("durA2")
    on_exit_A2 = act("exitA2")
    on_enter_B = act("entB")
    A_one = act("A_one")


def test_a_superstate_runs_its_during_action_then_its_on_event_action_then_the_child():
    """The chart sleeps with A.A1 active; E_three wakes it.

    Page (paraphrased): the root finds no transition valid for E_three; A's during action durA
    runs; then A's ``on E_three`` action A_one runs; A finds no valid transition among its
    children; A1's during action durA1 runs; the chart sleeps.  Nothing is exited or entered.
    """
    chart = SuperstateEventAction()
    chart.log.clear()
    chart.send("E_three")
    assert chart.log == ["durA", "A_one", "durA1"]
    assert chart.active_ids == frozenset({"A", "A1"})


def test_the_on_event_action_of_a_superstate_does_not_run_for_another_event():
    """Rule check derived from the same page (not a narrated example).

    An ``on E_three`` action runs only while the chart processes E_three.  On E_one, A runs durA
    (no outer transition is valid for E_one), then its child A1 takes A1 -> A2.
    """
    chart = SuperstateEventAction()
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["durA", "exitA1", "entA2"]
    assert chart.active_ids == frozenset({"A", "A2"})
