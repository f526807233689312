"""Live while writing in Chromium: the /lab page of ``ttt-sm gui --lab`` as a student saves their chart.

It starts with the tutorial's solution (every check shown passing), then a
save with a syntax error (the page shows file:line; the chart that loaded
keeps running: the simulated time goes on), then a save that fixes it and
renames a state (the diagram is drawn anew with it; the checks run again).
Each step waits on what the page shows, with generous timeouts; screenshots
of the passing and the failing page go to ``TTT_SM_LAB_SHOTS`` when set.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Any

from ttt_sm.debug.debugger import Debugger
from ttt_sm.params import load_params
from ttt_sm.web.lab_watch import LabTask, LabWatch
from ttt_sm.web.session import Session

from .conftest import open_page, served, text_of
from .lab_files import RENAMED, broken, broken_line, fixed, lab_folder, save

#: Waits in the page, ms: the checks run in a low-priority process on a busy machine.
CHECKS_MS = 600_000
RELOAD_MS = 120_000


def test_the_lab_page_follows_the_students_saves(browser: Any, tmp_path: Path) -> None:
    folder = tmp_path / "my_init3"
    ex = lab_folder(folder)
    argv = (sys.executable, "-m", "ttt_sm.lab.live", str(folder), "--nice", "5")
    watch = LabWatch(LabTask(ex.title, ex.slot, ex.chart_file, ex.class_name, argv), poll_s=0.1)
    dbg = Debugger.build(load_params(), seed=0, slots=watch.first_slots())
    session = Session(dbg, speed=1.0, running=True)
    shots = Path(os.environ.get("TTT_SM_LAB_SHOTS") or tmp_path)
    shots.mkdir(parents=True, exist_ok=True)
    page = browser.new_page(viewport={"width": 1400, "height": 900})
    try:
        with served(session, lab=watch) as cockpit:
            open_page(page, cockpit, "/lab")
            page.wait_for_selector('[data-role=diagram] [data-state="DriveInit3.approach"]', timeout=RELOAD_MS)
            page.wait_for_selector("[data-role=checks-status][data-status=done]", timeout=CHECKS_MS)
            verdicts = page.locator("[data-role=checks] li .verdict").all_text_contents()
            assert verdicts == ["PASS"] * 9
            assert text_of(page, "score") == "9/9"
            assert page.locator("[data-role=error]").is_hidden()
            assert "MyDriveInit3" in text_of(page, "running")
            page.screenshot(path=str(shots / "lab-passing.png"), full_page=True)

            save(ex.chart_file, broken())
            where = f"{ex.chart_file}:{broken_line()}: syntax error"
            page.wait_for_function("(w) => document.querySelector('[data-role=error]').textContent.startsWith(w)",
                                   arg=where, timeout=RELOAD_MS)
            assert page.locator("[data-role=error]").is_visible()
            t = float(text_of(page, "sim-time"))
            page.wait_for_function("(t) => Number(document.querySelector('[data-role=sim-time]').textContent) > t",
                                   arg=t + 0.5, timeout=RELOAD_MS)  # the chart that loaded last runs on
            assert text_of(page, "mode") == "running"
            assert page.locator('[data-role=diagram] [data-state="DriveInit3.approach"]').count() == 1
            assert text_of(page, "score") == "9/9"  # the last good chart's checks stay
            page.screenshot(path=str(shots / "lab-failing.png"), full_page=True)

            save(ex.chart_file, fixed())
            page.wait_for_selector(f'[data-role=diagram] [data-state="DriveInit3.{RENAMED[1]}"]', timeout=RELOAD_MS)
            assert page.locator(f'[data-role=diagram] [data-state="DriveInit3.{RENAMED[0]}"]').count() == 0
            page.wait_for_selector("[data-role=error]", state="hidden", timeout=RELOAD_MS)
            page.wait_for_function(
                "() => document.querySelector('[data-role=checks-status]').textContent.includes('chart 2')"
                " && document.querySelectorAll('[data-role=checks] li').length >= 1", timeout=CHECKS_MS)
            first = page.locator("[data-role=checks] li").first
            assert first.get_attribute("data-passed") == "true"
            assert first.get_attribute("data-check") == "drive 3 initialises from the rest pose"
    finally:
        page.close()
