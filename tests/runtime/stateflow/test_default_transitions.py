"""Conformance: "Control Chart Execution by Using Default Transitions" (Stateflow semantic examples).

https://mathworks.com/help/stateflow/ug/default-transition-examples.html
(mirrors read: uk/it/fr.mathworks.com; 2002 edition, one page per example, e.g.
"Default Transition and a History Junction Example":
http://www.ece.northwestern.edu/IT/local-apps/matlabhelp/toolbox/stateflow/semant30.html)

Four examples:

- Default Transition in Exclusive (OR) Decomposition (A -> superstate B, default to B.B1);
- Default Transition to a Junction (B's default goes through a junction; valid only when B is
  entered);
- Default Transition and a History Junction (B's history junction overrides its default);
- Labeled Default Transitions (B's default transition carries an event).

Limits of what could be read: the stored copies of the current page end inside "Default
Transition to a Junction" (its first three steps).  "Default Transition and a History Junction" is
read whole from the 2002 page (semant30).  The rest of "Default Transition to a Junction" and
"Labeled Default Transitions" follow the MathWorks text as remembered and the execution workflow
(flagged in README.md).
"""

from statemachine import HistoryState, State

from ttt_sm.runtime import Data, Junction, TickChart

from ._log import act

URL = "https://mathworks.com/help/stateflow/ug/default-transition-examples.html"


class DefaultInOrDecomposition(TickChart):
    """A (default) and B {B1 (default), B2}; A -> B labelled ``E_one/A``.  <URL above>

    The page calls the transition action ``A`` (step 4: "The transition action, A, is executed");
    a method cannot share the name of state A, so the method is ``ta_A`` and it logs ``A``.
    """

    local = (Data("log", "list", [], "actions in the order they ran"),)

    A = State(initial=True)

    class B(State.Compound):
        B1 = State(initial=True)
        B2 = State()
        E_two = B1.to(B2)

    E_one = A.to(B, on="ta_A")

    on_exit_A = act("exitA")
    on_enter_B = act("entB")
    on_enter_B1 = act("entB1")
    on_enter_B2 = act("entB2")
    ta_A = act("A")


def test_entering_a_superstate_by_its_border_follows_its_default_transition():
    """Default Transition in Exclusive (OR) Decomposition.  <URL above>

    A active, E_one: the root finds A -> B valid; A's exit action, A inactive, the transition
    action A, B active and B's entry action; B then finds its valid default transition to B.B1:
    B1 active and its entry action.
    """
    chart = DefaultInOrDecomposition()
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["exitA", "A", "entB", "entB1"]
    assert chart.active_ids == frozenset({"B", "B1"})


class DefaultToAJunction(TickChart):
    """A (default) and B {j0, B1, B2}; B's default transition goes to junction j0.  <URL above>

    j0 -> B1 ``[C_one]`` (1), j0 -> B2 ``[C_two]`` (2); A -> B ``E_one``.  The figure caption
    names top-level states A and B, B holding B1 and B2; which condition leads where is the
    reading consistent with the narrative (C_two true, yet B1 stays active).  All transitions
    between states are triggered by E_one, so the example's "an event occurs" (any other event)
    is written as a tick.
    """

    local = (
        Data("log", "list", [], "actions in the order they ran"),
        Data("C_one", "bool", True, "condition of the default path to B1"),
        Data("C_two", "bool", False, "condition of the default path to B2"),
    )

    A = State(initial=True)

    class B(State.Compound):
        j0 = Junction(initial=True)
        B1 = State()
        B2 = State()
        j0.to(B1, cond="C_one")
        j0.to(B2, cond="C_two")

    E_one = A.to(B)

    on_exit_A = act("exitA")
    on_enter_B = act("entB")
    during_B = act("durB")
    on_enter_B1 = act("entB1")
    during_B1 = act("durB1")
    on_exit_B1 = act("exitB1")
    on_enter_B2 = act("entB2")


def test_a_default_transition_through_a_junction_is_followed_only_when_the_state_is_entered():
    """Default Transition to a Junction.  <URL above>

    The page: the default transition to the junction is valid only when B is first entered, not at
    every wake-up.  B.B1 active (entered earlier while C_one held), now C_two true; an event wakes
    the chart: B checks for a valid transition for the event, none; B's during action; B1 checks
    for a valid transition, none; B1's during action; back to sleep.  B2 is not entered although
    its default-path condition now holds.
    """
    chart = DefaultToAJunction()
    chart.send("E_one")
    assert chart.log[-3:] == ["exitA", "entB", "entB1"]
    chart.C_one = False
    chart.C_two = True
    chart.log.clear()
    chart.tick()
    assert chart.log == ["durB", "durB1"]
    assert chart.active_ids == frozenset({"B", "B1"})


class DefaultAndHistory(TickChart):
    """A (default) and B {H, B1 (default), B2, B3, B4}; A -> B ``E_one``, B -> A ``E_two``.

    <URL above>  The narrative names B4 as the last active substate; B1..B3 and the events that
    lead there (``E_three``: B1 -> B2 -> B3 -> B4) and back to A (``E_two``) are added to get the
    chart into the example's starting situation.
    """

    local = (Data("log", "list", [], "actions in the order they ran"),)

    A = State(initial=True)

    class B(State.Compound):
        h = HistoryState()
        B1 = State(initial=True)
        B2 = State()
        B3 = State()
        B4 = State()
        E_three = B1.to(B2) | B2.to(B3) | B3.to(B4)

    E_one = A.to(B)
    E_two = B.to(A)

    on_enter_A = act("entA")
    on_exit_A = act("exitA")
    on_enter_B = act("entB")
    on_exit_B = act("exitB")
    on_enter_B1 = act("entB1")
    on_enter_B4 = act("entB4")
    on_exit_B4 = act("exitB4")


def test_a_history_junction_overrides_the_default_transition_when_the_superstate_is_reentered():
    """Default Transition and a History Junction.  <URL above; 2002: semant30>

    A active; B has a history junction and B.B4 was B's last active substate; E_one: the root
    finds A -> B valid; A's exit action, A inactive, B active, B's entry action; B uses its
    history junction to pick the destination: B4, the last active substate, becomes active and
    its entry action runs (B1's default transition is not followed).
    """
    chart = DefaultAndHistory()
    chart.send("E_one")
    for _ in range(3):
        chart.send("E_three")
    assert chart.active_ids == frozenset({"B", "B4"})
    chart.send("E_two")
    assert chart.active_ids == frozenset({"A"})
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["exitA", "entB", "entB4"]
    assert chart.active_ids == frozenset({"B", "B4"})


class LabeledDefaultTransitions(TickChart):
    """A (default) and B {B1, B2}; B's default transitions carry events.  <URL above>

    Default transitions of B: ``E_one`` to B1 and ``E_two`` to B2 (written through an initial
    junction j0, the API's form of a default transition with a label); A -> B on E_one or E_two.
    The narrative needs only the E_one default to B1; the E_two pair is the reading of "labeled
    default transitions" that makes the label decide (flagged in README.md).
    """

    local = (Data("log", "list", [], "actions in the order they ran"),)

    A = State(initial=True)

    class B(State.Compound):
        j0 = Junction(initial=True)
        B1 = State()
        B2 = State()
        j0.to(B1, event="E_one")
        j0.to(B2, event="E_two")

    E_one = A.to(B)
    E_two = A.to(B)

    on_exit_A = act("exitA")
    on_enter_B = act("entB")
    on_enter_B1 = act("entB1")
    on_enter_B2 = act("entB2")


def test_a_default_transition_labelled_with_an_event_is_valid_for_the_event_being_processed():
    """Labeled Default Transitions.  <URL above>

    A active, E_one: the root finds A -> B valid; A's exit action, A inactive, B active and its
    entry action; B finds a valid default transition to B.B1, valid because the event being
    processed is E_one; B1 active and its entry action.
    """
    chart = LabeledDefaultTransitions()
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["exitA", "entB", "entB1"]
    assert chart.active_ids == frozenset({"B", "B1"})
