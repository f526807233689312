"""Conformance: "Control Chart Execution by Using Condition Actions" (Stateflow semantic examples).

https://mathworks.com/help/stateflow/ug/condition-action-examples.html
(mirrors read: uk/de/it/au/jp.mathworks.com, ww2.mathworks.cn (zh), cs400-web.cs.wisc.edu R2020b
copy; Chinese translations of the whole page: http://rhkb.cn/news/241691.html,
https://45793.com/article/qie6JDK5ZSHuzX7ay8GsrM.html, https://e-com-net.com/article/1748467093977710592.htm;
2000 edition "Condition Actions":
https://atmos.washington.edu/~brodzik/for_yuter/20050614_opt/matlab6/help/toolbox/stateflow/semanti7.html)

Five examples:

- Condition Action Behavior (narrated);
- Condition and Transition Action Behavior (narrated);
- Create Condition Actions Using a For-Loop (figure only: the current page has one sentence and
  the chart, no step list);
- Broadcast Events to Parallel (AND) States Using Condition Actions (figure only, likewise);
- Avoid Cyclic Behavior (narrated: On -> Off, the condition action broadcasts E_one).

For the two figure-only examples the chart is rebuilt from the example's title and its sentence,
and the expected order follows the execution workflow (flagged in README.md); the for-loop
figure is the same construct as the "For-Loop Construct" example of the connective junction page,
whose narrative is used.
"""

import pytest
from statemachine import State

from ttt_sm.runtime import ChartExecutionError, Data, Junction, TickChart

from ._log import act

URL = "https://mathworks.com/help/stateflow/ug/condition-action-examples.html"


class ConditionActionOnAFirstSegment(TickChart):
    """A -> junction ``E_one{A_one}``; junction -> B ``[C_one]``; junction -> C ``[C_two]``.

    <URL above>  The uk copy's figure caption names states A, B and C; the narrative puts the
    condition action A_one on the segment from A to the junction and conditions on the segments
    to "possible destinations": C_one to B and C_two to C is the reading used.
    """

    local = (
        Data("log", "list", [], "actions in the order they ran"),
        Data("C_one", "bool", False, "condition C_one"),
        Data("C_two", "bool", False, "condition C_two"),
    )

    A = State(initial=True)
    B = State()
    C = State()
    j = Junction()

    E_one = A.to(j, before="A_one")
    j.to(B, cond="C_one")
    j.to(C, cond="C_two")

    on_enter_A = act("entA")
    during_A = act("durA")
    on_exit_A = act("exitA")
    on_enter_B = act("entB")
    on_enter_C = act("entC")
    A_one = act("A_one")


def test_a_condition_action_runs_at_once_even_when_the_whole_path_turns_out_invalid():
    """Condition Action Behavior.  <URL above>

    A active, C_one and C_two false, E_one: the segment from A to the junction is valid, so its
    condition action A_one runs at once (A still active).  Both segments out of the junction are
    false, so no complete transition is valid; A's during action runs and A stays active.
    A_one is not undone.
    """
    chart = ConditionActionOnAFirstSegment()
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["A_one", "durA"]
    assert chart.active_ids == frozenset({"A"})


class ConditionAndTransitionAction(TickChart):
    """A -> B labelled ``E_one[C_one]{A_one}/A_two``.  <URL above>

    The page writes A's exit action as ``ExitA()`` (capital E); the log uses that name.
    """

    local = (
        Data("log", "list", [], "actions in the order they ran"),
        Data("C_one", "bool", True, "condition C_one"),
    )

    A = State(initial=True)
    B = State()
    E_one = A.to(B, cond="C_one", before="A_one", on="A_two")

    on_enter_A = act("entA")
    during_A = act("durA")
    on_exit_A = act("ExitA")
    on_enter_B = act("entB")
    A_one = act("A_one")
    A_two = act("A_two")


def test_the_condition_action_runs_before_the_exit_and_the_transition_action_after_it():
    """Condition and Transition Action Behavior.  <URL above>

    A active, C_one true, E_one: A -> B is valid; the condition action A_one runs at once while A
    is still active; then A's exit action, A inactive, the transition action A_two, B active, B's
    entry action.
    """
    chart = ConditionAndTransitionAction()
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["A_one", "ExitA", "A_two", "entB"]
    assert chart.active_ids == frozenset({"B"})


class ForLoopWithConditionActions(TickChart):
    """A -> j ``E_one{i = 0}``; j -> j ``[i < 10]{i++; func1()}`` (1); j -> B (2).  <URL above>

    The page shows only the figure.  The labels are those of the same for-loop figure narrated on
    the connective junction page ("For-Loop Construct": condition action ``i = 0`` on the segment
    from A, a self-loop on the junction with condition ``[i < 10]`` and condition actions ``i++``
    and a call to ``func1``, an unlabelled segment to B, tried after the self-loop).
    """

    local = (
        Data("log", "list", [], "actions in the order they ran"),
        Data("i", "1", 0, "the loop counter"),
    )

    A = State(initial=True)
    B = State()
    j = Junction()

    E_one = A.to(j, before="init_loop")
    j.to(j, cond="i < 10", before="loop_body")
    j.to(B)

    on_exit_A = act("exitA")
    on_enter_B = act("entB")

    def init_loop(self):
        """Condition action ``i = 0``."""
        self.i = 0
        self.log.append("i = 0")

    def loop_body(self):
        """Condition actions ``i++; func1()`` of the junction's self-loop."""
        self.i += 1
        self.log.append("func1")


def test_condition_actions_on_a_junction_self_loop_make_a_for_loop_within_one_transition():
    """Create Condition Actions Using a For-Loop.  <URL above>

    The page: condition actions and a connective junction make a for-loop construct (figure
    only).  Expected, by the execution workflow: ``i = 0`` runs as the first segment is tested;
    the self-loop's condition ``[i < 10]`` holds ten times, each time running ``i++; func1()``; at
    i == 10 the self-loop fails and the segment to B is tried and valid; A is exited and B
    entered, all in the one wake-up on E_one.
    """
    chart = ForLoopWithConditionActions()
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["i = 0"] + ["func1"] * 10 + ["exitA", "entB"]
    assert chart.i == 10
    assert chart.active_ids == frozenset({"B"})


class BroadcastToParallelStates(TickChart):
    """Parallel A and B (execution order A, then B), each with two substates.  <URL above>

    A.A1 -> A.A2 ``E_one{send(E_two)}``; B.B1 -> B.B2 ``E_two``.  The page shows only the figure;
    the labels are rebuilt from the title (a condition action broadcasts an event to a parallel
    state) and the 2002 example of the same name.  A chart whose top level is parallel is written
    with a parallel superstate P (the API has no chart-level decomposition).  The broadcast action
    also writes ``send(E_two)`` to the log.
    """

    local = (Data("log", "list", [], "actions in the order they ran"),)

    class P(State.Parallel):
        class A(State.Compound):
            A1 = State(initial=True)
            A2 = State()
            E_one = A1.to(A2, before="broadcast_E_two")

        class B(State.Compound):
            B1 = State(initial=True)
            B2 = State()
            E_two = B1.to(B2)

    on_exit_A1 = act("exitA1")
    on_enter_A2 = act("entA2")
    on_exit_B1 = act("exitB1")
    on_enter_B2 = act("entB2")

    def broadcast_E_two(self):
        """Condition action ``send(E_two)``: an undirected broadcast of the local event E_two."""
        self.log.append("send(E_two)")
        self.send("E_two")


def test_a_condition_action_broadcast_lets_the_parallel_state_move_before_the_source_is_left():
    """Broadcast Events to Parallel (AND) States Using Condition Actions.  <URL above>

    The page: condition actions broadcast an event to parallel states immediately (figure only).
    Expected, by the workflow: E_one wakes the chart; A's A1 -> A2 is valid, so its condition
    action runs first and broadcasts E_two, which is processed at once from the root while A1 is
    still active: A has no transition on E_two, B takes B1 -> B2 (exitB1, entB2).  Back in the
    E_one step, A1 is exited and A2 entered.  B, executed next for E_one, has nothing to do.
    """
    chart = BroadcastToParallelStates()
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["send(E_two)", "exitB1", "entB2", "exitA1", "entA2"]
    assert chart.active_ids == frozenset({"P", "A", "A2", "B", "B2"})


class CyclicConditionActionBroadcast(TickChart):
    """On -> Off ``E_one{send(E_one)}``; Off -> On ``E_one``.  <URL above>

    The page's narrative: On active, E_one, the root finds On -> Off valid, and the transition's
    condition action broadcasts E_one.  The Off -> On transition is not in the part of the
    narrative that could be read; it is added so that Off is reachable and does not take part.
    The broadcast action also writes ``send(E_one)`` to the log.
    """

    local = (Data("log", "list", [], "actions in the order they ran"),)

    On = State(initial=True)
    Off = State()
    E_one = On.to(Off, before="broadcast_E_one") | Off.to(On)

    on_exit_On = act("exitOn")
    on_enter_Off = act("entOff")

    def broadcast_E_one(self):
        """Condition action ``send(E_one)``: rebroadcasts the event that triggers this transition."""
        self.log.append("send(E_one)")
        self.send("E_one")


def test_a_condition_action_that_rebroadcasts_its_own_trigger_recurses_without_end():
    """Avoid Cyclic Behavior (cyclic behavior to avoid).  <URL above>

    On active, E_one: On -> Off is valid; its condition action broadcasts E_one, which is
    processed at once while On is still active, so On -> Off is found valid again and its condition
    action broadcasts E_one again, and so on: the chart never gets to exit On.  The page shows the
    notation as one to avoid.  The runtime reports the endless nesting (docs/runtime.md: nested
    broadcasts more than 64 deep raise ChartExecutionError); On is never exited.
    """
    chart = CyclicConditionActionBroadcast()
    chart.log.clear()
    with pytest.raises(ChartExecutionError):
        chart.send("E_one")
    assert "exitOn" not in chart.log and "entOff" not in chart.log
    assert chart.log.count("send(E_one)") > 1
