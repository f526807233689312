"""The arm drawn live in the Tic-tac-toe page: where a person sees the tool tip is forward kinematics of the truth.

The frames carry the points along the arm computed on the server from the
twin's TRUE joint angles (ttt_sm.web.arm_view); the page draws them in two
projections.  These tests pause the robot at a chart tick and read, in
Chromium, where the tip marker is on screen, map it back through the SVG's
own screen transform to millimetres, and compare with ``fk`` of the true
angles read in the simulation thread: the page's drawing, not its data.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from starlette.testclient import TestClient

from ttt_sm.debug.debugger import Debugger
from ttt_sm.params import load_params
from ttt_sm.twin.kinematics import arm_points, fk
from ttt_sm.web.arm_view import POINT_NAMES
from ttt_sm.web.server import create_app
from ttt_sm.web.session import Session

from .conftest import Cockpit, served
from .test_protocol import Page

#: Where the page draws the tip may differ from forward kinematics by this much, mm:
#: the frame's points are rounded to 0.1 mm, the rest is the screen's sub-pixel geometry.
TIP_TOL_MM = 0.5


@pytest.fixture(scope="module")
def arm_cockpit() -> Iterator[Cockpit]:
    """A game (person at the page), paused at power-on, as fast as it goes when run."""
    dbg = Debugger.build(load_params(), seed=0, game=True, person="page")
    session = Session(dbg, speed=None, running=False)
    with served(session) as cockpit:
        yield cockpit


def truth_now(d: Debugger) -> dict[str, Any]:
    assert d.robot.sim is not None
    q = d.robot.sim.truth.q
    g = d.robot.params.true_geometry  # the view draws the true arm, as built
    return {"q": q, "tip_mm": fk(q, g)[:3] * 1e3, "points_mm": arm_points(q, g) * 1e3, "tick": d.robot.chart_ticks,
            "pen": d.robot.board.contact.pen_touching, "ink_mm2": d.robot.board.ink_area_mm2(),
            "ink": list(d.robot.board.ink_version)}


def tip_on_screen(page: Any, view: str) -> list[float]:
    """The tip marker's centre on screen, mapped back to the view's SVG user units (mm)."""
    return list(page.evaluate(
        """(view) => {
            const svg = document.querySelector(`svg[data-role="arm-${view}"]`);
            const r = svg.querySelector('[data-role="tip"]').getBoundingClientRect();
            const p = new DOMPoint(r.x + r.width / 2, r.y + r.height / 2).matrixTransform(svg.getScreenCTM().inverse());
            return [p.x, p.y];
        }""", view))


def wait_drawn_at(page: Any, tick: int) -> None:
    """Until the page has drawn the frame of chart tick ``tick`` (the session is paused there)."""
    page.wait_for_function("(tick) => window.lastTick === tick", arg=tick, timeout=60_000)


def test_the_frames_arm_part_is_forward_kinematics_of_the_true_angles() -> None:
    session = Session(Debugger.build(load_params(), seed=0), speed=None, running=False)
    session.start()
    try:
        with TestClient(create_app(session, manage_session=False)) as c, c.websocket_connect("/ws") as ws:
            page = Page(ws)
            info, full = page.join()
            assert info["arm"]["board"] == [-150.0, 150.0, 130.0, 370.0]  # the whiteboard, mm
            page.answer(page.send(type="tick", n=300))  # the drives move: initialising
            frame = page.frame()
            while "arm" not in frame:
                frame = page.frame()
            truth = session.call(truth_now)
            arm = frame["arm"]
            for name, p in zip(POINT_NAMES, truth["points_mm"], strict=True):
                assert arm["points"][name] == pytest.approx(p, abs=0.051), name
            assert arm["q_deg"] == pytest.approx(np.degrees(truth["q"]), abs=0.006)
            assert arm["tool"] == "pen" and arm["touching"] is None
            assert c.get("/api/arm/ink.png").headers["content-type"] == "image/png"
    finally:
        session.stop()


def test_the_drawn_tool_tip_is_where_forward_kinematics_puts_it(browser: Any, arm_cockpit: Cockpit) -> None:
    session = arm_cockpit.session
    page = browser.new_page(viewport={"width": 1400, "height": 1400})
    try:
        page.add_init_script("window.lastTick = -1; const _ws = window.WebSocket;"
                             " window.WebSocket = class extends _ws { constructor(...a) { super(...a);"
                             " this.addEventListener('message', (e) => { const m = JSON.parse(e.data);"
                             " if (m.type === 'frame') setTimeout(() => { window.lastTick = m.tick; }, 0); }); } };")
        page.goto(arm_cockpit.page_url("/game"))
        page.wait_for_selector('svg[data-role="arm-top"] [data-role="tip"]', timeout=30_000)

        # Paused at a tick in the middle of the field's first line: the pen on the board, inking.
        def into_a_stroke(d: Debugger) -> dict[str, Any]:
            d.add_breakpoint("enter Control.field_pen_down")
            d.run(300.0)
            d.delete(None)
            while not d.robot.board.contact.pen_touching:
                d.tick(1)
            d.tick(150)
            return truth_now(d)

        first = session.call(into_a_stroke, timeout_s=600)
        assert first["pen"] and first["ink_mm2"] > 0.0
        wait_drawn_at(page, first["tick"])
        x, minus_y = tip_on_screen(page, "top")
        y, minus_z = tip_on_screen(page, "side")
        tip = first["tip_mm"]
        assert [x, -minus_y] == pytest.approx(tip[:2], abs=TIP_TOL_MM)
        assert [y, -minus_z] == pytest.approx(tip[1:], abs=TIP_TOL_MM)
        assert page.locator('[data-role="arm"]').get_attribute("data-touching") == "pen"
        assert page.locator('svg[data-role="arm-top"] [data-role="tip"]').get_attribute("data-touching") == "true"
        # The ink under the top view is the board's, fetched for this very key: some dark pixels.
        key = ":".join(str(k) for k in first["ink"])
        page.wait_for_function("(key) => document.querySelector('[data-role=arm-ink]').dataset.key === key",
                               arg=key, timeout=30_000)
        dark = page.evaluate("""async () => {
            const img = new Image(); img.src = document.querySelector('[data-role=arm-ink]').getAttribute('href');
            await img.decode();
            const c = document.createElement('canvas'); c.width = img.width; c.height = img.height;
            const g = c.getContext('2d'); g.drawImage(img, 0, 0);
            const d = g.getImageData(0, 0, c.width, c.height).data; let n = 0;
            for (let i = 0; i < d.length; i += 4) if (d[i] + d[i + 1] + d[i + 2] < 400) n++;
            return n; }""")
        assert dark > 10

        # Three seconds later (the pen lifted or still drawing): the page follows the arm.
        second = session.call(lambda d: (d.tick(300), truth_now(d))[1])
        assert np.linalg.norm(second["tip_mm"] - tip) > 3.0  # it did move
        wait_drawn_at(page, second["tick"])
        x, minus_y = tip_on_screen(page, "top")
        y, minus_z = tip_on_screen(page, "side")
        assert [x, -minus_y] == pytest.approx(second["tip_mm"][:2], abs=TIP_TOL_MM)
        assert [y, -minus_z] == pytest.approx(second["tip_mm"][1:], abs=TIP_TOL_MM)
    finally:
        page.close()
