"""Conformance: "Broadcast Local Events in Parallel States" (directed event broadcasting, Stateflow).

https://mathworks.com/help/stateflow/ug/directly-broadcast-events.html
(mirrors: in.mathworks.com, ww2.mathworks.cn; rules also on
https://mathworks.com/help/stateflow/ug/broadcasting-events-to-synchronize-states.html and
https://mathworks.com/help/stateflow/ref/send.html)

Two narrated examples (figures missing, rebuilt from the narrative): the chart has parallel
top-level states A and B; A holds A1 (default) and A2, B holds B1 (default) and B2.  A1 -> A2 is
guarded by [data1==1] and broadcasts E_one to B; B1 -> B2 is triggered by E_one.  In the current
text the broadcast runs *before* A1's exit, so it is written as a condition action
``[data1==1]{send(E_one,B)}`` (the 2002 edition put it in the transition action, after exitA1;
the current order is the one asserted).

The chart-level parallel decomposition is written as one parallel superstate P without actions
(the API puts parallel regions in a ``State.Parallel`` class); P adds nothing to the logs.
The wake-up event is not named on the page ("an event occurs"); A1 -> A2 has no trigger, so any
wake-up works: the tests use ``chart.tick()``.
"""

from statemachine import State

from ttt_sm.runtime import Data, TickChart, action_on

from ._log import act

URL = "https://mathworks.com/help/stateflow/ug/directly-broadcast-events.html"


class DirectedSend(TickChart):
    """A1 -> A2 ``[data1==1]{send(E_one,B)}``; B1 -> B2 on E_one.  <URL above>"""

    local = (
        Data("log", "list", [], "actions in the order they ran"),
        Data("data1", "int", 1, "the guard's data; 1 on the page"),
    )

    class P(State.Parallel):
        class A(State.Compound):
            A1 = State(initial=True)
            A2 = State()
            A1.to(A2, cond="data1 == 1", before="send_E_one_to_B")

        class B(State.Compound):
            B1 = State(initial=True)
            B2 = State()
            E_one = B1.to(B2)

    on_exit_A1 = act("exitA1")
    on_enter_A2 = act("entA2")
    on_exit_B1 = act("exitB1")
    on_enter_B2 = act("entB2")

    def send_E_one_to_B(self):
        """send(E_one, B): the local event E_one, to state B and its descendants only."""
        self.send("E_one", "B")


#: send(B.E_one), E_one declared in state B: the runtime has no event scopes (docs/runtime.md, "Where
#: the runtime differs"), so a qualified name is written as the directed broadcast it means: this chart
#: is DirectedSend.
QualifiedSend = DirectedSend


def test_send_to_a_parallel_state_runs_the_receiver_before_the_sender_leaves_its_state():
    """Directed Event Broadcast Using Send.  A.A1 and B.B1 are active; data1 == 1.

    Page (paraphrased): no root transition; A finds A1 -> A2 valid because data1 == 1; the action
    send(E_one,B) runs: E_one reaches B, which is active, so B checks its transitions: B1 -> B2 is
    valid: exitB1, B1 inactive, B2 active, entB2.  Then exitA1, A1 inactive, A2 active, entA2.
    """
    chart = DirectedSend()
    chart.log.clear()
    chart.tick()
    assert chart.log == ["exitB1", "entB2", "exitA1", "entA2"]
    assert chart.active_ids == frozenset({"P", "A", "A2", "B", "B2"})


def test_a_qualified_event_name_sends_the_event_to_the_state_that_owns_it():
    """Directed Event Broadcast Using Qualified Event Name.  Same chart, E_one now belongs to B.

    Page (paraphrased): the only changes are that E_one is declared in state B (visible only there)
    and the action is send(B.E_one); the qualified name is needed because A cannot see E_one.  The
    behaviour is that of the previous example: exitB1, entB2, then exitA1, entA2.
    """
    chart = QualifiedSend()
    chart.log.clear()
    chart.tick()
    assert chart.log == ["exitB1", "entB2", "exitA1", "entA2"]
    assert chart.active_ids == frozenset({"P", "A", "A2", "B", "B2"})


# --- rules stated on the pages (not narrated examples) --------------------------------------------


class DirectedSendToInactiveState(TickChart):
    """A broadcasts E_one to B.B2 while B.B1 is the active child of B.  <broadcasting-events...>"""

    local = (
        Data("log", "list", [], "actions in the order they ran"),
        Data("data1", "int", 1, "the guard's data"),
    )

    class P(State.Parallel):
        class A(State.Compound):
            A1 = State(initial=True)
            A2 = State()
            A1.to(A2, cond="data1 == 1", before="send_E_one_to_B2")

        class B(State.Compound):
            B1 = State(initial=True)
            B2 = State()
            E_one = B1.to(B2)

    on_exit_A1 = act("exitA1")
    on_enter_A2 = act("entA2")
    on_exit_B1 = act("exitB1")
    on_enter_B2 = act("entB2")

    def send_E_one_to_B2(self):
        self.send("E_one", "B2")


def test_a_directed_broadcast_to_an_inactive_state_has_no_effect():
    """Rule: the receiving state must be active during the broadcast.

    broadcasting-events-to-synchronize-states.html: "The receiving state must be active during the
    event broadcast"; the 2002 edition (action36.html): the named state must be active when send
    executes to receive and possibly act on the event.  B2 is inactive, so nothing in B reacts
    (an undirected E_one would have taken B1 -> B2); A's transition completes normally.
    """
    chart = DirectedSendToInactiveState()
    chart.log.clear()
    chart.tick()
    assert chart.log == ["exitA1", "entA2"]
    assert chart.active_ids == frozenset({"P", "A", "A2", "B", "B1"})


class DirectedSendSkipsOtherStates(TickChart):
    """A has its own ``on E_one`` action; A sends E_one to B only.  <URL above>"""

    local = (
        Data("log", "list", [], "actions in the order they ran"),
        Data("data1", "int", 1, "the guard's data"),
    )

    class P(State.Parallel):
        class A(State.Compound):
            A1 = State(initial=True)
            A2 = State()
            A1.to(A2, cond="data1 == 1", before="send_E_one_to_B")

        class B(State.Compound):
            B1 = State(initial=True)
            B2 = State()

    E_one = action_on(P.A, "A_saw_E_one") | P.B.B1.to(P.B.B2)

    A_saw_E_one = act("A_saw_E_one")
    on_exit_A1 = act("exitA1")
    on_enter_A2 = act("entA2")
    on_exit_B1 = act("exitB1")
    on_enter_B2 = act("entB2")

    def send_E_one_to_B(self):
        self.send("E_one", "B")


def test_a_directed_broadcast_reaches_only_the_named_state_and_its_descendants():
    """Rule: send(E, S) broadcasts E to S and any of its offspring (send reference page).

    A's ``on E_one`` action must not run: A is neither B nor inside B.
    """
    chart = DirectedSendSkipsOtherStates()
    chart.log.clear()
    chart.tick()
    assert chart.log == ["exitB1", "entB2", "exitA1", "entA2"]
    assert chart.active_ids == frozenset({"P", "A", "A2", "B", "B2"})
