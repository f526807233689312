"""Conformance: "Evaluate Transitions" (Stateflow).

https://mathworks.com/help/stateflow/ug/evaluate-transitions.html
(mirrors: uk/de/fr/nl/jp.mathworks.com; the textual form of its flow chart is the 2002 "Executing a
Set of Flow Graphs", http://priede.bf.lu.lv/kurvis/Datorlietas/statistika/MatLab/toolbox/stateflow/semant17.html)

The page is a workflow (a flow chart, figure missing) plus three topics: the transition evaluation
order (explicit order numbers 1, 2, ... from a source; implicit ordering for C charts), and a
"Transition to the Inner Edge of a Parent State" example.  The evaluation order of this API is the
explicit one: transitions from one source are tried in the order they are written.  Implicit
ordering (hierarchy, label kind, clock position) cannot be expressed and is not tested.

Except for the inner-edge example, the tests below check rules the page states (a valid transition
is one whose conditions hold and whose path ends at a state; the first valid transition in order
is taken; condition actions run as their segment is tested; a dead end backs up to try the next
segment).
"""

import pytest
from statemachine import State

from ttt_sm.runtime import Data, Junction, TickChart

from ._log import act

URL = "https://mathworks.com/help/stateflow/ug/evaluate-transitions.html"


class ThreeWays(TickChart):
    """A has three outgoing transitions on E, numbered in the order written.  <URL above>

    1: E[c1]{ca1} -> B     2: E[c2]{ca2} -> C     3: E{ca3} -> D
    """

    local = (
        Data("log", "list", [], "actions in the order they ran"),
        Data("c1", "bool", False, "condition of transition 1"),
        Data("c2", "bool", False, "condition of transition 2"),
    )

    A = State(initial=True)
    B = State()
    C = State()
    D = State()
    E = A.to(B, cond="c1", before="ca1") | A.to(C, cond="c2", before="ca2") | A.to(D, before="ca3")

    on_exit_A = act("exitA")
    on_enter_B = act("entB")
    on_enter_C = act("entC")
    on_enter_D = act("entD")
    ca1 = act("ca1")
    ca2 = act("ca2")
    ca3 = act("ca3")


def test_outgoing_transitions_are_tested_in_their_order_and_the_first_valid_one_is_taken():
    """Transition Evaluation Order: the number near a transition's source is its order; the chart
    tests 1, then 2, ...  With c1 false and c2 true, transition 1 fails (its condition action does
    not run), transition 2 is valid and taken, transition 3 is never tested."""
    chart = ThreeWays()
    chart.log.clear()
    chart.c2 = True
    chart.send("E")
    assert chart.log == ["ca2", "exitA", "entC"]
    assert chart.active_ids == frozenset({"C"})


def test_no_transition_after_the_first_valid_one_is_tested():
    """With c1 and c2 both true, transition 1 is taken; transition 2's condition action never
    runs."""
    chart = ThreeWays()
    chart.log.clear()
    chart.c1 = True
    chart.c2 = True
    chart.send("E")
    assert chart.log == ["ca1", "exitA", "entB"]
    assert chart.active_ids == frozenset({"B"})


class DeadEndThenState(TickChart):
    """1: E{ca1} -> junction j with no way out (a terminal junction); 2: E -> B.  <URL above>"""

    local = (Data("log", "list", [], "actions in the order they ran"),)

    A = State(initial=True)
    B = State()
    j = Junction()
    E = A.to(j, before="ca1") | A.to(B)

    on_exit_A = act("exitA")
    on_enter_B = act("entB")
    ca1 = act("ca1")


def test_a_path_that_does_not_end_at_a_state_is_not_a_valid_transition():
    """Rule (first paragraph of the page): a valid transition is one whose conditions are true AND
    whose path ends at a state.  Transition 1 ends at a terminal junction, so after its condition
    action ran (condition actions run when their segment is tested and are not undone) evaluation
    goes back to A and tries transition 2, which is valid."""
    chart = DeadEndThenState()
    chart.log.clear()
    chart.send("E")
    assert chart.log == ["ca1", "exitA", "entB"]
    assert chart.active_ids == frozenset({"B"})


class BacktrackToSource(TickChart):
    """1: E{ca_a} -> j;  j [c2] -> B;  j [c3] -> C;  2: E -> D.  <URL above>"""

    local = (
        Data("log", "list", [], "actions in the order they ran"),
        Data("c2", "bool", False, "condition of j's first segment"),
        Data("c3", "bool", False, "condition of j's second segment"),
    )

    A = State(initial=True)
    B = State()
    C = State()
    D = State()
    j = Junction()
    E = A.to(j, before="ca_a") | A.to(D)
    j.to(B, cond="c2")
    j.to(C, cond="c3")

    on_exit_A = act("exitA")
    on_enter_B = act("entB")
    on_enter_C = act("entC")
    on_enter_D = act("entD")
    ca_a = act("ca_a")


def test_when_every_segment_out_of_a_junction_fails_evaluation_backs_up_to_the_next_one():
    """Rule (the evaluation workflow; 2002 "Executing a Set of Flow Graphs"): when no outgoing
    segment of a junction is valid, the chart backs up to the previous junction or source and tests
    its next segment.  Both of j's segments fail, so the chart returns to A and takes A -> D; the
    condition action of the abandoned segment has already run."""
    chart = BacktrackToSource()
    chart.log.clear()
    chart.send("E")
    assert chart.log == ["ca_a", "exitA", "entD"]
    assert chart.active_ids == frozenset({"D"})


class EventFilter(TickChart):
    """1: E_one -> B;  2: [c] -> C (no trigger).  <URL above>"""

    local = (
        Data("log", "list", [], "actions in the order they ran"),
        Data("c", "bool", True, "condition of transition 2"),
    )

    A = State(initial=True)
    B = State()
    C = State()
    E_one = A.to(B)
    A.to(C, cond="c")
    E_two = B.to(A)  # unused; declares the event E_two

    on_exit_A = act("exitA")
    on_enter_B = act("entB")
    on_enter_C = act("entC")


def test_a_transition_triggered_by_another_event_is_not_valid_and_an_untriggered_one_is():
    """Rule (label format; a transition's trigger must match the event being processed, a
    transition without a trigger is valid for any event): on E_two, transition 1 (E_one) is not
    valid, transition 2 (no trigger, [c] true) is taken."""
    chart = EventFilter()
    chart.log.clear()
    chart.send("E_two")
    assert chart.log == ["exitA", "entC"]
    assert chart.active_ids == frozenset({"C"})


@pytest.mark.xfail(
    strict=False,
    reason="the API has no documented spelling for a transition that ends on the inner edge of its "
    "own parent; written here as P.B.to(P, internal=True)",
)
def test_a_transition_to_the_inner_edge_of_the_parent_follows_the_parent_default_path_at_once():
    """Transition to the Inner Edge of a Parent State.  The transition from B ends on the inside
    edge of its parent: that is a shortcut back to the parent's default path, which is followed in
    the same time step (here to A).  The parent stays active; its exit and entry actions do not
    run.

    The chart class is built inside the test: python-statemachine rejects the spelling at class
    creation, and a module-level failure would hide every other test of this file.
    """

    class InnerEdgeOfParent(TickChart):
        """P{A (default), B}; A -> B on E_one; B -> inner edge of P on E_two.  <URL above>"""

        local = (Data("log", "list", [], "actions in the order they ran"),)

        class P(State.Compound):
            A = State(initial=True)
            B = State()
            E_one = A.to(B)

        E_two = P.B.to(P, internal=True)   # a transition that ends on P's inside edge

        on_enter_P = act("entP")
        on_exit_P = act("exitP")
        on_enter_A = act("entA")
        on_exit_A = act("exitA")
        on_enter_B = act("entB")
        on_exit_B = act("exitB")

    chart = InnerEdgeOfParent()
    chart.send("E_one")
    chart.log.clear()
    chart.send("E_two")
    assert chart.log == ["exitB", "entA"]
    assert chart.active_ids == frozenset({"P", "A"})
