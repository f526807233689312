"""The screenshots of docs/gui.md, taken in Chromium from a live cockpit.

Run as a test they go to a temporary folder (and must come out); ``make
screenshots`` runs this file with ``TTT_SM_SCREENSHOTS=docs/img`` to regenerate
the committed ones.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import pytest

from .conftest import Cockpit
from .test_cockpit_browser import go_to_tick, open_cockpit, show

SHOTS = ("gui_running.png", "gui_subchart_in_place.png", "gui_click_breakpoint.png", "gui_coverage.png")


# For each element `sel` picks in the diagram box: is it whole between the box's left and right edges?
HORIZONTALLY_WHOLE = """(sel) => {
  const d = document.querySelector('[data-role=diagram]');
  const left = d.getBoundingClientRect().left + d.clientLeft;
  return [...d.querySelectorAll(sel)].map((e) => {
    const r = e.getBoundingClientRect();
    return r.left >= left - 0.5 && r.right <= left + d.clientWidth + 0.5;
  });
}"""


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    wanted = os.environ.get("TTT_SM_SCREENSHOTS")
    return Path(wanted) if wanted else tmp_path


def wait_ready(page: Any, top: str | None = None) -> None:
    """Wait for the diagram; scroll the side bar up and the diagram to its top, or to state ``top``."""
    page.wait_for_function("!document.querySelector('[data-role=diagram]').dataset.loading")
    page.evaluate("window.scrollTo(0, 0); document.querySelector('.side').scrollTop = 0;"
                  " document.querySelector('[data-role=diagram]').scrollTop = 0")
    if top is not None:  # past the legend, to the states a picture is about
        page.evaluate("(top) => { const d = document.querySelector('[data-role=diagram]');"
                      " const s = d.querySelector(`[data-state=\"${top}\"]`);"
                      " d.scrollTop = s.getBoundingClientRect().top - d.getBoundingClientRect().top - 8; }", top)
    page.wait_for_timeout(300)


def test_the_screenshots_of_the_guide(browser: Any, cockpit: Cockpit, folder: Path) -> None:
    page = browser.new_page(viewport={"width": 1280, "height": 720})  # a laptop (issue 27)
    try:
        open_cockpit(page, cockpit)
        go_to_tick(page, 0)
        # 1. The Control chart drawing the field, paused by a breakpoint, data changed by the last frame
        page.get_by_label("Breakpoint spec").fill("enter Control.field_pen_down")
        page.get_by_role("button", name="Add", exact=True).click()
        page.get_by_role("button", name="Run", exact=True).click()
        page.wait_for_function("document.querySelector('[data-role=status]').dataset.kind === 'breakpoint'")
        page.locator('[data-role="chart-tabs"]').get_by_role("button", name="Control", exact=True).click()
        page.locator('[data-role="view-bar"]').get_by_role("button", name="Overview").click()
        wait_ready(page)
        # wider than the box: opened scrolled just enough to show the active state, its title pinned in view
        assert page.evaluate("(() => { const d = document.querySelector('[data-role=diagram]');"
                             " return d.scrollWidth > d.clientWidth && d.scrollLeft > 0; })()")
        assert page.evaluate(HORIZONTALLY_WHOLE, "[data-role=diagram-title]") == [True]
        assert page.evaluate(HORIZONTALLY_WHOLE, '[data-state-id="Drawing_playing_field"]') == [True]
        gap = page.evaluate("(() => { const d = document.querySelector('[data-role=diagram]');"
                            " const s = d.querySelector('[data-state-id=\"Drawing_playing_field\"]');"
                            " return d.getBoundingClientRect().left + d.clientLeft + d.clientWidth"
                            " - s.getBoundingClientRect().right; })()")
        assert 20 <= gap <= 30, gap  # the state at the right with its 24 px margin: no further than it takes
        page.screenshot(path=str(folder / SHOTS[0]))
        # 2. Its sub-chart opened in place
        page.get_by_role("button", name="open sub-chart Drawing_playing_field in place").click()
        wait_ready(page)
        page.screenshot(path=str(folder / SHOTS[1]))
        cockpit.session.call(lambda d: d.delete())
        # 3. A click on a state: its breakpoints
        go_to_tick(page, 0)
        show(page, "DriveInit1")
        wait_ready(page, top="DriveInit1.run")
        page.locator('[data-role="diagram"] [data-state="DriveInit1.run.initialise.turn_back"]').click()
        page.wait_for_selector('[data-role="menu"]:not([hidden])')
        page.screenshot(path=str(folder / SHOTS[2]))
        page.keyboard.press("Escape")
        assert page.locator('[data-role="menu"]').is_hidden()
        # 4. Coverage of one scenario file, coloured
        page.get_by_label("Scenario files").select_option("drive_1_turns_back_at_a_hard_stop.yaml")
        page.get_by_role("button", name="Run scenarios").click()
        page.wait_for_function("document.querySelector('[data-role=coverage-summary]').textContent"
                               ".includes('passed')", timeout=120_000)
        wait_ready(page, top="DriveInit1.run")
        page.screenshot(path=str(folder / SHOTS[3]))
        page.get_by_role("button", name="Clear coverage").click()
    finally:
        page.close()
    for name in SHOTS:
        assert (folder / name).stat().st_size > 20_000, name
