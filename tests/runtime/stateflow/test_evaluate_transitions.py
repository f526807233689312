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
    """1: E{ca1} -> junction j with no way out (a terminal junction); 2: E -> B.  A has a during action.
    <URL above>"""

    local = (Data("log", "list", [], "actions in the order they ran"),)

    A = State(initial=True)
    B = State()
    j = Junction()
    E = A.to(j, before="ca1") | A.to(B)

    on_exit_A = act("exitA")
    on_enter_B = act("entB")
    during_A = act("durA")
    ca1 = act("ca1")


def test_a_path_that_ends_at_a_terminal_junction_ends_the_evaluation_without_leaving_the_state():
    """Rule (first paragraph of the page): a valid transition is one whose conditions are true AND
    whose path ends at a state, so transition 1 takes no state transition.  Its path is complete,
    though: MathWorks' "Unexpected backtracking" diagnostic page advises an unconditional segment to
    a terminal junction precisely to stop backtracking, "Create Flow Charts in Stateflow" says a flow
    chart ends at a terminating junction, and "Modeling Guidelines for Stateflow Charts" counts a
    path to a terminating junction as complete.  So evaluation stops there: transition 2 is not
    tried, A is not left and goes on with its during action (the execution workflow's step after
    the outer transitions).  (Read first as backtracking on to transition 2; settled by those pages.)
    https://ww2.mathworks.cn/help/simulink/gui/unexpected-backtracking.html
    https://mathworks.com/help/stateflow/ug/flow-charts-in-stateflow.html"""
    chart = DeadEndThenState()
    chart.log.clear()
    chart.send("E")
    assert chart.log == ["ca1", "durA"]
    assert chart.active_ids == frozenset({"A"})


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


def test_a_transition_to_the_inner_edge_of_the_parent_follows_the_parent_default_path_at_once():
    """Transition to the Inner Edge of a Parent State.  The transition from B ends on the inside
    edge of its parent: that is a shortcut back to the parent's default path, which is followed in
    the same time step (here to A).  The parent stays active; its exit and entry actions do not
    run.

    python-statemachine refuses a transition from a state to its own parent's inner edge
    (``P.B.to(P, internal=True)``); the runtime writes the parent's default transition as an initial
    junction, and the transition to the inner edge as one to that junction (docs/runtime.md).
    """

    class InnerEdgeOfParent(TickChart):
        """P{A (default), B}; A -> B on E_one; B -> inner edge of P on E_two.  <URL above>"""

        local = (Data("log", "list", [], "actions in the order they ran"),)

        class P(State.Compound):
            start = Junction(initial=True)   # P's default transition, through a junction
            A = State()
            B = State()
            start.to(A)
            E_one = A.to(B)
            E_two = B.to(start)              # ends on P's inside edge: P's default path again

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
