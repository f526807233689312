"""Conformance: "Control Chart Execution by Using Temporal Logic" and the operator pages (Stateflow).

https://mathworks.com/help/stateflow/ug/using-temporal-logic-in-state-actions-and-transitions.html
Operator reference pages (their "Examples" sections are narrated examples too):
https://mathworks.com/help/stateflow/ref/after.html, .../ref/at.html, .../ref/before.html,
.../ref/every.html, .../ref/temporalcount.html, .../ref/elapsed.html, .../ref/duration.html
2002 edition (trigger vs conditional notation):
http://www.ece.northwestern.edu/local-apps/matlabhelp/toolbox/stateflow/action40.html

The guide's operator table and the reference pages give short examples (a label and one sentence
of behaviour).  Each becomes a test: the chart is the example's label on a state A (transitions go
to B), driven by events or ticks, asserting the event count / tick / chart time at which the
action runs or the transition is taken.

Conventions of these tests (the runtime's reading of the pages; see README.md):
- Construction is the chart's first wake-up, at chart time 0; it activates A.  ``chart.tick()``
  advances chart time by ``tick_period_s`` and wakes the chart; ``chart.send("E")`` wakes it on E
  without advancing time.
- ``after(n, tick)`` counts wake-ups *after* the one that activated the state: the first
  ``chart.tick()`` after activation is wake-up 1.  ``temporalCount(tick)`` is 0 in the entry action.
- An E-based counter counts broadcasts of E processed while its state is active; it restarts at 0
  each time the state is (re)activated, so an E that activates the state is not counted.
- Absolute time since activation is (ticks since activation) x tick_period_s; a threshold n sec is
  reached when that product is >= n (the tests use the page's 12.3 s with a 0.1 s tick: reached at
  tick 123, where 123 * 0.1 == 12.3 in floating point; a runtime that adds 0.1 per tick would reach
  12.299999999999972 and be one tick late, so it must count ticks, as Stateflow's discrete charts do
  with integer counters).
- "Trigger notation" ``after(5,E)`` (transition valid only when the chart processes E) is written
  as a transition assigned to event E with the temporal guard: ``E = A.to(B, cond=after(5, "E"))``
  (the 2002 page: ``after(10,CLK)`` is equivalent to ``CLK[after(10,CLK)]``).  "Conditional
  notation" ``[after(5,E)]`` (tested on any wake-up) is a transition with no event.
- ``on after(3,E): act`` is ``E = action_on(A, "act", cond=after(3, "E"))``;
  ``on after(3,tick): act`` is the unassigned ``action_on(A, "act", cond=after(3))``.
"""

import pytest
from statemachine import State

from ttt_sm.runtime import Data, TickChart, action_on, after, at, before, duration, every

from ._log import act

URL = "https://mathworks.com/help/stateflow/ug/using-temporal-logic-in-state-actions-and-transitions.html"
REF = "https://mathworks.com/help/stateflow/ref/"


def _log():
    return Data("log", "list", [], "actions in the order they ran")


def _sends(chart, event, n):
    """Send `event` n times; return the log length after each send."""
    lengths = []
    for _ in range(n):
        chart.send(event)
        lengths.append(len(chart.log))
    return lengths


def _ticks(chart, n):
    """Tick n times; return the log length after each tick."""
    lengths = []
    for _ in range(n):
        chart.tick()
        lengths.append(len(chart.log))
    return lengths


# --- after ---------------------------------------------------------------------------------------


class OnAfter3E(TickChart):
    """A: ``on after(3,E): disp("ON")``; G toggles A <-> B.  <URL, table row after(n,E)>"""

    local = (_log(),)
    A = State(initial=True)
    B = State()
    E = action_on(A, "disp_ON", cond=after(3, "E"))
    G = A.to(B) | B.to(A)
    disp_ON = act("ON")


def test_on_after_3_E_runs_at_every_E_from_the_third_one_on():
    """after(n,E) row / after page: the status message is shown each time the chart processes E,
    starting with the third broadcast of E since A became active."""
    chart = OnAfter3E()
    chart.log.clear()
    assert _sends(chart, "E", 5) == [0, 0, 1, 2, 3]


def test_the_E_counter_restarts_when_the_state_is_reactivated():
    """Guide, above the table: the chart resets the counter of each operator every time the
    associated state reactivates.  After leaving and re-entering A, two more E do nothing, the third
    shows the message."""
    chart = OnAfter3E()
    _sends(chart, "E", 3)
    chart.send("G")
    chart.send("G")
    chart.log.clear()
    assert _sends(chart, "E", 3) == [0, 0, 1]


class After5E(TickChart):
    """A -> B labelled ``after(5,E)`` (trigger notation).  <URL, table row after(n,E)>"""

    local = (_log(),)
    A = State(initial=True)
    B = State()
    E = A.to(B, cond=after(5, "E"))
    on_exit_A = act("exitA")
    on_enter_B = act("entB")


def test_after_5_E_leaves_the_state_on_the_fifth_E():
    """after(n,E) row: the transition is taken when the chart processes E, from the fifth broadcast
    of E since A became active."""
    chart = After5E()
    chart.log.clear()
    _sends(chart, "E", 4)
    assert chart.active_ids == frozenset({"A"})
    chart.send("E")
    assert chart.log == ["exitA", "entB"]
    assert chart.active_ids == frozenset({"B"})


class After7Tick(TickChart):
    """A -> B labelled ``after(7,tick)[temp > 98.6]``.  <URL, table row after(n,tick)>"""

    local = (_log(), Data("temp", "float", 99.0, "temperature"))
    A = State(initial=True)
    B = State()
    A.to(B, cond=[after(7), "temp > 98.6"])
    stop = B.to(A)
    on_enter_B = act("entB")


def test_after_7_tick_leaves_on_the_seventh_wake_up_when_the_condition_holds():
    """after(n,tick) row: leave A when the chart has woken up at least seven times since A became
    active and temp > 98.6 (true throughout here): at the seventh tick."""
    chart = After7Tick(tick_period_s=0.1)
    chart.log.clear()
    assert _ticks(chart, 7) == [0, 0, 0, 0, 0, 0, 1]
    assert chart.active_ids == frozenset({"B"})


def test_after_7_tick_still_leaves_later_when_the_condition_becomes_true_later():
    """Same label; temp is 98 until after the seventh wake-up and 99 at the ninth: "at least seven"
    stays true, so the transition is taken at the ninth tick."""
    chart = After7Tick(tick_period_s=0.1)
    chart.temp = 98.0
    chart.log.clear()
    _ticks(chart, 8)
    assert chart.active_ids == frozenset({"A"})
    chart.temp = 99.0
    chart.tick()
    assert chart.active_ids == frozenset({"B"})


class OnAfterSec(TickChart):
    """A: ``on after(12.3,sec): temp = LOW;``.  <URL, table row after(n,sec)>"""

    local = (_log(), Data("temp", "float", 1.0, "1 = HIGH, 0 = LOW"))
    A = State(initial=True)
    B = State()
    action_on(A, "set_temp_low", cond=after(12.3, "sec"))
    stop = A.to(B)

    def set_temp_low(self):
        self.log.append("temp=LOW")
        self.temp = 0.0


def test_on_after_12_3_sec_acts_at_every_wake_up_from_12_3_seconds_on():
    """after(n,sec) row: from 12.3 s after A became active, each wake-up sets temp to LOW.  With a
    0.1 s tick: nothing through tick 122 (12.2 s), then at ticks 123 and 124."""
    chart = OnAfterSec(tick_period_s=0.1)
    chart.log.clear()
    _ticks(chart, 122)
    assert chart.log == []
    assert chart.temp == 1.0
    assert _ticks(chart, 2) == [1, 2]
    assert chart.temp == 0.0


class AfterSecFromEntry(TickChart):
    """A -> B on go; B -> C labelled ``after(1,sec)``.  <REF after.html>"""

    local = (_log(),)
    A = State(initial=True)
    B = State()
    C = State()
    go = A.to(B)
    B.to(C, cond=after(1, "sec"))
    on_enter_C = act("entC")


def test_absolute_time_is_counted_from_the_activation_of_the_associated_state():
    """after page: true once at least n units of time have elapsed since the associated state
    became active.  B is entered at 0.75 s (by an event, between ticks of 0.25 s); it is left at
    the first tick at or after 1.75 s, the fourth tick after its entry."""
    chart = AfterSecFromEntry(tick_period_s=0.25)
    _ticks(chart, 3)
    chart.send("go")
    _ticks(chart, 3)
    assert chart.active_ids == frozenset({"B"})
    chart.tick()
    assert chart.active_ids == frozenset({"C"})


class AfterMsecUsec(TickChart):
    """A -> B labelled ``after(500,msec)``; C -> D labelled ``after(250000,usec)``.  <REF after>"""

    local = (_log(),)
    A = State(initial=True)
    B = State()
    C = State()
    D = State()
    A.to(B, cond=after(500, "msec"))
    jump = B.to(C)
    C.to(D, cond=after(250000, "usec"))


def test_msec_and_usec_are_the_same_clock_in_other_units():
    """after page: time_unit is sec, msec or usec.  With a 0.25 s tick, 500 msec is reached at the
    second tick after activation and 250000 usec at the first."""
    chart = AfterMsecUsec(tick_period_s=0.25)
    chart.tick()
    assert chart.active_ids == frozenset({"A"})
    chart.tick()
    assert chart.active_ids == frozenset({"B"})
    chart.send("jump")
    chart.tick()
    assert chart.active_ids == frozenset({"D"})


# --- trigger notation vs conditional notation -----------------------------------------------------


class TriggerNotation(TickChart):
    """A -> B labelled ``E[after(2,E) && ok]`` (after(2,E) in trigger notation).  <URL>"""

    local = (_log(), Data("ok", "bool", False, "an extra guard"))
    A = State(initial=True)
    B = State()
    E = A.to(B, cond=[after(2, "E"), "ok"])
    F = B.to(A)


class ConditionalNotation(TickChart):
    """A -> B labelled ``[after(2,E) && ok]`` (conditional notation: no trigger).  <URL>"""

    local = (_log(), Data("ok", "bool", False, "an extra guard"))
    A = State(initial=True)
    B = State()
    A.to(B, cond=[after(2, "E"), "ok"])
    E = B.to(B)
    F = B.to(A)


def test_an_event_based_temporal_transition_in_trigger_notation_is_tested_only_on_its_event():
    """Trigger notation: the transition can be taken only while the chart processes E (2002 page:
    "must occur as soon as" the count is reached, on E).  After two E the count is reached but ok is
    false; ok becomes true; a wake-up on F or a tick does not take it; the next E does."""
    chart = TriggerNotation(tick_period_s=0.1)
    _sends(chart, "E", 2)
    chart.ok = True
    chart.send("F")
    chart.tick()
    assert chart.active_ids == frozenset({"A"})
    chart.send("E")
    assert chart.active_ids == frozenset({"B"})


def test_an_event_based_temporal_condition_in_conditional_notation_is_tested_on_any_wake_up():
    """Conditional notation (2002 page: a condition on a non-base event "can occur no sooner than"
    the count, "depending on when" the other event occurs): after two E, with ok now true, the
    next wake-up of any kind (here event F) takes the transition."""
    chart = ConditionalNotation(tick_period_s=0.1)
    _sends(chart, "E", 2)
    assert chart.active_ids == frozenset({"A"})
    chart.ok = True
    chart.send("F")
    assert chart.active_ids == frozenset({"B"})


class EnteredByE(TickChart):
    """B -> A on E; A -> C labelled ``after(2,E)``.  <URL>"""

    local = (_log(),)
    B = State(initial=True)
    A = State()
    C = State()
    E = B.to(A) | A.to(C, cond=after(2, "E"))


def test_the_E_that_activates_a_state_does_not_count_for_that_state():
    """Inferred from "the counter resets every time the associated state reactivates": the first E
    enters A (its counter starts at 0 after that E); A is left at the third E, the second one
    processed while A is active."""
    chart = EnteredByE()
    chart.send("E")
    chart.send("E")
    assert chart.active_ids == frozenset({"A"})
    chart.send("E")
    assert chart.active_ids == frozenset({"C"})


# --- at ------------------------------------------------------------------------------------------


class OnAt3E(TickChart):
    """A: ``on at(3,E): disp("ON")``.  <URL, table row at(n,E); REF at.html>"""

    local = (_log(),)
    A = State(initial=True)
    B = State()
    E = action_on(A, "disp_ON", cond=at(3, "E"))
    stop = A.to(B)
    disp_ON = act("ON")


def test_on_at_3_E_runs_only_at_the_third_E():
    """at(n,E) row: the message is shown when the chart processes the third broadcast of E after A
    became active, and only then."""
    chart = OnAt3E()
    chart.log.clear()
    assert _sends(chart, "E", 5) == [0, 0, 1, 1, 1]


class At5E(TickChart):
    """A -> B labelled ``at(5,E)[ok]`` (trigger notation).  <REF at.html>"""

    local = (_log(), Data("ok", "bool", True, "an extra guard"))
    A = State(initial=True)
    B = State()
    E = A.to(B, cond=[at(5, "E"), "ok"])


def test_at_5_E_is_true_at_the_fifth_E_only():
    """at page: transition out of A when the chart processes the fifth broadcast of E since A became
    active.  With ok true it is taken at the fifth E; with ok false at the fifth E, a sixth E (ok now
    true) does not take it: at is true at exactly n."""
    chart = At5E()
    _sends(chart, "E", 4)
    assert chart.active_ids == frozenset({"A"})
    chart.send("E")
    assert chart.active_ids == frozenset({"B"})

    late = At5E()
    late.ok = False
    _sends(late, "E", 5)
    late.ok = True
    late.send("E")
    assert late.active_ids == frozenset({"A"})


class ConditionalAt5E(TickChart):
    """A -> B labelled ``[at(5,E) && ok]`` (conditional notation).  <REF at.html>"""

    local = (_log(), Data("ok", "bool", False, "an extra guard"))
    A = State(initial=True)
    B = State()
    A.to(B, cond=[at(5, "E"), "ok"])
    E = B.to(B)
    F = B.to(A)


def test_conditional_at_5_E_is_tested_on_any_event_while_exactly_five_E_have_occurred():
    """at page: ``[at(5,E)]`` transitions out of A if A has been active for exactly five broadcasts
    of E.  After five E (ok false), a wake-up on F with ok true takes it (the count is still 5)."""
    chart = ConditionalAt5E()
    _sends(chart, "E", 5)
    assert chart.active_ids == frozenset({"A"})
    chart.ok = True
    chart.send("F")
    assert chart.active_ids == frozenset({"B"})


class At7Tick(TickChart):
    """A -> B labelled ``at(7,tick)[temp > 98.6]``.  <URL, table row at(n,tick)>"""

    local = (_log(), Data("temp", "float", 98.0, "temperature"))
    A = State(initial=True)
    B = State()
    A.to(B, cond=[at(7), "temp > 98.6"])
    stop = B.to(A)


def test_at_7_tick_fires_only_at_the_seventh_wake_up():
    """at(n,tick) row: transition when the chart wakes up for the seventh time since A became
    active, but only if temp > 98.6.  With temp = 99 from the start: at tick 7.  With temp 98 at
    tick 7 and 99 afterwards: never (checked to tick 20)."""
    chart = At7Tick(tick_period_s=0.1)
    chart.temp = 99.0
    _ticks(chart, 6)
    assert chart.active_ids == frozenset({"A"})
    chart.tick()
    assert chart.active_ids == frozenset({"B"})

    missed = At7Tick(tick_period_s=0.1)
    _ticks(missed, 7)
    missed.temp = 99.0
    _ticks(missed, 13)
    assert missed.active_ids == frozenset({"A"})


def test_on_at_2_sec_runs_once_when_exactly_two_seconds_have_elapsed():
    """at page: at(n,sec) is true if exactly n seconds have elapsed since A became active.  With a
    0.25 s tick: only at tick 8.  (The page allows at(n,sec) in standalone MATLAB charts and refuses
    it in charts inside Simulink models; the runtime follows the standalone rule, docs/runtime.md.)"""

    class OnAtSec(TickChart):
        """A: ``on at(2,sec): disp("ON")``.  <REF at.html>"""

        local = (_log(),)
        A = State(initial=True)
        B = State()
        action_on(A, "disp_ON", cond=at(2, "sec"))
        stop = A.to(B)
        disp_ON = act("ON")

    chart = OnAtSec(tick_period_s=0.25)
    chart.log.clear()
    assert _ticks(chart, 10) == [0, 0, 0, 0, 0, 0, 0, 1, 1, 1]


# --- before --------------------------------------------------------------------------------------


class OnBefore3E(TickChart):
    """A: ``on before(3,E): disp("ON")``.  <REF before.html>"""

    local = (_log(),)
    A = State(initial=True)
    B = State()
    E = action_on(A, "disp_ON", cond=before(3, "E"))
    stop = A.to(B)
    disp_ON = act("ON")


def test_on_before_3_E_runs_at_the_first_and_second_E_only():
    """before page: the message is shown when the chart processes the first and the second
    broadcast of E after A became active."""
    chart = OnBefore3E()
    chart.log.clear()
    assert _sends(chart, "E", 4) == [1, 2, 2, 2]


class Before5E(TickChart):
    """A -> B labelled ``before(5,E)[ok]`` (trigger notation).  <REF before.html>"""

    local = (_log(), Data("ok", "bool", False, "an extra guard"))
    A = State(initial=True)
    B = State()
    E = A.to(B, cond=[before(5, "E"), "ok"])


def test_before_5_E_is_true_only_while_fewer_than_five_E_have_occurred():
    """before page: transition out of A when the chart processes E, but only if A has been active
    for fewer than five broadcasts of E.  ok true at the fourth E: taken; ok true only from the
    fifth E on: never taken."""
    early = Before5E()
    _sends(early, "E", 3)
    early.ok = True
    early.send("E")
    assert early.active_ids == frozenset({"B"})

    late = Before5E()
    _sends(late, "E", 4)
    late.ok = True
    _sends(late, "E", 3)
    assert late.active_ids == frozenset({"A"})


class Before7Tick(TickChart):
    """A -> B labelled ``before(7,tick)[temp > 98.6]``.  <REF before.html>"""

    local = (_log(), Data("temp", "float", 98.0, "temperature"))
    A = State(initial=True)
    B = State()
    A.to(B, cond=[before(7), "temp > 98.6"])
    stop = B.to(A)


def test_before_7_tick_is_true_only_during_the_first_six_wake_ups():
    """before page: true if the chart has woken up fewer than n times since A became active.  temp
    high at the sixth tick: taken; temp high only from the seventh tick on: never taken."""
    early = Before7Tick(tick_period_s=0.1)
    _ticks(early, 5)
    early.temp = 99.0
    early.tick()
    assert early.active_ids == frozenset({"B"})

    late = Before7Tick(tick_period_s=0.1)
    _ticks(late, 6)
    late.temp = 99.0
    _ticks(late, 5)
    assert late.active_ids == frozenset({"A"})


class OnBeforeSec(TickChart):
    """A: ``on before(1,sec): disp("ON")``.  <REF before.html>"""

    local = (_log(),)
    A = State(initial=True)
    B = State()
    action_on(A, "disp_ON", cond=before(1, "sec"))
    stop = A.to(B)
    disp_ON = act("ON")


def test_on_before_1_sec_runs_at_wake_ups_earlier_than_one_second():
    """before page: true if fewer than n units of time have elapsed since A became active.  With a
    0.25 s tick: at 0.25, 0.5 and 0.75 s, not at 1.0 s or later."""
    chart = OnBeforeSec(tick_period_s=0.25)
    chart.log.clear()
    assert _ticks(chart, 6) == [1, 2, 3, 3, 3, 3]


# --- every ---------------------------------------------------------------------------------------


class OnEvery3E(TickChart):
    """A: ``on every(3,E): disp("ON")``.  <REF every.html>"""

    local = (_log(),)
    A = State(initial=True)
    B = State()
    E = action_on(A, "disp_ON", cond=every(3, "E"))
    stop = A.to(B)
    disp_ON = act("ON")


def test_on_every_3_E_runs_at_every_third_E():
    """every row / every page: the message is shown at every third broadcast of E after A became
    active: the third and the sixth of seven."""
    chart = OnEvery3E()
    chart.log.clear()
    assert _sends(chart, "E", 7) == [0, 0, 1, 1, 1, 2, 2]


class OnEvery5Tick(TickChart):
    """A: ``on every(5,tick): disp("ON")``.  <REF every.html>"""

    local = (_log(),)
    A = State(initial=True)
    B = State()
    action_on(A, "disp_ON", cond=every(5))
    stop = A.to(B)
    disp_ON = act("ON")


def test_on_every_5_tick_runs_at_every_fifth_wake_up():
    """every page: true at every nth wake-up since A became active: the fifth and the tenth."""
    chart = OnEvery5Tick(tick_period_s=0.1)
    chart.log.clear()
    assert _ticks(chart, 10) == [0, 0, 0, 0, 1, 1, 1, 1, 1, 2]


# --- temporalCount, elapsed ----------------------------------------------------------------------


class CountE(TickChart):
    """A: ``on E: y = M(temporalCount(E));``.  <REF temporalcount.html>"""

    local = (_log(),)
    A = State(initial=True)
    B = State()
    E = action_on(A, "read_count")
    stop = A.to(B)

    def read_count(self):
        self.log.append(self.temporal_count("E"))


def test_temporalCount_E_numbers_the_E_processed_since_activation():
    """temporalCount page: each time the chart processes E, the action reads the next element of M:
    the count is 1 at the first E, 2 at the second, 3 at the third."""
    chart = CountE()
    chart.log.clear()
    _sends(chart, "E", 3)
    assert chart.log == [1, 2, 3]


class CountTicks(TickChart):
    """A: ``en,du: M(temporalCount(tick)+1) = u;``; G toggles A <-> B.  <REF temporalcount.html>"""

    local = (_log(),)
    A = State(initial=True)
    B = State()
    G = A.to(B) | B.to(A)

    def on_enter_A(self):
        self.log.append(self.temporal_count("tick"))

    def during_A(self):
        self.log.append(self.temporal_count("tick"))


def test_temporalCount_tick_is_zero_at_entry_and_counts_wake_ups_then_restarts():
    """temporalCount page: ``M(temporalCount(tick)+1) = u`` stores u in successive elements of M,
    the first at index 1 on entry (count 0), then 1, 2, ... at each wake-up.  Re-entering A starts
    again from 0."""
    chart = CountTicks(tick_period_s=0.1)
    _ticks(chart, 2)
    assert chart.log == [0, 1, 2]
    chart.send("G")
    chart.send("G")
    chart.tick()
    assert chart.log == [0, 1, 2, 0, 1]


class ElapsedSec(TickChart):
    """A: ``en,du: y = elapsed(sec);`` (same as et and temporalCount(sec)).  <REF elapsed.html>"""

    local = (_log(),)
    A = State(initial=True)
    B = State()
    stop = A.to(B)

    def on_enter_A(self):
        self.log.append(self.temporal_count("sec"))

    def during_A(self):
        self.log.append(self.temporal_count("sec"))


def test_elapsed_sec_is_the_time_since_activation():
    """elapsed page: y holds the seconds since A became active (elapsed(sec), et and
    temporalCount(sec) are the same).  With a 0.25 s tick: 0 on entry, then 0.25, 0.5."""
    chart = ElapsedSec(tick_period_s=0.25)
    _ticks(chart, 2)
    assert chart.log == [0.0, 0.25, 0.5]


# --- duration ------------------------------------------------------------------------------------


class DurationGuard(TickChart):
    """A -> B labelled ``[duration(x>=0) > 0.1]``; leave/back move A <-> C.  <REF duration.html>"""

    inputs = (Data("x", "float", 0.0, "input x"),)
    local = (_log(),)
    A = State(initial=True)
    B = State()
    C = State()
    A.to(B, cond=duration("x >= 0") > 0.1)
    leave = A.to(C)
    back = C.to(A)


def test_duration_leaves_once_the_condition_has_held_for_longer_than_the_limit():
    """duration page: transition out of A when x has been >= 0 for longer than 0.1 s.  x >= 0 from
    A's activation (t = 0); 0.0625 s tick: 0.0625 s at tick 1 (stay), 0.125 s at tick 2 (leave)."""
    chart = DurationGuard(tick_period_s=0.0625)
    chart.tick()
    assert chart.active_ids == frozenset({"A"})
    chart.tick()
    assert chart.active_ids == frozenset({"B"})


def test_duration_restarts_when_the_condition_becomes_false():
    """duration page, Tips: the chart resets the value when the condition becomes false; the
    condition is evaluated at each time step.  x >= 0 at tick 1, x < 0 at tick 2, x >= 0 again from
    tick 3: at tick 3 the duration is at most one tick (0.0625 s): stay; by tick 5 it exceeds 0.1 s:
    gone.  (Tick 4 is not asserted: the pages do not say whether the first true sample counts 0 or
    one period; see README.md.)"""
    chart = DurationGuard(tick_period_s=0.0625)
    chart.tick()
    chart.x = -1.0
    chart.tick()
    chart.x = 0.0
    chart.tick()
    assert chart.active_ids == frozenset({"A"})
    chart.tick()
    chart.tick()
    assert chart.active_ids == frozenset({"B"})


def test_duration_restarts_when_the_state_is_reentered():
    """duration page: the value is the time the condition stays true *and* the state has been
    active; the chart resets it when the state becomes inactive.  A is active 0-0.0625 s, left,
    re-entered at 0.125 s: still A at 0.1875 s (only 0.0625 s since re-entry), B at 0.25 s."""
    chart = DurationGuard(tick_period_s=0.0625)
    chart.tick()
    chart.send("leave")
    chart.tick()
    chart.send("back")
    chart.tick()
    assert chart.active_ids == frozenset({"A"})
    chart.tick()
    assert chart.active_ids == frozenset({"B"})


class DurationInAction(TickChart):
    """A: ``en,du: y = duration(x>5,msec);``.  <REF duration.html>"""

    inputs = (Data("x", "float", 6.0, "input x"),)
    local = (_log(),)
    A = State(initial=True)
    B = State()
    stop = A.to(B)

    def on_enter_A(self):
        self.log.append(self.duration("x > 5", "msec"))

    def during_A(self):
        self.log.append(self.duration("x > 5", "msec"))


@pytest.mark.xfail(
    strict=False,
    reason="the API gives duration() only as a guard comparison (duration('x > 0') >= 2.0); it has "
    "no way to read its value in an action; written as self.duration('x > 5', 'msec')",
)
def test_duration_in_a_state_action_reads_the_milliseconds_the_condition_has_held():
    """duration page: store the number of milliseconds since x became greater than 5 and A became
    active.  x = 6 throughout; 0.25 s tick: 0 on entry, then 250, 500."""
    chart = DurationInAction(tick_period_s=0.25)
    _ticks(chart, 2)
    assert chart.log == [0.0, 250.0, 500.0]
