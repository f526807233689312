"""Conformance: "Record State Activity by Using History Junctions" (Stateflow).

Current title "Resume Prior Substate Activity by Using History Junctions":
https://mathworks.com/help/stateflow/ug/recording-state-activity-with-history-junctions.html
(mirrors: uk/de.mathworks.com).  Earlier edition with the Power_on/Power_off example ("History
Junctions", R2020b copy): https://cs400-web.cs.wisc.edu/nchou/s/matlab-2020b/amd64_rhel7/help/stateflow/ug/history-junctions.html
Reference page: https://mathworks.com/help/stateflow/ref/historyjunction.html

Narrated examples: the earlier edition's Power_on/Power_off chart and the current edition's lamp
(On holding Solid and Blinking, Off).  The event names are not given by the pages for the lamp;
they are chosen here.  The current page also states, as a tip, that an inner transition to a
history junction behaves like a self-loop on every substate (the example itself is on the inner
transitions page, "Inner Transition to a History Junction"); and both editions state that a
history junction applies only to the level of the hierarchy in which it appears.
"""

from statemachine import HistoryState, State

from ttt_sm.runtime import Data, TickChart

from ._log import act

URL = "https://mathworks.com/help/stateflow/ug/recording-state-activity-with-history-junctions.html"
OLD_URL = (
    "https://cs400-web.cs.wisc.edu/nchou/s/matlab-2020b/amd64_rhel7/help/stateflow/ug/history-junctions.html"
)


class Power(TickChart):
    """Power_off (default) and Power_on{H, Low (default), High}.  <OLD_URL>

    switch_on: Power_off -> Power_on; switch_off: Power_on -> Power_off; inside Power_on, Low ->
    High on up and High -> Low on down (the page does not name the inner events).
    """

    local = (Data("log", "list", [], "actions in the order they ran"),)

    Power_off = State(initial=True)

    class Power_on(State.Compound):
        h = HistoryState()
        Low = State(initial=True)
        High = State()
        up = Low.to(High)
        down = High.to(Low)

    switch_on = Power_off.to(Power_on)
    switch_off = Power_on.to(Power_off)

    on_enter_Power_off = act("entPower_off")
    on_exit_Power_off = act("exitPower_off")
    on_enter_Power_on = act("entPower_on")
    on_exit_Power_on = act("exitPower_on")
    on_enter_Low = act("entLow")
    on_exit_Low = act("exitLow")
    on_enter_High = act("entHigh")
    on_exit_High = act("exitHigh")


def test_the_first_entry_follows_the_default_transition():
    """Power_on is entered for the first time: its default transition picks Low."""
    chart = Power()
    chart.log.clear()
    chart.send("switch_on")
    assert chart.log == ["exitPower_off", "entPower_on", "entLow"]
    assert chart.active_ids == frozenset({"Power_on", "Low"})


def test_a_reentry_resumes_the_last_active_substate():
    """Earlier edition's example: Power_on.High is active when switch_off occurs, so Power_on exits
    and Power_off becomes active; at the next switch_on, High, the last active substate, becomes
    active again (the history junction decides from the second entry on)."""
    chart = Power()
    chart.send("switch_on")
    chart.send("up")
    chart.log.clear()
    chart.send("switch_off")
    assert chart.log == ["exitHigh", "exitPower_on", "entPower_off"]
    chart.send("switch_on")
    assert chart.log == ["exitHigh", "exitPower_on", "entPower_off", "exitPower_off", "entPower_on", "entHigh"]
    assert chart.active_ids == frozenset({"Power_on", "High"})


class Lamp(TickChart):
    """Off and On{H, Solid (default), Blinking}; the lamp example.  <URL above>

    Events (chosen here): switch_on / switch_off between Off and On; blink / steady between Solid and
    Blinking.  The page does not say which of Off and On is the chart's default: Off is used.
    """

    local = (Data("log", "list", [], "actions in the order they ran"),)

    Off = State(initial=True)

    class On(State.Compound):
        h = HistoryState()
        Solid = State(initial=True)
        Blinking = State()
        blink = Solid.to(Blinking)
        steady = Blinking.to(Solid)

    switch_on = Off.to(On)
    switch_off = On.to(Off)
    refresh = On.to(On.h, internal=True)   # inner transition of On ending on its history junction

    on_enter_On = act("entOn")
    on_exit_On = act("exitOn")
    on_enter_Solid = act("entSolid")
    on_exit_Solid = act("exitSolid")
    on_enter_Blinking = act("entBlinking")
    on_exit_Blinking = act("exitBlinking")


def test_the_lamp_returns_to_the_mode_it_was_in_when_switched_off():
    """Current page: On's first activation runs its default transition (Solid); the history
    junction records the active substate, so going On -> Off -> On makes the last active substate
    (here Blinking) active again: the lamp returns to its previous mode."""
    chart = Lamp()
    chart.send("switch_on")
    assert chart.active_ids == frozenset({"On", "Solid"})
    chart.send("blink")
    chart.send("switch_off")
    assert chart.active_ids == frozenset({"Off"})
    chart.log.clear()
    chart.send("switch_on")
    assert chart.log == ["entOn", "entBlinking"]
    assert chart.active_ids == frozenset({"On", "Blinking"})


def test_an_inner_transition_to_the_history_junction_exits_and_reenters_the_active_substate():
    """Tip on the current page: an inner transition to a history junction is like a self-loop on
    every substate; when it is valid the chart exits and at once re-enters the active substate.
    On itself is neither exited nor entered."""
    chart = Lamp()
    chart.send("switch_on")
    chart.send("blink")
    chart.log.clear()
    chart.send("refresh")
    assert chart.log == ["exitBlinking", "entBlinking"]
    assert chart.active_ids == frozenset({"On", "Blinking"})


class NestedLamp(TickChart):
    """As Lamp, but Blinking holds Slow (default) and Fast; the history junction is in On only.

    <URL above; rule "applies only to the level of the hierarchy in which it appears", OLD_URL>
    """

    local = (Data("log", "list", [], "actions in the order they ran"),)

    Off = State(initial=True)

    class On(State.Compound):
        h = HistoryState()
        Solid = State(initial=True)

        class Blinking(State.Compound):
            Slow = State(initial=True)
            Fast = State()
            faster = Slow.to(Fast)

        blink = Solid.to(Blinking)

    switch_on = Off.to(On)
    switch_off = On.to(Off)

    on_enter_On = act("entOn")
    on_enter_Blinking = act("entBlinking")
    on_enter_Slow = act("entSlow")
    on_enter_Fast = act("entFast")


def test_a_history_junction_remembers_only_its_own_level():
    """Rule (both editions): the history junction applies only to the level of the hierarchy in
    which it appears.  On remembers Blinking, but Blinking has no history junction of its own, so
    re-entering it follows its default transition to Slow, although Fast was active."""
    chart = NestedLamp()
    chart.send("switch_on")
    chart.send("blink")
    chart.send("faster")
    chart.send("switch_off")
    chart.log.clear()
    chart.send("switch_on")
    assert chart.log == ["entOn", "entBlinking", "entSlow"]
    assert chart.active_ids == frozenset({"On", "Blinking", "Slow"})
