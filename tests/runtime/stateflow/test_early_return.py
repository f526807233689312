"""Conformance: "Early Return Logic for Event Broadcasts" (Stateflow).

https://mathworks.com/help/stateflow/ug/early-return-logic-for-event-broadcasts.html
(the page is reached from "Avoid Unwanted Recursion"; 2002 edition:
http://www.ece.northwestern.edu/local-apps/matlabhelp/toolbox/stateflow/semant15.html)

The page states three guidelines (a state's parent is active while the state is; an exclusive
(OR) state or chart never has two active children; an active parallel state's higher-priority
siblings are active), a table giving the early return rule for each action type, and ONE
narrated example (a condition action that broadcasts).  The first test is that example; the
others check each row of the table on small charts built for the purpose (rule tests, not
narrated on the page).

Reading choice used throughout (not spelled out on the page): the early return check is made
right after the broadcast statement returns, so the statements that follow the broadcast inside
the same action are skipped as well (the Stateflow code generator guards the rest of the action
with the activity check).  Each test's action logs "<name>_begin" before and "<name>_end" after
its broadcast to make this visible.
"""

from statemachine import State

from ttt_sm.runtime import Data, TickChart

from ._log import act

URL = "https://mathworks.com/help/stateflow/ug/early-return-logic-for-event-broadcasts.html"


class ConditionActionBroadcast(TickChart):
    """A -> B labelled ``E{send(F)}``; A -> C labelled ``F``.  <URL above>"""

    local = (Data("log", "list", [], "actions in the order they ran"),)

    A = State(initial=True)
    B = State()
    C = State()
    E = A.to(B, before="ca_send_F")
    F = A.to(C)

    during_A = act("durA")
    on_exit_A = act("exitA")
    on_enter_B = act("entB")
    on_enter_C = act("entC")
    during_C = act("durC")

    def ca_send_F(self):
        self.log.append("ca_begin")
        self.send("F")
        self.log.append("ca_end")


def test_a_condition_action_broadcast_that_leaves_the_source_halts_the_transition():
    """Example of Early Return Logic.  A is active; E occurs.

    Page (paraphrased): the root finds A -> B valid for E; its condition action broadcasts F, which
    interrupts the transition; for F the root finds A -> C valid: A exits and becomes inactive, C
    becomes active and runs its entry action.  C is now the chart's only active child.  The chart
    cannot go back to finish A -> B: its source A is inactive, and B would become a second active
    child of an exclusive chart.  So the transition A -> B is halted (no exitA again, no entB), and
    nothing else of the E pass runs (C was entered during F: no durC for E).
    """
    chart = ConditionActionBroadcast()
    chart.log.clear()
    chart.send("E")
    assert chart.log == ["ca_begin", "exitA", "entC"]
    assert chart.active_ids == frozenset({"C"})


# --- one rule test per row of the page's table ----------------------------------------------------


class EntryBroadcast(TickChart):
    """A -> B on E; B{B1 default} enters with ``send(F)``; B -> C on F.  <URL above>"""

    local = (Data("log", "list", [], "actions in the order they ran"),)

    A = State(initial=True)

    class B(State.Compound):
        B1 = State(initial=True)

    C = State()
    E = A.to(B)
    F = B.to(C)

    on_exit_A = act("exitA")
    on_exit_B = act("exitB")
    on_enter_B1 = act("entB1")
    on_exit_B1 = act("exitB1")
    on_enter_C = act("entC")

    def on_enter_B(self):
        self.log.append("entB_begin")
        self.send("F")
        self.log.append("entB_end")


def test_entry_early_return_skips_the_rest_of_entering_a_state_left_during_the_broadcast():
    """Table row "Entry": if the state is no longer active at the end of the broadcast, the chart
    does not perform the remaining steps for entering it.  B's entry action broadcasts F; F takes
    B -> C (B has no active child yet); back in B's entry: B is inactive, so the rest of the entry
    action and the entry of B's default child B1 are skipped."""
    chart = EntryBroadcast()
    chart.log.clear()
    chart.send("E")
    assert chart.log == ["exitA", "entB_begin", "exitB", "entC"]
    assert chart.active_ids == frozenset({"C"})


class ExitBroadcast(TickChart):
    """A{A1, A2}: A1 -> A2 on E; A1's exit action sends F once; A -> C on F.  <URL above>

    The flag ``sent`` stops the second exit of A1 (during F, A1 is still active, so F exits it
    again) from broadcasting F a second time.
    """

    local = (
        Data("log", "list", [], "actions in the order they ran"),
        Data("sent", "bool", False, "A1's exit action has already broadcast F"),
    )

    class A(State.Compound):
        A1 = State(initial=True)
        A2 = State()
        E = A1.to(A2)

    C = State()
    F = A.to(C)

    on_exit_A = act("exitA")
    on_enter_A2 = act("entA2")
    on_enter_C = act("entC")

    def on_exit_A1(self):
        self.log.append("exitA1_begin")
        if not self.sent:
            self.sent = True
            self.send("F")
        self.log.append("exitA1_end")


def test_exit_early_return_skips_the_rest_of_the_exit_and_the_transition():
    """Table row "Exit": if the state is no longer active at the end of the broadcast, the chart
    does not perform the remaining exit actions or the transition from state to state.

    E: A1 -> A2 is valid; A1's exit action (A1 still active) broadcasts F; F: A -> C is valid, so A
    exits its active child A1 (whose exit action runs again, completely: the flag stops a second
    broadcast), then A exits, C is entered.  Back in the first exit of A1: A1 is inactive, so the
    rest of that exit action and the transition A1 -> A2 (entA2) are skipped."""
    chart = ExitBroadcast()
    chart.log.clear()
    chart.send("E")
    assert chart.log == ["exitA1_begin", "exitA1_begin", "exitA1_end", "exitA", "entC"]
    assert chart.active_ids == frozenset({"C"})


class DuringBroadcast(TickChart):
    """A{A1}; A's during action sends F; A -> B on F.  <URL above>"""

    local = (Data("log", "list", [], "actions in the order they ran"),)

    class A(State.Compound):
        A1 = State(initial=True)

    B = State()
    F = A.to(B)

    during_A1 = act("durA1")
    on_exit_A1 = act("exitA1")
    on_exit_A = act("exitA")
    on_enter_B = act("entB")

    def during_A(self):
        self.log.append("durA_begin")
        self.send("F")
        self.log.append("durA_end")


def test_during_early_return_skips_the_rest_of_executing_the_state():
    """Table row "During": if the state is no longer active at the end of the broadcast, the chart
    does not perform the remaining steps of executing it.  A tick: A has no outer transition valid
    without F; its during action broadcasts F; F takes A -> B (A1 exits first).  Back in A's during
    action: A is inactive, so the rest of it, A's inner transitions and its children (durA1) are
    skipped."""
    chart = DuringBroadcast()
    chart.log.clear()
    chart.tick()
    assert chart.log == ["durA_begin", "exitA1", "exitA", "entB"]
    assert chart.active_ids == frozenset({"B"})


class TransitionBroadcastParentLeft(TickChart):
    """A{A1, A2}: A1 -> A2 labelled ``E/send(F)``; A -> C on F.  <URL above>"""

    local = (Data("log", "list", [], "actions in the order they ran"),)

    class A(State.Compound):
        A1 = State(initial=True)
        A2 = State()
        E = A1.to(A2, on="ta_send_F")

    C = State()
    F = A.to(C)

    on_exit_A1 = act("exitA1")
    on_enter_A2 = act("entA2")
    on_exit_A = act("exitA")
    on_enter_C = act("entC")

    def ta_send_F(self):
        self.log.append("ta_begin")
        self.send("F")
        self.log.append("ta_end")


def test_transition_early_return_when_the_parent_of_the_path_is_no_longer_active():
    """Table row "Transition", first case: if the parent of the transition path is not active, the
    chart does not perform the remaining transition actions and state entry actions.  A1 -> A2 has
    exited A1 when its transition action broadcasts F; F takes A -> C (A has no active child).
    Back in the transition action: its parent A is inactive, so the rest of the action and entA2
    are skipped."""
    chart = TransitionBroadcastParentLeft()
    chart.log.clear()
    chart.send("E")
    assert chart.log == ["exitA1", "ta_begin", "exitA", "entC"]
    assert chart.active_ids == frozenset({"C"})


class TransitionBroadcastParentRefilled(TickChart):
    """A{A1, A2}: A1 -> A2 labelled ``E/send(F)``; an inner transition of A on F goes to A1.  <URL>"""

    local = (Data("log", "list", [], "actions in the order they ran"),)

    class A(State.Compound):
        A1 = State(initial=True)
        A2 = State()
        E = A1.to(A2, on="ta_send_F")

    F = A.to(A.A1, internal=True)

    on_exit_A1 = act("exitA1")
    on_enter_A1 = act("entA1")
    on_enter_A2 = act("entA2")
    on_exit_A = act("exitA")
    on_enter_A = act("entA")

    def ta_send_F(self):
        self.log.append("ta_begin")
        self.send("F")
        self.log.append("ta_end")


def test_transition_early_return_when_the_parent_of_the_path_has_an_active_child_again():
    """Table row "Transition", second case: if the parent of the transition path has an active
    child, the chart does not perform the remaining transition actions and state entry actions.
    A1 -> A2 has exited A1 when its transition action broadcasts F; F: A stays active, its inner
    transition to A1 is valid and enters A1 (A had no active child).  Back in the transition
    action: A now has an active child, so the rest of the action and entA2 are skipped (A2 would
    be a second active child)."""
    chart = TransitionBroadcastParentRefilled()
    chart.log.clear()
    chart.send("E")
    assert chart.log == ["exitA1", "ta_begin", "entA1"]
    assert chart.active_ids == frozenset({"A", "A1"})
