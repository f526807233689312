"""The /kinematics page: its JSON views (web/kinematics.py) and the page in Chromium.

The Lab exercises of docs/kinematics.md are checked here on what the page is given
(the route's JSON) and, once each, on what it shows in Chromium.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest
from starlette.testclient import TestClient

from ttt_sm.debug.debugger import Debugger
from ttt_sm.params import load_params
from ttt_sm.twin.kinematics import fk
from ttt_sm.web.access import allowed_hosts
from ttt_sm.web.server import create_app
from ttt_sm.web.session import Session

from .conftest import Cockpit, served, text_of

#: The whiteboard's far corner (x max, y max of board_bounds), m.
FAR_CORNER = (0.15, 0.37)


@pytest.fixture(scope="module")
def kin_session() -> Iterator[Session]:
    s = Session(Debugger.build(load_params(), seed=0), speed=None, running=False)
    yield s


@pytest.fixture(scope="module")
def api(kin_session: Session) -> Iterator[TestClient]:
    with TestClient(create_app(kin_session, manage_session=False)) as c:
        yield c


def get(api: TestClient, view: str, **query: Any) -> dict[str, Any]:
    r = api.get(f"/api/kinematics/{view}", params={k: str(v) for k, v in query.items()})
    assert r.status_code == 200, r.text
    return r.json()


def test_workspace_json(api: TestClient) -> None:
    d = get(api, "workspace", resolution=16)
    assert len(d["top"]["code"]) == 16 and len(d["top"]["code"][0]) == 16
    assert len(d["side"]["code"]) == 16 and d["fits"] is True
    assert d["cells"] == [["elbow up"] * 5] * 5
    assert d["q_max_deg"][2] == pytest.approx(30.0)


def test_the_workspace_draws_the_cameras_field_and_it_holds_the_playing_field(api: TestClient, params: Any) -> None:
    """The game's camera (beyond the far edge, looking down at a slant) sees a trapezoid of the board plane:
    its image corners mapped back through the camera's homography, the playing field inside it."""
    from matplotlib.path import Path as Polygon

    from ttt_sm.vision.simulated import CameraPose

    d = get(api, "workspace", resolution=8)
    footprint = np.asarray(d["camera_field_m"])
    assert footprint.shape == (4, 2)
    pose = CameraPose.beyond_far_edge(params)
    corners = pose.project(np.column_stack([footprint, np.full(4, params.board.surface_z)]))
    w, h = pose.width_px - 1, pose.height_px - 1
    assert np.allclose(corners, [[0, 0], [w, 0], [w, h], [0, h]], atol=0.05)  # back on the image's corners
    fx0, fx1, fy0, fy1 = d["field_m"]
    assert Polygon(footprint).contains_points([[fx0, fy0], [fx1, fy0], [fx1, fy1], [fx0, fy1]]).all()
    # nearer the camera (+y) the footprint is narrower: it looks at a slant
    far, near = footprint[:2], footprint[2:]
    assert np.ptp(near[:, 0]) < np.ptp(far[:, 0]) and near[:, 1].min() > far[:, 1].max()


def test_exercise_a_on_the_route(api: TestClient) -> None:
    d = get(api, "workspace", q2_max_deg=86, q3_max_deg=100, resolution=8)
    down = [(i, j) for i, row in enumerate(d["cells"]) for j, c in enumerate(row) if c == "elbow down"]
    assert down == [(i, j) for i in range(3) for j in range(5)] + [(3, 0), (3, 1), (3, 2)]


def test_exercise_b_on_the_route(api: TestClient) -> None:
    assert not get(api, "workspace", L2=0.215, cells=6, cell_m=0.03, resolution=8)["fits"]
    assert get(api, "workspace", L2=0.22, cells=6, cell_m=0.03, resolution=8)["fits"]


def test_exercise_c_the_far_corner_on_the_route(api: TestClient) -> None:
    """Every method fails (out of reach); the analytic ones know at once, adaptive DLS gives up early,
    the thesis' fixed-lambda LM and the twist step run to the iteration limit."""
    d = get(api, "race", x=FAR_CORNER[0], y=FAR_CORNER[1])
    by = {m["method"]: m for m in d["methods"]}
    assert all(m["reason"] == "out of reach" and not m["converged"] for m in d["methods"])
    assert by["analytic_up"]["iterations"] == by["analytic_down"]["iterations"] == 1
    assert by["lm_fixed"]["iterations"] == by["twist"]["iterations"] == d["max_iterations"] == 100
    assert by["dls_adaptive"]["iterations"] < 60


def test_the_race_converges_within_1e_5_m_inside_the_field(api: TestClient) -> None:
    d = get(api, "race", x=0.075, y=0.325)
    for m in d["methods"]:
        assert m["converged"], m["method"]
        assert m["errors_m"][-1] <= 1e-5
        tip = fk(np.array(m["q_rad"]), load_params().geometry)[:3]
        assert np.linalg.norm(tip - [0.075, 0.325, 0.0]) <= 1e-5


def test_the_dh_route_gives_the_table_and_frames_ending_at_the_pen_tip(api: TestClient) -> None:
    d = get(api, "dh", q_deg="10,90,-80,0")
    assert len(d["rows"]) == 4 and len(d["frames"]) == 5
    assert np.allclose(d["frames"][-1]["origin_m"], d["fk"][:3], atol=1e-12)
    assert np.allclose(d["arm_m"][-1], d["fk"][:3], atol=1e-12)


@pytest.mark.parametrize("view, query, named", [("workspace", {"tool": "brush"}, "tool"),
                                                ("workspace", {"L2": "abc"}, "L2"),
                                                ("workspace", {"q3_max_deg": "-170"}, "q3"),
                                                ("race", {"x": "0.1"}, "x and y"),
                                                ("dh", {"q_deg": "1,2"}, "q_deg")])
def test_a_bad_query_is_a_400_naming_the_key(api: TestClient, view: str, query: dict[str, str],
                                             named: str) -> None:
    r = api.get(f"/api/kinematics/{view}", params=query)
    assert r.status_code == 400 and named in r.json()["error"] and "\n" not in r.json()["error"]
    assert api.get("/api/kinematics/nothing").status_code == 404


def test_the_page_and_its_routes_want_the_token(kin_session: Session) -> None:
    app = create_app(kin_session, token="s3cret", hosts=allowed_hosts("127.0.0.1", 8765), manage_session=False)
    with TestClient(app, base_url="http://127.0.0.1:8765") as c:
        for path in ("/kinematics", "/api/kinematics/workspace", "/api/kinematics/race?x=0&y=0.25"):
            assert c.get(path).status_code == 403, path
        assert c.get("/static/kinematics.js").status_code == 200
        assert c.get("/kinematics?token=s3cret").status_code == 200
        assert c.get("/api/kinematics/dh").status_code == 200  # the cookie now


@pytest.fixture(scope="module")
def kin_cockpit(kin_session: Session) -> Iterator[Cockpit]:
    with served(kin_session) as cockpit:
        yield cockpit


def _set(page: Any, role: str, value: str) -> None:
    n = page.evaluate("window.kinematics.redraws.length")
    page.eval_on_selector(f"[data-role={role}]",
                          "(el, v) => { el.value = v; el.dispatchEvent(new Event('input')); }", value)
    page.wait_for_function(f"window.kinematics.redraws.length > {n} && window.kinematics.idle()", timeout=60_000)


def test_the_page_in_chromium_answers_the_three_exercises(page: Any, kin_cockpit: Cockpit) -> None:
    page.set_viewport_size({"width": 1280, "height": 720})
    page.goto(kin_cockpit.page_url("/kinematics"))
    page.wait_for_function("document.body.dataset.ready === 'true'", timeout=60_000)
    assert text_of(page, "fits") == "5 x 5 fits" and text_of(page, "elbow-down") == "none"
    # the DH table shown is the route's, the frames drawn
    assert page.locator("[data-role=dh-table] tbody tr").count() == 4
    assert page.locator("[data-role=dh-table] tbody tr").nth(1).locator("td").nth(3).text_content() == "0.2200"
    # the link to the trajectories and forces page works
    motion = page.locator("a[href='/kinematics/motion']")
    assert motion.count() == 1
    assert page.request.get(kin_cockpit.page_url("/kinematics/motion")).status == 200
    # (a)
    _set(page, "q3max", "100")
    assert text_of(page, "elbow-down") == "none"
    _set(page, "q2max", "86")
    assert text_of(page, "elbow-down") == ("(0,0) (0,1) (0,2) (0,3) (0,4) (1,0) (1,1) (1,2) (1,3) (1,4)"
                                           " (2,0) (2,1) (2,2) (2,3) (2,4) (3,0) (3,1) (3,2)")
    # (b)
    page.click("[data-role=ws-reset]")
    page.select_option("[data-role=cells]", "6")
    page.wait_for_function("window.kinematics.idle()", timeout=60_000)
    _set(page, "L2", "0.215")
    assert text_of(page, "fits") == "6 x 6 does not fit" and text_of(page, "unreachable") == "(5,5)"
    _set(page, "L2", "0.22")
    assert text_of(page, "fits") == "6 x 6 fits"
    # (c)
    page.click("[data-role=race-corner]")
    page.wait_for_function("window.kinematics.race.target[0] > 0.1", timeout=60_000)
    rows = page.locator("[data-role=race-table] tbody tr")
    assert rows.count() == 5
    got = {rows.nth(i).get_attribute("data-method"): (rows.nth(i).locator("td").nth(1).text_content(),
                                                     rows.nth(i).locator("td").nth(2).text_content())
           for i in range(5)}
    assert got == {"lm_fixed": ("out of reach", "100"), "dls_adaptive": ("out of reach", got["dls_adaptive"][1]),
                   "analytic_up": ("out of reach", "1"), "analytic_down": ("out of reach", "1"),
                   "twist": ("out of reach", "100")}
    assert int(got["dls_adaptive"][1]) < 60
    assert page.evaluate("window.kinematics.errors") == 0
