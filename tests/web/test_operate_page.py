"""The Operational page (/operate) in Chromium: Run_simulation, Trigger, the sliders, the graphs, CSV.

One session for the module, paused at power-on, as fast as it goes once
Run_simulation is clicked; the tests run in order on it (the arm waits at its
waiting pose after the O's test).  Test workers may split the module
(pytest-xdist's worksteal), so no test relies on another having run: the two
that need the arm at power-on get a session of their own when the module's has
already been run, and the others click Run_simulation when it is still on.  What the drawing tests assert on is the
simulated whiteboard's ink, read in the simulation thread, beside what the
page shows.

The screenshot of docs/gui.md's ``/operate`` section is taken after the O;
``make screenshots`` (``TTT_SM_SCREENSHOTS=docs/img``) writes it into docs/img.
"""

from __future__ import annotations

import csv
import io
import math
import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ttt_sm.debug.debugger import Debugger
from ttt_sm.params import load_params
from ttt_sm.web.operate import (
    MSG_DRAWING,
    MSG_INITIALISING,
    MSG_READY,
    MSG_STAIRCASE,
    MSG_TURNING_OFF,
    SAMPLE_PERIOD_S,
)
from ttt_sm.web.session import Session

from .conftest import Cockpit, open_page, served, text_of

SHOT = "gui_operate.png"
#: Waits in the page, ms: the simulation runs as fast as it goes but the machine may be busy.
LONG = 240_000


@pytest.fixture(scope="module")
def operate_cockpit(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Cockpit]:
    """A session at power-on, paused, as fast as it goes when run."""
    dbg = Debugger.build(load_params(), seed=0)
    trace = tmp_path_factory.mktemp("operate") / "trace.jsonl"
    session = Session(dbg, speed=None, running=False, trace_path=trace)
    with served(session) as cockpit:
        yield cockpit


@pytest.fixture
def powered_on(operate_cockpit: Cockpit) -> Iterator[Cockpit]:
    """The module's session while it is still at power-on (never run); otherwise one of its own, at power-on."""
    if operate_cockpit.session.call(lambda d: d.robot.t) == 0.0:
        yield operate_cockpit
        return
    session = Session(Debugger.build(load_params(), seed=0), speed=None, running=False)
    with served(session) as cockpit:
        yield cockpit


def wait_status(page: Any, text: str, timeout: int = LONG) -> None:
    page.wait_for_function("(text) => document.querySelector('[data-role=status]').textContent.trim() === text",
                           arg=text, timeout=timeout)


def open_operate(page: Any, cockpit: Cockpit) -> None:
    open_page(page, cockpit, "/operate")


def trigger(page: Any) -> Any:
    return page.get_by_role("button", name="Trigger", exact=True)


def run_until_waiting(page: Any) -> None:
    """Click Run_simulation if the session has not been run yet; wait until Trigger is on (the arm waits)."""
    run = page.get_by_role("button", name="Run_simulation", exact=True)
    if run.is_enabled():
        run.click()
    page.wait_for_function("!document.querySelector('[data-cmd=trigger]').disabled", timeout=LONG)


def fit_circle(points: np.ndarray) -> tuple[float, float, float]:
    """The least-squares circle through ``points`` (x, y rows): centre and diameter, m."""
    x, y = points[:, 0], points[:, 1]
    a = np.column_stack([x, y, np.ones_like(x)])
    c = np.linalg.lstsq(a, x * x + y * y, rcond=None)[0]
    xc, yc = c[0] / 2, c[1] / 2
    return float(xc), float(yc), 2 * math.sqrt(c[2] + xc * xc + yc * yc)


def test_trigger_is_off_before_the_arm_waits_and_a_typed_value_out_of_range_is_refused(
        browser: Any, powered_on: Cockpit) -> None:
    page = browser.new_page()
    try:
        open_operate(page, powered_on)
        assert page.get_by_role("status", name="manipulator status").text_content() == MSG_INITIALISING
        assert trigger(page).is_disabled()
        assert text_of(page, "why").startswith("Trigger is off: the manipulator is not at its waiting pose yet")
        magnitude = page.get_by_role("slider", name="Magnitude", exact=True)
        box = page.get_by_role("spinbutton", name="Magnitude (cm)", exact=True)
        magnitude.fill("4.5")  # the slider moves the box
        assert box.input_value() == "4.5"
        box.fill("12")
        check = page.get_by_role("status", name="the values typed")
        assert check.text_content() == ("Magnitude 12 is refused: it must be a number from 0 to 10 cm;"
                                        " the slider stays at 4.5 cm")
        assert box.get_attribute("aria-invalid") == "true"
        assert box.input_value() == "12" and magnitude.input_value() == "4.5"  # not clamped, not taken
        speed = page.get_by_role("spinbutton", name="Speed (0 to 5)", exact=True)
        speed.fill("-1")
        assert "Speed -1 is refused: it must be a number from 0 to 5" in str(check.text_content())
        speed.fill("2")
        box.fill("6")
        assert text_of(page, "check") == "" and box.get_attribute("aria-invalid") == "false"
        assert page.get_by_role("slider", name="Speed", exact=True).input_value() == "2"
        assert text_of(page, "speed-mm-s") == "15.0 mm/s"
    finally:
        page.close()


def test_an_o_of_6_cm_at_speed_3_is_a_circle_of_60_mm_on_the_whiteboard(
        browser: Any, powered_on: Cockpit, tmp_path: Path) -> None:
    session = powered_on.session
    page = browser.new_page(viewport={"width": 1500, "height": 1000})
    charts = browser.new_page(viewport={"width": 1200, "height": 900})
    try:
        open_operate(page, powered_on)
        page.get_by_role("button", name="Run_simulation", exact=True).click()
        wait_status(page, MSG_DRAWING)  # the field first: the Control chart's own order
        assert trigger(page).is_disabled()
        wait_status(page, MSG_READY)
        page.wait_for_function("!document.querySelector('[data-cmd=trigger]').disabled", timeout=30_000)
        page.get_by_label("Symbol", exact=True).select_option("O")
        assert text_of(page, "magnitude-means") == "the O's diameter"
        # A typed value out of range reaches the session as typed, and the session refuses it too.
        box = page.get_by_role("spinbutton", name="Magnitude (cm)", exact=True)
        box.fill("10.5")
        actions_before = session.call(lambda d: len(d.actions))
        trigger(page).click()
        page.wait_for_function("document.querySelector('[data-role=reply]').dataset.error === 'true'",
                               timeout=30_000)
        assert text_of(page, "reply") == "operate_trigger: 'magnitude_cm' must be a number from 0 to 10, got 10.5"
        assert session.call(lambda d: len(d.actions)) == actions_before  # nothing set, nothing posted
        box.fill("6")
        page.get_by_role("spinbutton", name="Speed (0 to 5)", exact=True).fill("3")
        assert text_of(page, "speed-mm-s") == "20.0 mm/s"
        open_page(charts, powered_on, "/charts")
        strokes_before, t0 = session.call(lambda d: (len(d.robot.board.strokes), d.robot.t))
        trigger(page).click()
        # the same session in the chart cockpit: Trigger's inputs and event, within a frame
        charts.wait_for_function("document.querySelector('[data-role=actions]').textContent.includes("
                                 "'post Control button')", timeout=30_000)
        assert "set Control.size 0.06" in str(charts.locator('[data-role="actions"]').text_content())
        page.wait_for_function("document.querySelector('[data-role=reply]').textContent.startsWith('Trigger:')",
                               timeout=30_000)
        assert text_of(page, "reply") == "Trigger: an O, 6 cm diameter, speed 3 (20 mm/s)"
        page.wait_for_function("document.querySelector('[data-key=what]').textContent.startsWith('an O')",
                               timeout=LONG)
        wait_status(page, MSG_READY)
        # the session's own samples, read now: it keeps the last 30 simulated seconds, and the arm goes on
        # running while the page is photographed and its CSV downloaded (on a loaded machine that was longer)
        t1, taken = session.call(lambda d: (d.robot.t, {row[0]: row for row in session.operate.stage.history}))

        def ink(d: Debugger) -> np.ndarray:
            strokes = [s for s in d.robot.board.strokes[strokes_before:] if s.author == "robot"]
            return np.vstack([s.points for s in strokes])

        points = session.call(ink)
        xc, yc, diameter = fit_circle(points)
        centre = session.call(lambda d: (d.robot.control.x0, d.robot.control.y0))
        assert abs(diameter - 0.060) <= 0.0005, diameter
        assert math.hypot(xc - centre[0], yc - centre[1]) < 0.0005
        # every ink point lies on that circle (no tail, no second stroke elsewhere)
        assert np.abs(np.hypot(points[:, 0] - xc, points[:, 1] - yc) - diameter / 2).max() < 0.0005
        precision = session.call(lambda d: session.operate.results[-1])
        assert text_of(page, "precision").count("mm") >= 3
        assert precision["closure_gap_mm"] is not None and precision["closure_gap_mm"] < 1.0
        assert f"{precision['rms_error_mm']:.3f} mm" in text_of(page, "precision")
        # the graphs got at least 10 points a simulated second over the drawing, up to the session's time
        # (waited for: on a loaded machine the page's drawing may still be behind the frames it was sent)
        page.wait_for_function(f"window.operateStats.lastT >= {t1 - 0.5}", timeout=LONG)
        got = page.evaluate("window.operateStats")
        assert got["points"] >= 10 * (got["lastT"] - got["firstT"])
        assert got["firstT"] <= t0 and got["lastT"] >= t1 - 0.5
        assert got["redraws"] > 0
        shot = Path(os.environ.get("TTT_SM_SCREENSHOTS") or tmp_path) / SHOT
        page.screenshot(path=str(shot))
        assert shot.stat().st_size > 20_000

        # X axis, as CSV: the page's samples, those the session took, 0.04 s apart over the drawing
        with page.expect_download() as info:
            page.get_by_role("button", name="X axis CSV", exact=True).click()
        download = info.value
        assert download.suggested_filename == "x_axis.csv"
        rows = list(csv.reader(io.StringIO(Path(download.path()).read_text(encoding="utf-8"))))
        assert rows[0] == ["t_s", "x_desired_mm", "x_fk_mm"]
        # a sample the arm has no value for yet (before its drives are initialised) is an empty field
        table = [[float(v) if v else math.nan for v in r] for r in rows[1:]]
        times = [r[0] for r in table]
        assert all(math.isclose(b - a, SAMPLE_PERIOD_S, abs_tol=1e-6) for a, b in zip(times, times[1:], strict=False))
        during = [r for r in table if t0 <= r[0] <= t1]
        assert len(during) >= 10 * (t1 - t0)
        assert all(taken[r[0]][1:3] == r[1:] for r in during if r[0] in taken)
        assert sum(r[0] in taken for r in during) > 100
        # the pen followed the circle: desired x spans the O's 60 mm
        assert max(r[1] for r in during) - min(r[1] for r in during) >= 59.0
    finally:
        charts.close()
        page.close()


def draw_from_page(page: Any, session: Session, symbol: str, magnitude_cm: str, speed: str) -> list[np.ndarray]:
    """Choose ``symbol`` (the list's value), type the magnitude and speed, Trigger, wait until the arm waits
    again; the robot's ink strokes of that drawing (x, y rows, m), read on the twin's whiteboard."""
    run_until_waiting(page)  # on a session the O's test has not run
    page.get_by_label("Symbol", exact=True).select_option(symbol)
    page.get_by_role("spinbutton", name="Magnitude (cm)", exact=True).fill(magnitude_cm)
    page.get_by_role("spinbutton", name="Speed (0 to 5)", exact=True).fill(speed)
    drawings, strokes_before = session.call(lambda d: (len(session.operate.results), len(d.robot.board.strokes)))
    trigger(page).click()
    page.wait_for_function("document.querySelector('[data-role=reply]').textContent.startsWith('Trigger:')",
                           timeout=30_000)
    while session.call(lambda d: len(session.operate.results)) == drawings:
        page.wait_for_timeout(100)
    wait_status(page, MSG_READY)
    return [s.points[:, :2] for s in session.call(lambda d: d.robot.board.strokes[strokes_before:])
            if s.author == "robot"]


def shown_precision(page: Any, session: Session) -> dict[str, Any]:
    """The last drawing's precision as the session measured it; the page shows the same numbers."""
    precision: dict[str, Any] = session.call(lambda d: session.operate.results[-1])
    page.wait_for_function("(rms) => document.querySelector('[data-key=rms_error_mm]').textContent === rms",
                           arg=f"{precision['rms_error_mm']:.3f} mm", timeout=30_000)
    assert text_of(page, "precision").count(f"{precision['max_error_mm']:.3f} mm") == 1
    return precision


def test_a_sine_wave_of_4_cm_at_speed_4_is_4_cm_peak_to_peak_on_the_whiteboard(
        browser: Any, operate_cockpit: Cockpit) -> None:
    session = operate_cockpit.session
    page = browser.new_page(viewport={"width": 1500, "height": 1000})
    try:
        open_operate(page, operate_cockpit)
        page.get_by_label("Symbol", exact=True).select_option("sine")
        assert text_of(page, "magnitude-means") == "the sine wave's peak to peak"
        strokes = draw_from_page(page, session, "sine", "4", "4")
        assert text_of(page, "reply") == "Trigger: a sine wave, 4 cm peak to peak, speed 4 (25 mm/s)"
        assert len(strokes) == 1  # one stroke, the pen down from end to end
        ink = strokes[0]
        length = session.call(lambda d: float(d.robot.control.sine_length))
        # along X the wave's length; across, its peak to peak: the Magnitude
        assert abs(np.ptp(ink[:, 0]) - length) <= 0.0005, np.ptp(ink[:, 0])
        assert abs(np.ptp(ink[:, 1]) - 0.040) <= 0.0005, np.ptp(ink[:, 1])
        precision = shown_precision(page, session)
        assert precision["symbol"] == "sine" and precision["closure_gap_mm"] is None
        assert precision["rms_error_mm"] < 0.5
        assert page.locator('[data-key="what"]').text_content() == "a sine wave, 4 cm, speed 4 (25 mm/s)"
    finally:
        page.close()


def test_an_x_of_5_cm_at_speed_5_is_two_5_cm_diagonals_on_the_whiteboard(
        browser: Any, operate_cockpit: Cockpit) -> None:
    session = operate_cockpit.session
    page = browser.new_page(viewport={"width": 1500, "height": 1000})
    try:
        open_operate(page, operate_cockpit)
        strokes = draw_from_page(page, session, "X", "5", "5")
        assert text_of(page, "reply") == "Trigger: an X, 5 cm side, speed 5 (30 mm/s)"
        assert len(strokes) == 2  # two lines, the pen lifted between
        for line, slope in zip(strokes, (1.0, -1.0), strict=True):
            # each a straight line at 45 degrees spanning the X's side along X and along Y
            assert abs(np.ptp(line[:, 0]) - 0.050) <= 0.0005 and abs(np.ptp(line[:, 1]) - 0.050) <= 0.0005
            fit = np.polyfit(line[:, 0], line[:, 1], 1)
            assert abs(fit[0] - slope) < 0.02, fit
        both = np.vstack(strokes)
        assert abs(np.ptp(both[:, 0]) - 0.050) <= 0.0005 and abs(np.ptp(both[:, 1]) - 0.050) <= 0.0005
        # the two lines cross in their middles: the X's centre
        middles = [line.mean(axis=0) for line in strokes]
        assert np.hypot(*(middles[0] - middles[1])) < 0.001
        precision = shown_precision(page, session)
        assert precision["symbol"] == "X" and precision["rms_error_mm"] < 0.5
        assert page.locator('[data-key="what"]').text_content() == "an X, 5 cm, speed 5 (30 mm/s)"
    finally:
        page.close()


def test_stop_simulation_turns_the_manipulator_off_and_trigger_says_why(
        browser: Any, operate_cockpit: Cockpit) -> None:
    page = browser.new_page()
    try:
        open_operate(page, operate_cockpit)
        run_until_waiting(page)
        wait_status(page, MSG_READY)
        page.get_by_role("button", name="Stop_simulation", exact=True).click()
        wait_status(page, MSG_TURNING_OFF)
        page.wait_for_function("document.querySelector('[data-cmd=trigger]').disabled", timeout=LONG)
        assert text_of(page, "why") == "Trigger is off: the manipulator is being turned off"
        operate_cockpit.session.call(lambda d: d.robot.run_until(lambda: d.robot.control.at_start, 60.0))
        assert operate_cockpit.session.call(lambda d: bool(d.robot.control.at_start))
    finally:
        page.close()


def test_the_staircase_choice_plays_section_3_5_and_shows_its_three_comparisons(
        browser: Any, powered_on: Cockpit, tmp_path: Path) -> None:
    session = powered_on.session
    page = browser.new_page(viewport={"width": 1500, "height": 1000})
    try:
        open_operate(page, powered_on)
        run_until_waiting(page)
        assert page.get_by_label("Axis", exact=True).is_hidden()
        page.get_by_label("Symbol", exact=True).select_option("staircase")
        # its own choices instead of the magnitude and the speed
        assert page.get_by_label("Axis", exact=True).is_visible() and page.get_by_label("Steps").is_visible()
        assert page.get_by_role("slider", name="Magnitude", exact=True).is_hidden()
        page.get_by_label("Axis", exact=True).select_option("z")
        page.get_by_label("Steps").select_option("small")
        done = session.call(lambda d: len(session.operate.results))
        trigger(page).click()
        wait_status(page, MSG_STAIRCASE)
        assert text_of(page, "reply").startswith("Trigger: the staircase of section 3.5 along Z, 5 small stairs")
        assert trigger(page).is_disabled() and "follows the staircase" in text_of(page, "why")
        while session.call(lambda d: len(session.operate.results)) == done:
            page.wait_for_timeout(100)
        wait_status(page, MSG_READY)
        result = session.call(lambda d: session.operate.results[-1])
        assert result["symbol"] == "staircase" and result["thesis_figure"] == "3.15"
        table = page.get_by_role("table", name="the last staircase")
        page.wait_for_function("document.querySelector('[data-key=staircase-what]').textContent.startsWith('along Z')",
                               timeout=30_000)
        assert table.locator("[data-key=staircase-what]").text_content() == (
            "along Z, 5 small stairs of 0.5 mm, as fig. 3.15")
        for comparison in ("desired_vs_fk", "fk_vs_sensor", "desired_vs_sensor"):
            row = table.locator(f"[data-comparison={comparison}]")
            for key, col in (("max_static_mm", "static"), ("max_dynamic_mm", "dynamic")):
                assert row.locator(f"[data-key={col}]").text_content() == f"{result['summary'][comparison][key]:.3f} mm"
        assert result["summary"]["desired_vs_sensor"]["max_static_mm"] <= 0.1
        page.screenshot(path=str(Path(os.environ.get("TTT_SM_SCREENSHOTS") or tmp_path) / "gui_operate_staircase.png"))
    finally:
        page.close()


@pytest.mark.parametrize("path", ["/operate", "/charts"])
def test_stop_drive_1_is_a_toggle_on_the_operational_page_and_the_cockpit(
        browser: Any, powered_on: Cockpit, path: str) -> None:
    session = powered_on.session
    page = browser.new_page()
    try:
        open_page(page, powered_on, path)
        button = page.get_by_role("button", name="Stop drive 1", exact=True)
        assert button.get_attribute("aria-pressed") == "false"
        button.click()
        released = page.get_by_role("button", name="Release drive 1", exact=True)
        released.wait_for(timeout=30_000)
        assert released.get_attribute("aria-pressed") == "true"
        assert session.call(lambda d: bool(d.robot.chart("DriveInit1").stop)) is True
        released.click()
        page.get_by_role("button", name="Stop drive 1", exact=True).wait_for(timeout=30_000)
        assert session.call(lambda d: bool(d.robot.chart("DriveInit1").stop)) is False
        assert [a.describe().split(": ", 1)[1] for a in session.call(lambda d: d.actions)][-2:] == [
            "set DriveInit1.stop True", "set DriveInit1.stop False"]
    finally:
        page.close()


#: The least span of each graph's vertical axis (operate.js's GRAPHS' minSpan), in the graph's unit.
MIN_SPAN = {"z_axis": 1.0, "second_drive": 0.2, "third_drive": 0.2, "following_error": 0.5}


def test_idle_graphs_keep_a_least_span_the_x_y_view_holds_the_ink_and_the_simulation_speed_is_set_here(
        browser: Any) -> None:
    """At power-on the arm hardly moves: the graphs show the noise as the flat line it is, with ticks that
    differ; the X-Y view shows the ink on the whiteboard; the Simulation speed list sets the session's speed."""
    session = Session(Debugger.build(load_params(), seed=0), speed=None, running=False)
    with served(session) as cockpit:
        session.operate.plot_history()  # the graphs' samples are taken from here on
        session.call(lambda d: d.tick(500))  # 1 s after power-on: the drives start to initialise
        page = browser.new_page(viewport={"width": 1280, "height": 720})
        try:
            open_operate(page, cockpit)
            page.wait_for_function("document.querySelector('[data-graph=z_axis] canvas')?.dataset.yTicks",
                                   timeout=30_000)
            for graph, span in MIN_SPAN.items():
                canvas = page.locator(f'[data-graph="{graph}"] canvas')
                labels = str(canvas.get_attribute("data-y-ticks")).split(" / ")
                lo, hi = (float(v) for v in str(canvas.get_attribute("data-y-range")).split())
                assert hi - lo >= span, (graph, lo, hi)
                assert len(labels) >= 2 and len(set(labels)) == len(labels), (graph, labels)
            # The X-Y view: a cross drawn by hand in the middle cell is in the whiteboard's picture there.
            key = session.call(lambda d: (d.robot.board.draw_symbol("X", 3, 3), list(d.robot.board.ink_version))[1])
            page.reload()
            page.wait_for_function("(key) => document.querySelector('[data-role=xy-ink]')?.dataset.key === key",
                                   arg=":".join(str(k) for k in key), timeout=30_000)
            board, field = session.info["arm"]["board"], session.info["arm"]["field"]
            # the ink picture's pixel under the field's centre (x = 0, y = the field's middle), read in the page
            dark = page.evaluate("""async ([[bx0, bx1, by0, by1], [fx0, fx1, fy0, fy1]]) => {
                const img = new Image(); img.src = document.querySelector('[data-role=xy-ink]').getAttribute('href');
                await img.decode();
                const c = document.createElement('canvas'); c.width = img.width; c.height = img.height;
                const ctx = c.getContext('2d'); ctx.drawImage(img, 0, 0);
                const s = img.width / (bx1 - bx0), x = ((fx0 + fx1) / 2 - bx0) * s, y = (by1 - (fy0 + fy1) / 2) * s;
                return Array.from(ctx.getImageData(x - 2, y - 2, 5, 5).data).filter((v, i) => i % 4 === 0)
                  .some((v) => v < 128); }""", [board, field])
            assert dark
            # The simulation's speed, chosen here, is the session's (the session's `speed` command).
            speed = page.get_by_role("combobox", name="Simulation speed")
            assert speed.input_value() == "max"
            speed.select_option("0.5")
            page.wait_for_function("document.querySelector('[data-role=reply]').textContent === 'x0.5'",
                                   timeout=30_000)
            assert session.speed == 0.5
        finally:
            page.close()
