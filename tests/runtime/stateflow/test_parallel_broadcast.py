"""Conformance: "Undirected Broadcast Events in Parallel States" (Stateflow).

https://mathworks.com/help/stateflow/ug/parallel-and-state-examples.html
(mirrors: uk.mathworks.com, se.mathworks.com; earlier titles "Broadcast Events in Parallel (AND)
States" / "Parallel (AND) State Examples": "Event Broadcast State Action", "Event Broadcast
Transition Action with a Nested Event Broadcast", "Event Broadcast Condition Action",
http://www.ece.northwestern.edu/local-apps/matlabhelp/toolbox/stateflow/semant48.html .. semant50.html)

Three narrated examples share one chart shape (figures missing, rebuilt from the narrative):

    A  (du: durA), parallel decomposition, children in execution order A1 then A2
      A1 (du: durA1)           A1a (du: durA1a) --E_one--> A1b (en: entA1b)      A1a ex: exitA1a
      A2 (du: durA2)           A2a (ex: exitA2a) --E_two--> A2b (en: entA2b, du: durA2b)

They differ only in where the undirected broadcast of E_two sits: an ``on E_one`` action of A1,
the transition action of A1a -> A1b, or its condition action.  The broadcast is undirected
(``send(E_two)``; the API's ``self.send("E_two")``): it is processed at once, from the chart root,
while the sending action is suspended (a nested event, not a queued one).

Reading choices (the narrative leaves them open):
- durA1a / durA2b: the modern text of the first example names durA1a inside the nested E_two
  pass; the closing steps of every example (cut from the copies that could be read) end with A2
  executing for E_one after its E_two transition.  A2b is given a during action durA2b and A1a a
  during action durA1a in all three charts; where the state is active and not left, Stateflow runs
  its during action, so the asserted orders follow the execution workflow for those steps.
- A1b and A2a carry during actions too (durA1b, durA2a) so the tests also check they do NOT run.
"""

from statemachine import State

from ttt_sm.runtime import Data, TickChart, action_on

from ._log import act

URL = "https://mathworks.com/help/stateflow/ug/parallel-and-state-examples.html"


class _Logged:
    """The three charts' actions: each logs its name; send_E_two broadcasts E_two."""

    during_A = act("durA")
    during_A1 = act("durA1")
    during_A2 = act("durA2")
    during_A1a = act("durA1a")
    on_exit_A1a = act("exitA1a")
    on_enter_A1b = act("entA1b")
    during_A1b = act("durA1b")
    during_A2a = act("durA2a")
    on_exit_A2a = act("exitA2a")
    on_enter_A2b = act("entA2b")
    during_A2b = act("durA2b")

    def send_E_two(self):
        """The undirected broadcast send(E_two) (E_two is a local event of the chart)."""
        self.send("E_two")


class BroadcastInStateAction(_Logged, TickChart):
    """A1's label has ``on E_one: send(E_two)`` after its during action.  <URL above>"""

    local = (Data("log", "list", [], "actions in the order they ran"),)

    class A(State.Parallel):
        class A1(State.Compound):
            A1a = State(initial=True)
            A1b = State()

        class A2(State.Compound):
            A2a = State(initial=True)
            A2b = State()
            E_two = A2a.to(A2b)

    E_one = action_on(A.A1, "send_E_two") | A.A1.A1a.to(A.A1.A1b)


class BroadcastInTransitionAction(_Logged, TickChart):
    """A1a -> A1b is labelled ``E_one/send(E_two)``.  <URL above>"""

    local = (Data("log", "list", [], "actions in the order they ran"),)

    class A(State.Parallel):
        class A1(State.Compound):
            A1a = State(initial=True)
            A1b = State()
            E_one = A1a.to(A1b, on="send_E_two")

        class A2(State.Compound):
            A2a = State(initial=True)
            A2b = State()
            E_two = A2a.to(A2b)


class BroadcastInConditionAction(_Logged, TickChart):
    """A1a -> A1b is labelled ``E_one{send(E_two)}``.  <URL above>"""

    local = (Data("log", "list", [], "actions in the order they ran"),)

    class A(State.Parallel):
        class A1(State.Compound):
            A1a = State(initial=True)
            A1b = State()
            E_one = A1a.to(A1b, before="send_E_two")

        class A2(State.Compound):
            A2a = State(initial=True)
            A2b = State()
            E_two = A2a.to(A2b)


def test_a_broadcast_from_an_on_event_action_is_processed_at_once_from_the_root():
    """Broadcast in a state action.  A.A1.A1a and A.A2.A2a are active; E_one wakes the chart.

    Page (paraphrased): no root transition for E_one; durA; A's parallel children run in order,
    A1 first: durA1, then A1's ``on E_one`` action broadcasts E_two, which wakes the chart a second
    time, from the root: no root transition; durA; no valid transition among A's children; A1:
    durA1, no transition for E_two, A1a's during action durA1a; A2: durA2, A2a -> A2b is valid for
    E_two: exitA2a, entA2b.  Then the E_one pass resumes in A1: A1a -> A1b is valid: exitA1a,
    entA1b; then A2 runs for E_one: durA2, no transition for E_one, durA2b; the chart sleeps.
    """
    chart = BroadcastInStateAction()
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == [
        "durA", "durA1",
        # nested E_two, from the root
        "durA", "durA1", "durA1a", "durA2", "exitA2a", "entA2b",
        # E_one resumes
        "exitA1a", "entA1b", "durA2", "durA2b",
    ]
    assert chart.active_ids == frozenset({"A", "A1", "A1b", "A2", "A2b"})


def test_a_broadcast_from_a_transition_action_runs_between_the_exit_and_the_entry():
    """Broadcast in a transition action (nested event broadcast).  Same start; E_one wakes it.

    Page (paraphrased): no root transition; durA; A1: durA1; A1a -> A1b is valid for E_one: exitA1a,
    A1a marked inactive; the transition action broadcasts E_two, which interrupts the transition:
    from the root, no transition; durA; A1: durA1, no transition for E_two in A1 (A1 has no active
    child at this moment, so no child during action); A2: durA2, A2a -> A2b: exitA2a, entA2b.  The
    E_one pass resumes: A1b marked active, entA1b; A2 runs for E_one: durA2, durA2b.
    """
    chart = BroadcastInTransitionAction()
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == [
        "durA", "durA1", "exitA1a",
        # nested E_two while A1 has no active child
        "durA", "durA1", "durA2", "exitA2a", "entA2b",
        # E_one resumes: the transition's parent A1 is active and has no active child
        "entA1b", "durA2", "durA2b",
    ]
    assert chart.active_ids == frozenset({"A", "A1", "A1b", "A2", "A2b"})


def test_a_broadcast_from_a_condition_action_runs_before_the_source_is_exited():
    """Broadcast in a condition action.  Same start; E_one wakes the chart.

    Page (paraphrased): no root transition; durA; A1: durA1; A1a -> A1b is valid and its condition
    action broadcasts E_two while A1a is still active: from the root, no transition; durA; A1:
    durA1, no transition for E_two, durA1a (A1a is still active); A2: durA2, A2a -> A2b: exitA2a,
    entA2b.  The E_one pass resumes: exitA1a, A1a inactive, entA1b, A1b active; A2 runs for E_one:
    durA2, durA2b.
    """
    chart = BroadcastInConditionAction()
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == [
        "durA", "durA1",
        # nested E_two while A1a is still active
        "durA", "durA1", "durA1a", "durA2", "exitA2a", "entA2b",
        # E_one resumes: the source A1a is still active, so the transition completes
        "exitA1a", "entA1b", "durA2", "durA2b",
    ]
    assert chart.active_ids == frozenset({"A", "A1", "A1b", "A2", "A2b"})
