"""Conformance: "Process Events in States Containing Inner Transitions" (Stateflow semantic examples).

https://mathworks.com/help/stateflow/ug/inner-transition-examples.html
(mirrors read: uk/de/jp.mathworks.com, docs.exponenta.ru (ru), tatmou.com (zh); Chinese
translation http://coloradmin.cn/o/1864724.html; 2002 edition:
http://www.ece.northwestern.edu/CFS/local-apps/matlabhelp/toolbox/stateflow/semant33.html (inner
transition in an OR state), .../semant34.html (inner transition to a connective junction))

Three examples, the first two in parts:

- Process Events with an Inner Transition in an Exclusive (OR) State: Process One Event, a Second
  Event, a Third Event;
- Process Events with an Inner Transition to a Connective Junction: Process the First Event, a
  Second Event;
- Inner Transition to a History Junction.

Limits of what could be read: every stored copy ends inside "Process a Third Event" (its first
line) or inside the junction example's second event (2002 page).  The third event, the end of the
junction example and the history-junction example follow the MathWorks text as remembered and the
execution workflow (flagged in README.md).
"""

from statemachine import HistoryState, State

from ttt_sm.runtime import Data, Junction, TickChart

from ._log import act

URL = "https://mathworks.com/help/stateflow/ug/inner-transition-examples.html"


class InnerInOrState(TickChart):
    """A (default) and B, top-level OR states.  <URL above>

    - A -> B ``E_one[C_one]/A_one`` (outer);
    - A's inner transition ``E_one/A_two`` (a self-loop drawn inside A; the narrative: "the inner
      transition action A_two");
    - B -> A ``E_two[C_two]/A_three``;
    - B's self-loop ``E_two/A_four`` (third event: "active state B has a valid self-loop").

    Reading choices: the narrative names the actions but not the events of the inner transition
    and of B's self-loop; E_one and E_two are the reading consistent with the three events.  B's
    outer transitions are tried in the order written: B -> A first, then the self-loop.
    """

    local = (
        Data("log", "list", [], "actions in the order they ran"),
        Data("C_one", "bool", False, "condition C_one"),
        Data("C_two", "bool", False, "condition C_two"),
    )

    A = State(initial=True)
    B = State()

    E_one = A.to(B, cond="C_one", on="A_one") | A.to.itself(internal=True, on="A_two")
    E_two = B.to(A, cond="C_two", on="A_three") | B.to.itself(on="A_four")

    on_enter_A = act("entA")
    during_A = act("durA")
    on_exit_A = act("exitA")
    on_enter_B = act("entB")
    during_B = act("durB")
    on_exit_B = act("exitB")
    A_one = act("A_one")
    A_two = act("A_two")
    A_three = act("A_three")
    A_four = act("A_four")


def test_first_event_takes_the_inner_transition_after_the_during_action_without_leaving_A():
    """Process One Event in an Exclusive (OR) State.  <URL above>

    A active, C_one false, E_one: the root sees A -> B but it is not valid ([C_one] false); A's
    during action runs; A then checks for a valid transition inside it and finds the inner one;
    A stays active and the inner transition's action A_two runs; A's exit and entry actions do
    not run.
    """
    chart = InnerInOrState()
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["durA", "A_two"]
    assert chart.active_ids == frozenset({"A"})


def test_second_event_takes_the_outer_transition_first_and_runs_no_during_action():
    """Process a Second Event in an Exclusive (OR) State.  <URL above>

    A still active, C_one now true, E_one: the root finds A -> B valid; A's exit action, A
    inactive, the transition action A_one, B active, B's entry action.  A's during action and the
    inner transition do not run: the outer transition was taken first.
    """
    chart = InnerInOrState()
    chart.C_one = True
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["exitA", "A_one", "entB"]
    assert chart.active_ids == frozenset({"B"})


def test_third_event_takes_the_self_loop_which_exits_and_reenters_B():
    """Process a Third Event in an Exclusive (OR) State.  <URL above>

    B active, C_two false, E_two: the root sees B -> A, not valid ([C_two] false); B's self-loop
    is valid: B's exit action, B inactive, the self-loop's transition action A_four, B active
    again, B's entry action.  Unlike an inner transition, a self-loop exits and re-enters.
    """
    chart = InnerInOrState()
    chart.C_one = True
    chart.send("E_one")
    chart.C_one = False
    chart.log.clear()
    chart.send("E_two")
    assert chart.log == ["exitB", "A_four", "entB"]
    assert chart.active_ids == frozenset({"B"})


class InnerToAJunction(TickChart):
    """A {A1 (default), A2, A3, junction j}; an inner transition of A goes to j.  <URL above>

    From j, in this order: ``[C_one]`` to A1, ``[C_two]`` to A2, unlabelled to A3 (the 2002
    text: the segments with a condition are evaluated before the unlabelled one).  The inner
    transition is labelled ``E_one`` (the narrative names no event on it; E_one is the event of
    both parts).  A1..A3 have during actions, so the tests also check that the children do not
    execute once A has taken its inner transition.
    """

    local = (
        Data("log", "list", [], "actions in the order they ran"),
        Data("C_one", "bool", False, "condition to A1"),
        Data("C_two", "bool", False, "condition to A2"),
    )

    class A(State.Compound):
        A1 = State(initial=True)
        A2 = State()
        A3 = State()
        j = Junction()
        j.to(A1, cond="C_one")
        j.to(A2, cond="C_two")
        j.to(A3)

    E_one = A.to(A.j, internal=True)

    on_enter_A = act("entA")
    during_A = act("durA")
    on_exit_A = act("exitA")
    on_enter_A1 = act("entA1")
    during_A1 = act("durA1")
    on_exit_A1 = act("exitA1")
    on_enter_A2 = act("entA2")
    during_A2 = act("durA2")
    on_exit_A2 = act("exitA2")
    on_enter_A3 = act("entA3")
    during_A3 = act("durA3")


def test_first_event_an_inner_transition_through_a_junction_moves_between_substates():
    """Process the First Event with an Inner Transition to a Connective Junction.  <URL above>

    A.A1 active, C_two true, E_one: no valid transition at the root level; A's during action;
    A checks itself and finds the inner transition to the junction; of the junction's segments
    [C_two] holds, so the path to A.A2 is valid: A1's exit action, A1 inactive, A2 active, A2's
    entry action.  A is neither exited nor entered.
    """
    chart = InnerToAJunction()
    chart.C_two = True
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["durA", "exitA1", "entA2"]
    assert chart.active_ids == frozenset({"A", "A2"})


def test_second_event_the_inner_transition_to_the_active_substate_exits_and_reenters_it():
    """Process a Second Event with an Inner Transition to a Connective Junction.  <URL above>

    Continuing: A.A2 active, C_two still true, E_one again: A's during action; the inner
    transition through the junction to A2 is valid again, so A2 is exited and entered again
    (exitA2, A2 inactive, A2 active, entA2).
    """
    chart = InnerToAJunction()
    chart.C_two = True
    chart.send("E_one")
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["durA", "exitA2", "entA2"]
    assert chart.active_ids == frozenset({"A", "A2"})


class InnerToHistory(TickChart):
    """A {H, A1 (default), A2}, inner transition of A to its history junction on E_one.

    <URL above>  A1 <-> A2 on E_two are added so that A has a history to remember (the example
    itself starts with A1 active).
    """

    local = (Data("log", "list", [], "actions in the order they ran"),)

    class A(State.Compound):
        h = HistoryState()
        A1 = State(initial=True)
        A2 = State()
        E_two = A1.to(A2) | A2.to(A1)

    E_one = A.to(A.h, internal=True)

    on_enter_A = act("entA")
    during_A = act("durA")
    on_exit_A = act("exitA")
    on_enter_A1 = act("entA1")
    during_A1 = act("durA1")
    on_exit_A1 = act("exitA1")
    on_enter_A2 = act("entA2")


def test_an_inner_transition_to_the_history_junction_exits_and_reenters_the_last_active_substate():
    """Inner Transition to a History Junction.  <URL above>

    A.A1 active (A is active, so its history holds A1), E_one: no valid transition at the root;
    A's during action; A finds its inner transition to the history junction valid; the history
    junction names the last active substate, A1, as the destination: A1's exit action, A1
    inactive, A1 active, A1's entry action.  A is not exited.
    """
    chart = InnerToHistory()
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["durA", "exitA1", "entA1"]
    assert chart.active_ids == frozenset({"A", "A1"})
