"""The Safety chart in the chart cockpit (/charts), in Chromium: a twin fault trips it, the page says why, Reset.

The session runs on the twin behind :class:`~ttt_sm.faults.twin.FaultyArm`
(the fault matrix's arm, docs/safety.md): a drive is blocked mid-stroke while
the arm draws the field, the Safety chart stops the arm, the page shows its
reason; the fault is cleared and a person clicks Reset: the chart goes through
``reinitialising`` back to ``monitoring`` while the drives are initialised
again, and the debugger's trace holds the new initialisation.  /game and
/operate share the same Safety controls (web/static/session.js), and /operate
refuses Trigger while the chart holds the arm.
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from ttt_sm.debug.debugger import Debugger
from ttt_sm.faults.twin import FaultyArm
from ttt_sm.params import load_params
from ttt_sm.twin.sim import ArmSim
from ttt_sm.web.session import Session

from .conftest import Cockpit, open_page, served, text_of

SHOT = "gui_safety.png"
#: Waits in the page, ms: the simulation runs as fast as it goes but the machine may be busy.
LONG = 240_000


@pytest.fixture
def faulty(tmp_path: Path) -> Iterator[tuple[Cockpit, FaultyArm]]:
    """A session on the twin with faults to inject, paused at power-on, as fast as it goes when run."""
    params = load_params()
    sim = ArmSim(params, seed=0)
    arm = FaultyArm(sim)
    dbg = Debugger.build(params, seed=0, arm=arm, truth=sim.truth)
    session = Session(dbg, speed=None, running=False, trace_path=tmp_path / "trace.jsonl")
    with served(session) as cockpit:
        yield cockpit, arm


def run_to_pen_down(page: Any, session: Session, run: str = "Run") -> None:
    """Run from the page (its button ``run``) to the field's first pen-down (a breakpoint), paused there."""
    session.call(lambda d: d.add_breakpoint("enter Control.field_pen_down"))
    page.get_by_role("button", name=run, exact=True).click()
    deadline = time.monotonic() + LONG / 1e3
    while not (session.mode == "paused" and session.call(lambda d: d.breakpoints[0].hits) >= 1):
        assert time.monotonic() < deadline, "the breakpoint on the field's first pen-down was not hit"
        time.sleep(0.05)
    session.call(lambda d: d.delete(None))


def watch_safety_states(page: Any) -> None:
    """Every state the page's Safety indicator shows, in order, into ``window.safetyStates``."""
    page.evaluate("() => { const el = document.querySelector('[data-role=\"safety-state\"]');"
                  " window.safetyStates = [el.dataset.state]; new MutationObserver(() => {"
                  " const s = el.dataset.state; if (window.safetyStates.at(-1) !== s) window.safetyStates.push(s); })"
                  ".observe(el, { attributes: true }); }")


def test_a_blocked_drive_trips_the_safety_chart_the_cockpit_says_why_and_reset_reinitialises(
        browser: Any, faulty: tuple[Cockpit, FaultyArm], tmp_path: Path) -> None:
    cockpit, arm = faulty
    session = cockpit.session
    page = browser.new_page(viewport={"width": 1400, "height": 900})
    try:
        open_page(page, cockpit, "/charts")
        reset = page.get_by_role("button", name="Reset", exact=True)
        page.wait_for_function("document.querySelector('[data-role=safety-state]').dataset.state === 'monitoring'",
                               timeout=30_000)
        assert text_of(page, "safety-state") == "Safety: monitoring"
        assert reset.is_disabled() and page.locator('[data-role="safety"]').is_hidden()
        run_to_pen_down(page, session)

        def block_drive_2_mid_stroke(d: Debugger) -> float:
            while not d.robot.board.contact.pen_touching:
                d.step(10)
            d.step(200)
            arm.inject("motor_blocked", 2)
            return d.robot.t

        t_fault = session.call(block_drive_2_mid_stroke)
        page.get_by_role("button", name="Run", exact=True).click()
        page.wait_for_function("document.querySelector('[data-role=safety-state]').dataset.state === 'tripped'",
                               timeout=LONG)
        tripped, reason, trips = session.call(lambda d: (d.robot.tripped, str(d.robot.safety.reason),
                                                         int(d.robot.safety.trips)))
        assert tripped and trips == 1 and "drive 2" in reason, reason
        # the page says it, and why, as the chart's `reason` output says it
        banner = page.get_by_role("alert", name="safety")
        assert banner.is_visible() and text_of(page, "safety") == f"Safety stop: {reason}"
        assert banner.get_attribute("data-error") == "true"
        assert text_of(page, "safety-state") == "Safety: stopped"
        assert reset.is_enabled()
        # the Safety chart's own picture shows it in its safe state
        page.locator('[data-role="chart-tabs"]').get_by_role("button", name="Safety", exact=True).click()
        page.wait_for_function("document.querySelector('[data-role=diagram] [data-state-id=\"safe\"]')"
                               "?.dataset.active === 'true'", timeout=30_000)
        shot = Path(os.environ.get("TTT_SM_SCREENSHOTS") or tmp_path) / SHOT
        page.screenshot(path=str(shot))
        assert shot.stat().st_size > 20_000

        # the cause removed, a person resets: the drives are initialised again from where they stand
        session.call(lambda d: arm.clear())
        watch_safety_states(page)
        tick_reset = session.call(lambda d: d.robot.chart_ticks)
        reset.click()
        page.wait_for_function("document.querySelector('[data-role=status]').textContent.startsWith('Reset:')",
                               timeout=30_000)
        assert text_of(page, "status") == f"Reset: the Safety chart re-initialises the drives (it tripped on: {reason})"
        page.wait_for_function("window.safetyStates.at(-1) === 'monitoring'", timeout=LONG)
        assert page.evaluate("window.safetyStates") == ["tripped", "reinitialising", "monitoring"]
        assert page.locator('[data-role="safety"]').is_hidden() and reset.is_disabled()
        # the Reset is an input the debugger recorded, and the cockpit lists it
        page.wait_for_function("document.querySelector('[data-role=actions]').textContent"
                               ".includes('post Safety reset')", timeout=30_000)

        def after_reset(d: Debugger) -> dict[str, Any]:
            actions = [a for a in d.actions if a.kind == "post" and a.chart == "Safety" and a.name == "reset"]
            records = [r for r in d.trace.records if r.tick is not None and r.tick > tick_reset]
            return {"actions": len(actions), "initialised": d.robot.initialised, "tripped": d.robot.tripped,
                    "safety": sorted(d.robot.active("Safety")), "t": d.robot.t,
                    "passed": sorted({r.chart for r in records if r.target == "pass_pos"}),
                    "safety_trace": [(r.source, r.target) for r in records if r.chart == "Safety"]}

        done = session.call(after_reset)
        assert done["actions"] == 1 and not done["tripped"] and done["safety"] == ["monitoring"]
        assert done["safety_trace"][:2] == [("safe", "reinitialising"), ("reinitialising", "monitoring")]
        # every drive searched its switch again and passes its position through: the arm is initialised
        assert done["initialised"] and done["passed"] == ["DriveInit1", "DriveInit2", "DriveInit3"], done
        assert done["t"] > t_fault
    finally:
        page.close()


def test_operate_refuses_trigger_while_the_safety_chart_holds_the_arm_and_resets_from_its_page(
        browser: Any, faulty: tuple[Cockpit, FaultyArm]) -> None:
    cockpit, arm = faulty
    session = cockpit.session
    page = browser.new_page(viewport={"width": 1400, "height": 900})
    try:
        open_page(page, cockpit, "/operate")
        run_to_pen_down(page, session, "Run_simulation")
        session.call(lambda d: arm.inject("motor_blocked", 1))
        page.get_by_role("button", name="Run_simulation", exact=True).click()
        page.wait_for_function("document.querySelector('[data-role=safety-state]').dataset.state === 'tripped'",
                               timeout=LONG)
        reason = session.call(lambda d: str(d.robot.safety.reason))
        assert text_of(page, "safety") == f"Safety stop: {reason}"
        page.wait_for_function("document.querySelector('[data-role=why]').textContent.includes('Safety chart')",
                               timeout=30_000)
        assert text_of(page, "why") == (f"Trigger is off: the Safety chart holds the arm ({reason}): Reset it once the"
                                        " cause is removed")
        session.call(lambda d: arm.clear())
        page.get_by_role("button", name="Reset", exact=True).click()
        page.wait_for_function("document.querySelector('[data-role=safety-state]').dataset.state === 'monitoring'",
                               timeout=LONG)
        assert session.call(lambda d: (d.robot.initialised, d.robot.tripped)) == (True, False)
    finally:
        page.close()
