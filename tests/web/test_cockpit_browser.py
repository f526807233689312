"""The chart cockpit in a real browser (Debian's Chromium through Playwright): what a person sees.

One session for the module (``cockpit``, as fast as it goes when run); each test
drives it through the page, as a student would, and compares what the page
shows with a debugger of its own run to the same point (same seed).
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import pytest

from ttt_sm.debug.debugger import Debugger
from ttt_sm.debug.views import fmt_value
from ttt_sm.params import load_params
from ttt_sm.scenario.loader import load_scenario
from ttt_sm.scenario.suite import coverage_dict, run_scenarios

from .conftest import SCENARIOS, Cockpit, open_page

TIMEOUT_MS = 60_000


def open_cockpit(page: Any, cockpit: Cockpit) -> None:
    page.set_default_timeout(TIMEOUT_MS)
    open_page(page, cockpit, "/charts", timeout_ms=TIMEOUT_MS)
    page.wait_for_selector("[data-state]")


def show(page: Any, chart: str) -> None:
    """Show a chart's whole picture (every state drawn)."""
    page.locator('[data-role="chart-tabs"]').get_by_role("button", name=chart, exact=True).click()
    whole = page.locator('[data-role="view-bar"]').get_by_role("button", name="Whole chart")
    if whole.count():
        whole.click()
    page.wait_for_function("(() => { const d = document.querySelector('[data-role=diagram]');"
                           f" return d.dataset.chart === '{chart}' && d.dataset.view === 'whole'"
                           " && !d.dataset.loading; })()")


def shown_tick(page: Any) -> int:
    return int(page.locator('[data-role="tick"]').text_content())


def go_to_tick(page: Any, tick: int) -> None:
    """Replay to a chart tick with the time slider.

    The slider's range is the run so far as the page last heard it: a tick the session has passed
    but the page not yet shown would be clamped to the old end (seen once in CI), so this waits for
    the range to reach the tick first, as a person would see the knob's track grow.
    """
    page.wait_for_function(f"Number(document.querySelector('[data-role=slider]').max) >= {tick}")
    page.locator('[data-role="slider"]').fill(str(tick))
    page.wait_for_function(f"document.querySelector('[data-role=tick]').textContent === '{tick}'"
                           " && document.querySelector('[data-role=mode]').textContent === 'paused'")


def active_shown(page: Any) -> set[str]:
    return set(page.eval_on_selector_all('[data-role="diagram"] [data-state][data-active="true"]',
                                         "els => els.map(e => e.dataset.stateId)"))


def test_the_index_links_every_page_and_controls_have_names(page: Any, cockpit: Cockpit) -> None:
    page.goto(cockpit.page_url("/"))
    assert page.get_by_role("link", name="Charts").get_attribute("href") == "/charts"
    open_cockpit(page, cockpit)
    for name in ("Run", "Pause", "Step", "Tick", "Next"):
        assert page.get_by_role("button", name=name, exact=True).is_visible()
    assert page.get_by_role("combobox", name="Speed").is_visible()
    assert page.get_by_role("slider", name="Time slider").is_visible()
    float(page.locator('[data-role="sim-time"]').text_content())


def test_the_page_opens_on_the_chart_the_tutorial_starts_with(page: Any, cockpit: Cockpit) -> None:
    # issue 27: it opened on Safety, the last tab; docs/tutorial.md begins with DriveInit1
    open_cockpit(page, cockpit)
    page.wait_for_function("(() => { const d = document.querySelector('[data-role=diagram]');"
                           " return d.dataset.chart && !d.dataset.loading; })()")
    first = page.locator('[data-role="chart-tabs"] button').first.text_content()
    assert first == "DriveInit1"
    assert page.locator('[data-role="diagram"]').get_attribute("data-chart") == first


def test_the_highlighted_states_are_the_robots_configuration_at_the_paused_tick(
        page: Any, cockpit: Cockpit) -> None:
    open_cockpit(page, cockpit)
    go_to_tick(page, 0)
    page.get_by_label("Condition", exact=True).fill("DriveInit1.pos_Encoder > 90deg")  # the condition language
    page.get_by_role("button", name="Add condition").click()
    page.get_by_role("button", name="Run", exact=True).click()
    page.wait_for_function("document.querySelector('[data-role=status]').dataset.kind === 'breakpoint'")
    tick = shown_tick(page)
    where = cockpit.session.call(lambda d: (d.robot.chart_ticks, d.where()))
    assert tick == where[0] > 0
    for chart, states in where[1].items():
        show(page, chart)
        assert active_shown(page) == set(states), chart
    cockpit.session.call(lambda d: d.delete())


def test_a_click_breakpoint_stops_the_run_at_the_tick_the_state_is_entered(page: Any, cockpit: Cockpit) -> None:
    ref = Debugger.build(load_params(), seed=0)
    ref.add_breakpoint("enter DriveInit1.turn_back")
    expected = ref.run(30).chart_ticks
    open_cockpit(page, cockpit)
    go_to_tick(page, 0)
    show(page, "DriveInit1")
    page.locator('[data-role="diagram"] [data-state="DriveInit1.run.initialise.turn_back"]').click()
    page.get_by_role("menuitem", name="Break on entering DriveInit1.turn_back").click()
    page.wait_for_selector('[data-role="breakpoints"] li[data-breakpoint]')
    page.get_by_role("button", name="Run", exact=True).click()
    page.wait_for_function("document.querySelector('[data-role=status]').dataset.kind === 'breakpoint'")
    assert shown_tick(page) == expected
    turn_back = page.locator('[data-role="diagram"] [data-state="DriveInit1.run.initialise.turn_back"]')
    assert turn_back.get_attribute("data-active") == "true"
    edge = page.locator('[data-transition~="DriveInit1.turn_fwd->turn_back"]').first
    assert int(edge.get_attribute("data-taken-count")) == 1
    cockpit.session.call(lambda d: d.delete())


def test_step_and_tick_advance_by_one(page: Any, cockpit: Cockpit) -> None:
    open_cockpit(page, cockpit)
    cockpit.session.call(lambda d: d.furthest_tick >= 1000 or d.run(3.0))
    go_to_tick(page, 10)
    t0 = float(page.locator('[data-role="sim-time"]').text_content())
    page.get_by_role("button", name="Step", exact=True).click()
    page.wait_for_function(f"parseFloat(document.querySelector('[data-role=sim-time]').textContent) > {t0}")
    assert float(page.locator('[data-role="sim-time"]').text_content()) == pytest.approx(t0 + 0.001)
    tick = shown_tick(page)
    page.get_by_role("button", name="Tick", exact=True).click()
    page.wait_for_function(f"document.querySelector('[data-role=tick]').textContent === '{tick + 1}'")
    assert shown_tick(page) == tick + 1
    # Next: to the next chart tick that takes a transition, as the debugger's next does
    ref = Debugger.build(load_params(), seed=0)
    ref.step(ref.steps_of_tick(tick + 1))
    expected = ref.next(10.0)
    assert expected.kind == "transition"
    page.get_by_role("button", name="Next", exact=True).click()
    page.wait_for_function("document.querySelector('[data-role=status]').dataset.kind === 'transition'")
    assert shown_tick(page) == expected.chart_ticks
    newest = page.locator('[data-role="trace"] tbody tr').first.locator("td").first.text_content()
    assert int(newest) == ref.trace.records[-1].tick, (newest, expected.chart_ticks)


def test_the_slider_replays_to_the_tick_asked_for_and_shows_its_data(page: Any, cockpit: Cockpit) -> None:
    open_cockpit(page, cockpit)
    cockpit.session.call(lambda d: d.furthest_tick >= 1000 or d.run(3.0))
    ref = Debugger.build(load_params(), seed=0)
    ref.step(ref.steps_of_tick(700))
    expected = fmt_value(ref.robot.charts["DriveInit1"].pos_out, "rad")
    show(page, "DriveInit1")
    go_to_tick(page, 700)
    row = page.locator('[data-role="watch"] tr[data-datum="DriveInit1.pos_out"] [data-role="value"]')
    page.wait_for_function("document.querySelector('[data-datum=\"DriveInit1.pos_out\"] [data-role=value]')"
                           f".textContent === {json.dumps(expected)}")
    assert row.text_content() == expected
    assert active_shown(page) == set(ref.where()["DriveInit1"])
    assert "chart tick 700" in page.locator('[data-role="status"]').text_content()


def test_coverage_colours_equal_the_report(page: Any, cockpit: Cockpit, tmp_path: Any) -> None:
    name = "drive_1_turns_back_at_a_hard_stop.yaml"
    report = run_scenarios([load_scenario(SCENARIOS / name)], load_params(), coverage=True)
    assert report.coverage is not None
    expected = coverage_dict(report.coverage)["DriveInit1"]
    open_cockpit(page, cockpit)
    show(page, "DriveInit1")

    def colours() -> tuple[set[str], set[str]]:
        entered = set(page.eval_on_selector_all('[data-role="diagram"] [data-state][data-coverage="entered"]',
                                                "els => els.map(e => e.dataset.stateId)"))
        never = set(page.eval_on_selector_all('[data-role="diagram"] [data-state][data-coverage="never"]',
                                              "els => els.map(e => e.dataset.stateId)"))
        return entered, never

    # Run from the page
    page.get_by_label("Scenario files").select_option(name)
    page.get_by_role("button", name="Run scenarios").click()
    page.wait_for_function("document.querySelector('[data-role=coverage-summary]').textContent.includes('passed')",
                           timeout=120_000)
    entered, never = colours()
    assert entered == set(expected["entered"])
    assert never == set(expected["missing_states"])
    edges = page.eval_on_selector_all('[data-role="diagram"] [data-index]',
                                      "els => els.map(e => [e.dataset.index, e.dataset.coverage])")
    labels = {t.label: t.index for t in cockpit.session.chart_classes["DriveInit1"].structure().transitions}
    taken = {labels[x] for x in expected["taken"]}
    assert edges and all(
        colour == ("taken" if any(int(i) in taken for i in index.split()) else "never") for index, colour in edges)
    # Load the same report, as `ttt-sm scenario run --coverage --json` writes it
    page.get_by_role("button", name="Clear coverage").click()
    page.wait_for_function("document.querySelector('[data-role=diagram]').dataset.coverage === 'off'")
    path = tmp_path / "coverage.json"
    path.write_text(json.dumps(report.to_dict()))
    page.get_by_label("Coverage report").set_input_files(str(path))
    page.wait_for_function("document.querySelector('[data-role=diagram]').dataset.coverage === 'on'")
    assert colours() == (entered, never)


def test_a_click_on_a_transition_breaks_when_it_is_taken(page: Any, cockpit: Cockpit) -> None:
    ref = Debugger.build(load_params(), seed=0)
    ref.add_breakpoint("transition DriveInit1 turn_fwd->turn_back")
    expected = ref.run(30).chart_ticks
    open_cockpit(page, cockpit)
    go_to_tick(page, 0)
    show(page, "DriveInit1")
    edge = page.locator('[data-role="diagram"] [data-transition~="DriveInit1.turn_fwd->turn_back"]').first
    edge.locator("text").first.click()  # its label, as a person clicks it
    page.get_by_role("menuitem", name="Break when DriveInit1 turn_fwd->turn_back is taken").click()
    page.wait_for_selector('[data-role="breakpoints"] li[data-breakpoint]')
    page.get_by_role("button", name="Run", exact=True).click()
    page.wait_for_function("document.querySelector('[data-role=status]').dataset.kind === 'breakpoint'")
    assert shown_tick(page) == expected
    assert edge.get_attribute("data-taken-count") == "1"
    cockpit.session.call(lambda d: d.delete())


def test_an_event_posted_from_the_page_stops_at_its_event_breakpoint(page: Any, cockpit: Cockpit) -> None:
    ref = Debugger.build(load_params(), seed=0)
    ref.add_breakpoint("event Control.button")
    ref.post("Control", "button", symbol=1.0)  # as `post Control button symbol=1` reads it
    expected = ref.run(30)
    assert expected.kind == "breakpoint"
    open_cockpit(page, cockpit)
    go_to_tick(page, 0)
    show(page, "Control")
    page.get_by_label("Event breakpoint").select_option("Control.button")
    page.get_by_role("button", name="Add event breakpoint").click()
    page.wait_for_selector('[data-role="breakpoints"] li[data-breakpoint]')
    page.get_by_label("Event to post").select_option("Control.button")
    page.get_by_label("Event data").fill("symbol=1")
    page.get_by_role("button", name="Post", exact=True).click()
    page.wait_for_function("document.querySelector('[data-role=actions]').textContent.includes('button')")
    assert cockpit.session.call(lambda d: [a.describe() for a in d.actions]) == [a.describe() for a in ref.actions]
    page.get_by_role("button", name="Run", exact=True).click()
    page.wait_for_function("document.querySelector('[data-role=status]').dataset.kind === 'breakpoint'")
    assert shown_tick(page) == expected.chart_ticks
    assert "Control.button" in page.locator('[data-role="status"]').text_content()
    cockpit.session.call(lambda d: (d.delete(), d.replay(0)))


def test_an_input_set_forced_and_released_from_the_watch(page: Any, cockpit: Cockpit) -> None:
    open_cockpit(page, cockpit)
    cockpit.session.call(lambda d: d.furthest_tick >= 1000 or d.run(3.0))
    go_to_tick(page, 10)
    show(page, "DriveInit1")
    row = page.locator('[data-role="watch"] tr[data-datum="DriveInit1.stop"]')
    row.get_by_label("value for DriveInit1.stop").fill("1")
    row.get_by_role("button", name="Force DriveInit1.stop").click()
    page.wait_for_function("document.querySelector('[data-datum=\"DriveInit1.stop\"]').dataset.forced === 'true'")
    page.get_by_role("button", name="Tick", exact=True).click()
    page.wait_for_function("document.querySelector('[data-state=\"DriveInit1.stopped\"]').dataset.active === 'true'")
    assert row.locator('[data-role="value"]').text_content() == "True"
    assert cockpit.session.call(lambda d: d.where()["DriveInit1"]) == ["stopped"]
    row.get_by_role("button", name="Release DriveInit1.stop").click()
    page.wait_for_function("document.querySelector('[data-datum=\"DriveInit1.stop\"]').dataset.forced === 'false'")
    row.get_by_label("value for DriveInit1.stop").fill("0")
    row.get_by_role("button", name="Set DriveInit1.stop").click()
    page.wait_for_function("document.querySelector('[data-role=actions]').textContent.includes('stop')")
    page.get_by_role("button", name="Tick", exact=True).click()
    page.wait_for_function("document.querySelector('[data-state=\"DriveInit1.stopped\"]').dataset.active === 'false'")
    assert "stopped" not in cockpit.session.call(lambda d: d.where()["DriveInit1"])
    cockpit.session.call(lambda d: d.replay(0))


def test_sub_charts_open_in_place_and_on_their_own_and_stay_lit(page: Any, cockpit: Cockpit) -> None:
    open_cockpit(page, cockpit)
    go_to_tick(page, 0)
    page.get_by_label("Breakpoint spec").fill("enter Control.field_pen_down")
    page.get_by_role("button", name="Add", exact=True).click()
    page.get_by_role("button", name="Run", exact=True).click()
    page.wait_for_function("document.querySelector('[data-role=status]').dataset.kind === 'breakpoint'")
    active = set(cockpit.session.call(lambda d: d.where()["Control"]))
    assert {"Drawing_playing_field", "field_pen_down"} <= active
    page.locator('[data-role="chart-tabs"]').get_by_role("button", name="Control", exact=True).click()
    bar = page.locator('[data-role="view-bar"]')
    diagram = page.locator('[data-role="diagram"]')

    def shown(view: str) -> set[str]:
        page.wait_for_function("(() => { const d = document.querySelector('[data-role=diagram]');"
                               f" return d.dataset.view === '{view}' && !d.dataset.loading; }})()")
        return set(diagram.locator("[data-state]").evaluate_all("els => els.map(e => e.dataset.stateId)"))

    bar.get_by_role("button", name="Overview").click()
    closed = shown("overview")
    assert "Drawing_playing_field" in closed and "field_pen_down" not in closed  # the overview: sub-charts closed
    assert active_shown(page) == active & closed  # the closed sub-chart the chart is in is lit
    bar.get_by_role("button", name="open sub-chart Drawing_playing_field in place").click()
    opened = shown("overview+Drawing_playing_field")
    assert {"field_pen_down", "to_line"} <= opened and "wait_1" not in opened  # the others stay closed
    assert active_shown(page) == active & opened
    bar.get_by_role("button", name="open sub-chart Drawing_playing_field on its own").click()
    alone = shown("Drawing_playing_field")
    assert "field_pen_down" in alone and not {"start_stop", "Erase", "Drawing_X"} & alone
    assert active_shown(page) == active & alone
    cockpit.session.call(lambda d: d.delete())


def test_a_stall_at_real_time_is_counted_and_shown_never_hidden(page: Any, cockpit: Cockpit) -> None:
    import time

    open_cockpit(page, cockpit)
    page.get_by_label("Speed", exact=True).select_option("1")
    page.get_by_role("button", name="Run", exact=True).click()
    page.wait_for_function("document.querySelector('[data-role=mode]').textContent === 'running'")
    before = cockpit.session.clock.stats()
    cockpit.session.call(lambda d: time.sleep(0.4))  # the simulation thread stalls 0.4 s at x1
    # the next paced step is late by the stall: the page shows it
    page.wait_for_function(f"Number(document.querySelector('[data-role=pace]').dataset.overruns) > {before.overruns}")
    page.get_by_role("button", name="Pause", exact=True).click()
    page.wait_for_function("document.querySelector('[data-role=mode]').textContent === 'paused'")
    after = cockpit.session.clock.stats()
    assert after.overruns > before.overruns and after.slips > before.slips and after.lost_s >= before.lost_s + 0.25
    pace = page.locator('[data-role="pace"]')
    page.wait_for_function(f"document.querySelector('[data-role=pace]').dataset.overruns === '{after.overruns}'")
    assert f"{after.slips} slip" in pace.text_content() and "s lost" in pace.text_content()
    page.get_by_label("Speed", exact=True).select_option("max")


def test_a_leaving_breakpoint_by_click_and_the_timeline_of_the_shown_chart(page: Any, cockpit: Cockpit) -> None:
    ref = Debugger.build(load_params(), seed=0)
    ref.add_breakpoint("exit DriveInit1.turn_fwd")
    expected = ref.run(30).chart_ticks
    open_cockpit(page, cockpit)
    # an earlier test set and forced DriveInit1.stop: going back keeps such inputs unless they are dropped
    page.get_by_label("drop my later inputs").check()
    go_to_tick(page, 0)
    page.get_by_label("drop my later inputs").uncheck()
    assert cockpit.session.call(lambda d: len(d.inputs.ahead)) == 0
    show(page, "DriveInit1")
    page.locator('[data-state="DriveInit1.run.initialise.turn_fwd"]').click()
    page.get_by_role("menuitem", name="Break on leaving DriveInit1.turn_fwd").click()
    page.wait_for_selector('[data-role="breakpoints"] li[data-breakpoint]')
    page.get_by_role("button", name="Run", exact=True).click()
    page.wait_for_function("document.querySelector('[data-role=status]').dataset.kind === 'breakpoint'")
    assert shown_tick(page) == expected
    assert page.locator('[data-state="DriveInit1.run.initialise.turn_fwd"]').get_attribute("data-active") == "false"
    # the timeline of DriveInit1 (asked for once a second): turn_fwd's bar ended, turn_back's runs on
    page.wait_for_function("document.querySelector('[data-timeline-state=\"DriveInit1.run.initialise.turn_back\"]')"
                           " !== null")
    assert "of DriveInit1" in page.locator('[data-role="timeline-chart"]').text_content()
    window = cockpit.session.call(lambda d: d.timeline("DriveInit1", 20))
    drawn = page.locator('[data-role="timeline"] [data-timeline-state="DriveInit1.run.initialise.turn_fwd"] .tl-bar')
    assert drawn.count() == len([iv for iv in window.intervals if iv.state == "turn_fwd"]) >= 1
    cockpit.session.call(lambda d: d.delete())


def test_a_click_on_a_red_transition_shows_a_scenario_that_takes_it(page: Any, cockpit: Cockpit, tmp_path: Any) -> None:
    open_cockpit(page, cockpit)
    show(page, "DriveInit1")
    # a report in which DriveInit1 took nothing: every edge red
    path = tmp_path / "nothing.json"
    path.write_text(json.dumps({"coverage": {"DriveInit1": {"entered": [], "taken": []}}}))
    page.get_by_label("Coverage report").set_input_files(str(path))
    # (a report an earlier test loaded may still be drawn: wait for this one's colours, not just 'on')
    edge = page.locator('[data-role="diagram"] [data-transition~="DriveInit1.turn_fwd->turn_back"]').first
    page.wait_for_function("document.querySelector('[data-role=diagram]').dataset.coverage === 'on' &&"
                           " document.querySelector('[data-role=diagram] [data-transition~=\"DriveInit1.turn_fwd"
                           "->turn_back\"]').dataset.coverage === 'never'")
    assert edge.get_attribute("data-coverage") == "never"
    index = int(edge.get_attribute("data-index").split()[0])
    label = cockpit.session.chart_classes["DriveInit1"].structure().transitions[index].label
    edge.locator("text").first.click()
    page.get_by_role("menuitem", name=f"Suggest a scenario that takes {label}").click()
    panel = page.get_by_role("region", name="Suggested scenario")
    page.wait_for_function("document.querySelector('[data-role=suggestion-yaml]').textContent.includes('expect_states')",
                           timeout=120_000)
    yaml = page.locator('[data-role="suggestion-yaml"]').text_content()
    assert "chart: DriveInit1" in yaml and "expect_states: {chart: DriveInit1" in yaml
    assert label in yaml  # the header comment names the transition it takes
    save = panel.get_by_role("link", name="Save")
    assert save.get_attribute("download").startswith(f"DriveInit1_{index}_")
    assert save.get_attribute("download").endswith(".yaml")
    with page.expect_download() as download:
        save.click()
    assert download.value.suggested_filename == save.get_attribute("download")
    assert panel.get_by_role("button", name="Copy").is_visible()
    shots = Path(os.environ.get("TTT_SM_SCREENSHOTS", str(tmp_path)))
    shots.mkdir(parents=True, exist_ok=True)
    panel.screenshot(path=str(shots / "coverage_suggestion.png"))
    page.get_by_role("button", name="Clear coverage").click()
    page.wait_for_function("document.querySelector('[data-role=diagram]').dataset.coverage === 'off'")
