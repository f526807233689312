"""docs/tutorial.md's browser path, done in Chromium as the tutorial says: its quoted status line holds."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

from ttt_sm.debug.views import fmt_value

from .conftest import Cockpit
from .test_cockpit_browser import go_to_tick, open_cockpit, show

TUTORIAL = (Path(__file__).resolve().parents[2] / "docs" / "tutorial.md").read_text(encoding="utf-8")


def browser_part() -> str:
    part = re.search(r"### The same in the browser\n(.*?)\n## ", TUTORIAL, re.S)
    assert part, "docs/tutorial.md has no browser part"
    return part.group(1)


def test_the_tutorials_browser_path_stops_where_it_says(page: Any, cockpit: Cockpit) -> None:
    text = browser_part()
    status = re.search(r"The status line says `([^`]+)`", text)
    menu = re.search(r"choose \*\*([^*]+)\*\*", text)
    assert status and menu, "the browser part quotes the status line and the menu item"
    open_cockpit(page, cockpit)
    page.get_by_role("button", name="Pause", exact=True).click()
    go_to_tick(page, 0)
    page.wait_for_function("document.querySelector('[data-role=status]').textContent.startsWith('replayed to step 0')")
    show(page, "DriveInit1")
    page.locator('[data-role="diagram"] [data-state="DriveInit1.run.initialise.turn_back"]').click()
    page.get_by_role("menuitem", name=menu.group(1)).click()
    page.wait_for_selector('[data-role="breakpoints"] li[data-breakpoint]')
    page.get_by_role("button", name="Run", exact=True).click()
    page.wait_for_function("document.querySelector('[data-role=status]').dataset.kind === 'breakpoint'")
    shown = page.locator('[data-role="status"]').text_content()
    assert " ".join(status.group(1).split()) in shown, shown
    turn_back = page.locator('[data-role="diagram"] [data-state="DriveInit1.run.initialise.turn_back"]')
    assert turn_back.get_attribute("data-active") == "true"
    edge = page.locator('[data-transition~="DriveInit1.turn_fwd->turn_back"]').first
    assert edge.get_attribute("data-taken-count") == "1"
    assert "`q_true` (simulation only) at 170 deg" in " ".join(text.split())
    q_true = page.locator('[data-role="signals"] tr[data-signal="q_true"]')
    assert "simulation only" in q_true.text_content()
    q1 = re.search(r"\(\[([-\d.]+) ", q_true.locator('[data-role="value"]').text_content())
    assert q1 is not None and abs(float(q1.group(1)) - 170.0) < 0.5
    # 5. Tick: pos_out turns back by inc each chart tick
    pos_out = page.locator('[data-role="watch"] tr[data-datum="DriveInit1.pos_out"] [data-role="value"]')
    before = cockpit.session.call(lambda d: d.robot.charts["DriveInit1"].pos_out)
    tick = int(page.locator('[data-role="tick"]').text_content())
    page.get_by_role("button", name="Tick", exact=True).click()
    page.wait_for_function(f"document.querySelector('[data-role=tick]').textContent === '{tick + 1}'")
    after, inc = cockpit.session.call(lambda d: (d.robot.charts["DriveInit1"].pos_out,
                                                 d.robot.charts["DriveInit1"].inc))
    assert after == before - inc != before
    expected = fmt_value(after, "rad")
    page.wait_for_function("document.querySelector('[data-datum=\"DriveInit1.pos_out\"] [data-role=value]')"
                           f".textContent === {json.dumps(expected)}")
    assert pos_out.text_content() == expected
    # the values that Tick changed are marked, the others not
    watch = page.locator('[data-role="watch"]')
    assert watch.locator('tr[data-datum="DriveInit1.pos_out"]').get_attribute("data-changed") == "true"
    assert watch.locator('tr[data-datum="DriveInit1.ini2"]').get_attribute("data-changed") == "false"
    cockpit.session.call(lambda d: d.delete())
