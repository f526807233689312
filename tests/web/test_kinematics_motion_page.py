"""The /kinematics/motion page: its JSON views (web/kinematics_motion.py) and the page in Chromium.

docs/kinematics.md, "Lab: trajectories and forces".
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
from starlette.testclient import TestClient

from ttt_sm.debug.debugger import Debugger
from ttt_sm.params import load_params
from ttt_sm.web.access import allowed_hosts
from ttt_sm.web.server import create_app
from ttt_sm.web.session import Session

from .conftest import Cockpit, served, text_of


@pytest.fixture(scope="module")
def kin_session() -> Iterator[Session]:
    yield Session(Debugger.build(load_params(), seed=0), speed=None, running=False)


@pytest.fixture(scope="module")
def api(kin_session: Session) -> Iterator[TestClient]:
    with TestClient(create_app(kin_session, manage_session=False)) as c:
        yield c


def get(api: TestClient, view: str, **query: Any) -> dict[str, Any]:
    r = api.get(f"/api/kinematics/motion/{view}", params={k: str(v) for k, v in query.items()})
    assert r.status_code == 200, r.text
    return r.json()


def test_trajectory_json_has_each_method_s_numbers_and_series(api: TestClient) -> None:
    d = get(api, "trajectory", x0=-0.02, y0=0.25, x1=0.02, y1=0.25, hold_s=0.5, methods="cubic,step_fr_sw")
    assert [m["method"] for m in d["methods"]] == ["cubic", "step_fr_sw"]
    cubic, step = d["methods"]
    assert cubic["fr_sw"] is False and step["fr_sw"] is True
    n = len(cubic["t_s"])
    assert n > 100 and all(len(cubic[k]) == n for k in ("tip_m", "target_m", "following_rad", "current_a"))
    # the cubic's targets lie on the line, z pressed 1 mm into the board
    assert all(abs(p[1] - 0.25) < 1e-9 and p[2] == pytest.approx(-d["press_m"]) for p in cubic["target_m"])
    assert cubic["ink_max_off_line_m"] < step["ink_max_off_line_m"]


def test_forces_json_has_the_jacobian_ellipses_and_the_force_line(api: TestClient) -> None:
    d = get(api, "forces", x=0.05, y=0.3, grid=3)
    p = d["pose"]
    assert (p["x_m"], p["y_m"]) == (0.05, 0.3) and len(p["jacobian"]) == 4
    assert p["arm_m"][-1] == pytest.approx([0.05, 0.3, 0.0], abs=1e-5)
    assert len(d["ellipses"]) == 9
    line = d["line"]
    assert len(line["true_n"]) == len(line["estimate_n"]) == len(line["t_s"]) == len(line["observable"])
    assert max(line["true_n"]) == pytest.approx(2.0, abs=0.1)
    assert line["errors"]["mean_rel"] < 0.10


@pytest.mark.parametrize("view, query, named", [("trajectory", {"x0": "abc"}, "x0"),
                                                ("trajectory", {"x1": "0.9"}, "x1, y1"),
                                                ("trajectory", {"methods": "spline"}, "methods"),
                                                ("trajectory", {"x1": "-0.025", "y1": "0.226"}, "5 mm"),
                                                ("forces", {"speed": "1"}, "speed"),
                                                ("forces", {"x": "0", "y": "0.9"}, "x, y")])
def test_a_bad_query_is_a_400_naming_the_key(api: TestClient, view: str, query: dict[str, str], named: str) -> None:
    r = api.get(f"/api/kinematics/motion/{view}", params=query)
    assert r.status_code == 400 and named in r.json()["error"] and "\n" not in r.json()["error"]
    assert api.get("/api/kinematics/motion/nothing").status_code == 404


def test_the_page_and_its_routes_want_the_token(kin_session: Session) -> None:
    app = create_app(kin_session, token="s3cret", hosts=allowed_hosts("127.0.0.1", 8765), manage_session=False)
    with TestClient(app, base_url="http://127.0.0.1:8765") as c:
        for path in ("/kinematics/motion", "/api/kinematics/motion/forces"):
            assert c.get(path).status_code == 403, path
        assert c.get("/static/kinematics_motion.js").status_code == 200
        assert c.get("/kinematics/motion?token=s3cret").status_code == 200


@pytest.fixture(scope="module")
def motion_cockpit(kin_session: Session) -> Iterator[Cockpit]:
    with served(kin_session) as cockpit:
        yield cockpit


def _open(page: Any, cockpit: Cockpit) -> None:
    page.set_viewport_size({"width": 1280, "height": 720})
    page.goto(cockpit.page_url("/kinematics/motion"))
    page.wait_for_function("document.body.dataset.ready === 'true' || window.kinematicsMotion?.errors > 0",
                           timeout=120_000)
    assert page.evaluate("window.kinematicsMotion.errors") == 0, text_of(page, "status")


def _inked(page: Any, canvas: str) -> int:
    """How many pixels of the canvas were drawn."""
    return int(page.evaluate(f"""(() => {{ const c = document.querySelector('[data-role={canvas}]');
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let n = 0; for (let i = 3; i < d.length; i += 4) if (d[i]) n++; return n; }})()"""))


def test_the_trajectory_view_in_chromium(page: Any, motion_cockpit: Cockpit) -> None:
    _open(page, motion_cockpit)
    # a row per method, the numbers the route gave
    rows = page.locator("[data-role=traj-table] tbody tr")
    assert [rows.nth(i).get_attribute("data-method") for i in range(rows.count())] == [
        "increment", "step_fr_sw", "cubic", "quintic"]
    traj = page.evaluate("window.kinematicsMotion.trajectory")
    step = traj["methods"][1]
    assert rows.nth(1).locator("td").nth(6).text_content() == f"{step['ink_max_off_line_m'] * 1e3:.2f}"
    assert float(rows.nth(0).locator("td").nth(6).text_content()) < 0.5  # the increments' ink on the line
    assert page.input_value("[data-role=x0]") == "-0.025" and page.input_value("[data-role=y1]") == "0.275"
    for canvas in ("traj-ink", "traj-lag", "traj-current"):  # every plot drawn
        assert _inked(page, canvas) > 5000, canvas
    # another line: the table and the route's document follow the inputs
    page.fill("[data-role=x0]", "-0.04")
    page.fill("[data-role=y0]", "0.25")
    page.fill("[data-role=x1]", "0.04")
    page.fill("[data-role=y1]", "0.25")
    page.click("[data-role=traj-go]")
    page.wait_for_function("window.kinematicsMotion.trajectory.a_m[0] < -0.03 && window.kinematicsMotion.idle()",
                           timeout=120_000)
    assert page.evaluate("window.kinematicsMotion.trajectory.methods[0].move_s") == pytest.approx(0.08 / 0.02)
    assert page.evaluate("window.kinematicsMotion.errors") == 0


def test_the_forces_view_in_chromium_and_the_link_back(page: Any, motion_cockpit: Cockpit) -> None:
    _open(page, motion_cockpit)
    for canvas in ("ellipses", "force"):
        assert _inked(page, canvas) > 5000, canvas
    # the Jacobian at the field's centre, the estimate's error in the text
    assert page.locator("[data-role=jacobian] tbody tr").count() == 4
    assert text_of(page, "pose") == "x 0.000 m, y 0.250 m"
    assert text_of(page, "force-error").startswith("mean ")
    assert float(page.get_attribute("[data-role=force-error]", "data-mean")) < 0.10
    # a click on the board moves the pen: the Jacobian is recomputed there
    board = page.locator("[data-role=ellipses]")
    box = board.bounding_box()
    board.click(position={"x": box["width"] * 0.7, "y": box["height"] * 0.5})  # scrolled into view first
    page.wait_for_function("(window.kinematicsMotion.forces.pose.x_m > 0.02 && window.kinematicsMotion.idle())"
                           " || window.kinematicsMotion.errors > 0", timeout=120_000)
    assert page.evaluate("window.kinematicsMotion.errors") == 0, text_of(page, "status")
    forces = page.evaluate("window.kinematicsMotion.forces")
    assert text_of(page, "pose") == f"x {forces['pose']['x_m']:.3f} m, y {forces['pose']['y_m']:.3f} m"
    jac = page.locator("[data-role=jacobian] tbody tr").nth(0).locator("td").nth(0).text_content()
    assert jac == f"{forces['pose']['jacobian'][0][0]:.4f}"
    # and back to /kinematics, which links here
    page.click("[data-role=back]")
    page.wait_for_url("**/kinematics")
    assert page.locator("a[href='/kinematics/motion']").count() == 1
