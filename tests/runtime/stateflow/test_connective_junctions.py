"""Conformance: "Represent Multiple Paths by Using Connective Junctions" (Stateflow semantic examples).

https://mathworks.com/help/stateflow/ug/use-connective-junctions-to-represent-multiple-paths.html
(older URL: .../connective-junction-examples.html; mirrors read: in.mathworks.com; 2000 edition:
https://atmos.uw.edu/~brodzik/for_yuter/20050614_opt/matlab6/help/toolbox/stateflow/semant10.html
("If-Then-Else Decision Construct", "Self Loop"); the notation page with the same charts:
http://www.ece.northwestern.edu/CFS/local-apps/matlabhelp/toolbox/stateflow/notati23.html)

Nine examples:

- the label format for transition segments (S1 -> junction -> S2 / S3);
- If-Then-Else Decision Construct;
- Self-Loop Transition;
- For-Loop Construct;
- Flow Chart Notation;
- Transition from a Common Source to Multiple Destinations;
- Transition from Multiple Sources to a Common Destination;
- Transition from a Source to a Destination Based on a Common Event;
- Backtrack in Flow Charts (backtracking behavior).

Limits of what could be read: the stored copies of the current page end inside "Self-Loop
Transition"; the 2000 page gives that example whole.  The other six follow the MathWorks text as
remembered (step lists, conditions, names) and the execution workflow; "Flow Chart Notation" in
particular is a reconstruction (its figure and most of its labels are not recoverable), so its test
checks the reconstructed chart against documented rules, not the page's own figure.  All of this is
flagged in README.md.
"""

from statemachine import State

from ttt_sm.runtime import Data, Junction, TickChart

from ._log import act

URL = "https://mathworks.com/help/stateflow/ug/use-connective-junctions-to-represent-multiple-paths.html"


class SegmentLabelFormat(TickChart):
    """S1 -> j ``E[condition_1]{condition_action}/transition_action``; j -> S2 ``[condition_2]``;
    j -> S3 ``[condition_3]``.  <URL above>

    The page's caption names states S1, S2 and S3; the narrative uses condition_1 (first
    segment), condition_2 (to S2) and the actions condition_action and transition_action.  The
    transition action is put on the first segment, as in the state-to-state label format; it
    runs only once the whole path is valid.  The third segment's condition is not named by the
    narrative; condition_3 is false here.
    """

    local = (
        Data("log", "list", [], "actions in the order they ran"),
        Data("condition_1", "bool", True, "condition of the segment from S1"),
        Data("condition_2", "bool", True, "condition of the segment to S2"),
        Data("condition_3", "bool", False, "condition of the segment to S3"),
    )

    S1 = State(initial=True)
    S2 = State()
    S3 = State()
    j = Junction()

    E = S1.to(j, cond="condition_1", before="condition_action", on="transition_action")
    j.to(S2, cond="condition_2")
    j.to(S3, cond="condition_3")

    on_exit_S1 = act("exitS1")
    on_enter_S2 = act("entS2")
    on_enter_S3 = act("entS3")
    condition_action = act("condition_action")
    transition_action = act("transition_action")


def test_a_segment_label_runs_like_a_state_label_condition_action_first_transition_action_between_exit_and_entry():
    """Label format for a transition segment entering a junction.  <URL above>

    The label format is the same as for a transition between states.  On the event, S1's
    outgoing transition matches; condition_1 is true, so condition_action runs; the junction's
    outgoing segments are checked and condition_2 holds, so S1 -> S2 is a valid state-to-state
    transition; S1's exit actions, S1 inactive, transition_action, S2 active, S2's entry action.
    """
    chart = SegmentLabelFormat()
    chart.log.clear()
    chart.send("E")
    assert chart.log == ["condition_action", "exitS1", "transition_action", "entS2"]
    assert chart.active_ids == frozenset({"S2"})


class IfThenElse(TickChart):
    """A -> j ``E_one``; j -> B ``[C_one]`` (1); j -> C ``[C_two]`` (2); j -> D (3).  <URL above>

    The caption names states A, B, C and D; the narrative tests [C_one] first, then [C_two],
    reaching C; D is the unconditional "else" segment (the 2002 notation page: "Otherwise ... the
    transition A to D is valid").
    """

    local = (
        Data("log", "list", [], "actions in the order they ran"),
        Data("C_one", "bool", False, "condition to B"),
        Data("C_two", "bool", True, "condition to C"),
    )

    A = State(initial=True)
    B = State()
    C = State()
    D = State()
    j = Junction()

    E_one = A.to(j)
    j.to(B, cond="C_one")
    j.to(C, cond="C_two")
    j.to(D)

    on_exit_A = act("exitA")
    on_enter_B = act("entB")
    on_enter_C = act("entC")
    on_enter_D = act("entD")


def test_if_then_else_takes_the_first_segment_in_order_whose_condition_holds():
    """If-Then-Else Decision Construct.  <URL above>

    A active, [C_two] true, E_one: the segment from A to the junction is valid; the junction's
    segments are tested in their order: [C_one] is not valid, [C_two] is; the complete transition
    A -> C is valid: A's exit action exitA(), A inactive, C active, C's entry action entC().
    """
    chart = IfThenElse()
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["exitA", "entC"]
    assert chart.active_ids == frozenset({"C"})


class SelfLoopThroughAJunction(TickChart):
    """A -> j ``E_one``; j -> B ``[C_one]{A_one}`` (1); j -> A ``/A_two`` (2).  <URL above>

    The narrative: the segment "labeled with a condition and action" to B fails, the segment
    back to A is valid, and A_two runs between A's exit and entry.  Whether B's segment carries
    its action in braces or after a slash does not matter here: it fails before either could run.
    """

    local = (
        Data("log", "list", [], "actions in the order they ran"),
        Data("C_one", "bool", False, "condition to B"),
    )

    A = State(initial=True)
    B = State()
    j = Junction()

    E_one = A.to(j)
    j.to(B, cond="C_one", before="A_one")
    j.to(A, on="A_two")

    on_enter_A = act("entA")
    on_exit_A = act("exitA")
    on_enter_B = act("entB")
    A_one = act("A_one")
    A_two = act("A_two")


def test_a_self_loop_through_a_junction_exits_runs_the_transition_action_and_reenters():
    """Self-Loop Transition.  <URL above; 2000: semant10>

    A active, [C_one] false, E_one: the segment from A to the junction is valid; the segment to B
    fails ([C_one] false), so A -> B is not valid; the segment from the junction back to A is
    valid: A's exit action, A inactive, the transition action A_two, A active, A's entry action.
    """
    chart = SelfLoopThroughAJunction()
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["exitA", "A_two", "entA"]
    assert chart.active_ids == frozenset({"A"})


class ForLoop(TickChart):
    """A -> j ``E_one{i = 0}``; j -> j ``[i < 10]{i++; func1()}`` (1); j -> B (2).  <URL above>"""

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
        """Condition actions ``i++`` and ``func1()``."""
        self.i += 1
        self.log.append("func1")


def test_a_for_loop_is_a_junction_self_loop_whose_condition_actions_repeat_until_the_condition_fails():
    """For-Loop Construct.  <URL above>

    A active, E_one: the segment from A to the junction is valid and its condition action
    ``i = 0`` runs.  Of the junction's two segments the self-loop is tested first: [i < 10] holds,
    its condition actions ``i++`` and the call to func1 run, and the junction is tested again,
    until the condition fails (ten passes).  Then the segment to B is tested and valid: A's exit
    action, A inactive, B active, B's entry action.
    """
    chart = ForLoop()
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["i = 0"] + ["func1"] * 10 + ["exitA", "entB"]
    assert chart.i == 10
    assert chart.active_ids == frozenset({"B"})


class FlowChartNotation(TickChart):
    """RECONSTRUCTION.  A {A1 (default), j1, j2}; an inner transition of A drives a flow chart.

    <URL above>  What is remembered of the narrative: A.A1 active, ``C_one`` initially true, E_one;
    no valid transition at the root; A finds a valid inner transition to a connective junction;
    that junction has one outgoing segment, with a condition action, which runs; the next junction
    has a conditional self-loop (tested first, taken while C_one holds) and an unconditional
    segment.  Chart used here:

        A --inner E_one--> j1 ;  j1 --{ca_one}--> j2 ;
        j2 --[C_one]{ca_loop}--> j2 (1) ;  j2 --> A1 (2)

    ``ca_loop`` makes C_one false (the page's ``C_one()`` is a function that turns false; guards
    here are pure, so the change is a condition action).  Where the unconditional segment leads on
    the page is not recoverable; A1 is used (an inner transition to the active substate, which
    exits and re-enters it, as in the inner-transition page).
    """

    local = (
        Data("log", "list", [], "actions in the order they ran"),
        Data("C_one", "bool", True, "condition of the self-loop"),
    )

    class A(State.Compound):
        A1 = State(initial=True)
        j1 = Junction()
        j2 = Junction()
        j1.to(j2, before="ca_one")
        j2.to(j2, cond="C_one", before="ca_loop")
        j2.to(A1)

    E_one = A.to(A.j1, internal=True)

    during_A = act("durA")
    on_exit_A = act("exitA")
    on_enter_A1 = act("entA1")
    during_A1 = act("durA1")
    on_exit_A1 = act("exitA1")
    ca_one = act("ca_one")

    def ca_loop(self):
        """Condition action of the self-loop: logs, and makes C_one false."""
        self.log.append("ca_loop")
        self.C_one = False


def test_flow_chart_notation_runs_each_segment_condition_action_as_the_flow_passes_and_loops_on_the_junction():
    """Flow Chart Notation (reconstructed chart, see the class docstring).  <URL above>

    A.A1 active, C_one true, E_one: no valid transition at the root; A's during action; A's inner
    transition to j1 is valid; j1's only segment runs its condition action; at j2 the conditional
    self-loop is tested first and taken while C_one holds (its condition action runs once and makes
    C_one false); tested again it fails, so the unconditional segment is taken to A1: the path ends
    at a state, A1 is exited and entered again; A is not exited; A1's during action does not run.
    """
    chart = FlowChartNotation()
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["durA", "ca_one", "ca_loop", "exitA1", "entA1"]
    assert chart.active_ids == frozenset({"A", "A1"})


class CommonSourceToMultipleDestinations(TickChart):
    """A -> j (no label); j -> B ``E_one`` (1); j -> C ``E_two`` (2).  <URL above>"""

    local = (Data("log", "list", [], "actions in the order they ran"),)

    A = State(initial=True)
    B = State()
    C = State()
    j = Junction()

    A.to(j)
    j.to(B, event="E_one")
    j.to(C, event="E_two")

    on_exit_A = act("exitA")
    on_enter_B = act("entB")
    on_enter_C = act("entC")


def test_events_on_the_segments_after_a_junction_choose_the_destination():
    """Transition from a Common Source to Multiple Destinations.  <URL above>

    A active, E_two: the segment from A to the junction (no event: valid for any event) is valid;
    of the junction's segments, the one triggered by E_one is not valid for E_two, the one
    triggered by E_two is: the complete transition A -> C is valid: A's exit action, A inactive,
    C active, C's entry action.
    """
    chart = CommonSourceToMultipleDestinations()
    chart.log.clear()
    chart.send("E_two")
    assert chart.log == ["exitA", "entC"]
    assert chart.active_ids == frozenset({"C"})


class MultipleSourcesToCommonDestination(TickChart):
    """A -> j ``E_one``; B -> j ``E_two``; j -> C.  <URL above>

    Reading choice: each source has its own event (the next example puts the event on the common
    segment instead).  B is never reached from A in this fragment, so python-statemachine's
    connectivity check is switched off.
    """

    validate_disconnected_states = False  # B is a source only, as on the page

    local = (Data("log", "list", [], "actions in the order they ran"),)

    A = State(initial=True)
    B = State()
    C = State()
    j = Junction()

    E_one = A.to(j)
    E_two = B.to(j)
    j.to(C)

    on_exit_A = act("exitA")
    on_exit_B = act("exitB")
    on_enter_C = act("entC")


def test_paths_from_several_sources_can_share_their_last_segment():
    """Transition from Multiple Sources to a Common Destination.  <URL above>

    A active, E_one: the segment from A to the junction is valid and so is the segment from the
    junction to C: A's exit action, A inactive, C active, C's entry action.  B's segment plays no
    part (B is not active).
    """
    chart = MultipleSourcesToCommonDestination()
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["exitA", "entC"]
    assert chart.active_ids == frozenset({"C"})


class SourceToDestinationOnACommonEvent(TickChart):
    """A -> j and B -> j (no labels); j -> C ``E_one`` (the common event).  <URL above>

    The example starts with B active (``start_value="B"``).  The event's name is as remembered;
    the order of actions does not depend on it.
    """

    validate_disconnected_states = False  # B is entered only through start_value, as on the page

    local = (Data("log", "list", [], "actions in the order they ran"),)

    A = State(initial=True)
    B = State()
    C = State()
    j = Junction()

    A.to(j)
    B.to(j)
    E_one = j.to(C)

    on_exit_A = act("exitA")
    on_exit_B = act("exitB")
    on_enter_C = act("entC")


def test_an_event_on_the_common_segment_serves_every_source():
    """Transition from a Source to a Destination Based on a Common Event.  <URL above>

    B active, E_one: the segment from B to the junction is valid and so is the junction's segment
    to C, triggered by the common event: B's exit action, B inactive, C active, C's entry action.
    """
    chart = SourceToDestinationOnACommonEvent(start_value="B")
    chart.log.clear()
    chart.send("E_one")
    assert chart.log == ["exitB", "entC"]
    assert chart.active_ids == frozenset({"C"})


class BacktrackingFlow(TickChart):
    """A -> j1 ``[c1]{a1}`` (1); A -> j2 ``[c2]{a2}`` (2); j1 -> j3; j2 -> j3;
    j3 -> j4 ``[c3]{a3}``; j4 -> B ``[c4]``.  <URL above>

    The narrative: from A a segment ``[c1]`` with action a1 and a segment ``[c2]`` with a2; on
    either path ``[c3]`` with a3 and then ``[c4]``, which fails and sends control back to A.  The
    two paths meet at j3 (the reading that makes a3 the same segment on both).  No event is named:
    the transitions have none, and the wake-up is a tick.
    """

    local = (
        Data("log", "list", [], "actions in the order they ran"),
        Data("c1", "bool", True, "condition c1"),
        Data("c2", "bool", True, "condition c2"),
        Data("c3", "bool", True, "condition c3"),
        Data("c4", "bool", False, "condition c4"),
    )

    A = State(initial=True)
    B = State()
    j1 = Junction()
    j2 = Junction()
    j3 = Junction()
    j4 = Junction()

    A.to(j1, cond="c1", before="a1")
    A.to(j2, cond="c2", before="a2")
    j1.to(j3)
    j2.to(j3)
    j3.to(j4, cond="c3", before="a3")
    j4.to(B, cond="c4")

    on_exit_A = act("exitA")
    on_enter_B = act("entB")
    a1 = act("a1")
    a2 = act("a2")
    a3 = act("a3")


def test_backtracking_retries_the_next_path_and_does_not_undo_condition_actions():
    """Backtrack in Flow Charts.  <URL above>

    A active; c1, c2 and c3 true, c4 false: the chart finds the segment [c1] from A valid, so a1
    runs; c3 is true, so a3 runs; c4 is not true, so control backtracks to A; the next segment
    from A, [c2], is valid, so a2 runs; c3 is true, so a3 runs again; c4 is not true, so control
    backtracks to A again; no path is left, A stays active, the chart sleeps.  The condition actions
    that ran are not undone (a3 ran twice): the page's point about backtracking.
    """
    chart = BacktrackingFlow()
    chart.log.clear()
    chart.tick()
    assert chart.log == ["a1", "a3", "a2", "a3"]
    assert chart.active_ids == frozenset({"A"})
