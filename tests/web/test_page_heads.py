"""The pages' common head is written once (web/page_heads.py): every page file under ``static/`` is its body,
and each page is served whole, its own stylesheets and script after the shared head."""

from __future__ import annotations

import re
from importlib import resources

from starlette.testclient import TestClient

from ttt_sm.web.page_heads import HEADS, page_html

STATIC = resources.files("ttt_sm.web") / "static"


def test_every_page_file_is_a_body_with_a_declared_head() -> None:
    files = sorted(p.name for p in STATIC.iterdir() if p.name.endswith(".html"))
    assert files == sorted(HEADS)
    for name in files:
        text = (STATIC / name).read_text(encoding="utf-8")
        assert text.startswith("<body ") and text.endswith("</body>\n</html>\n"), name
        assert "<head>" not in text and "<title>" not in text, name


def test_a_page_is_served_with_one_head_holding_the_shared_tags_then_its_own() -> None:
    html = page_html("kinematics_motion.html")
    head = html[:html.index("</head>")]
    assert html.startswith("<!doctype html>\n<html lang=\"en\">\n<head>\n") and html.count("<head>") == 1
    assert "<title>ttt_sm — kinematics: trajectories and forces</title>" in head
    links = re.findall(r'<link rel="stylesheet" href="([^"]+)">', head)
    assert links == ["/static/cockpit.css", "/static/kinematics.css", "/static/kinematics_motion.css"]
    assert re.findall(r'<script type="module" src="([^"]+)"></script>', head) == ["/static/kinematics_motion.js"]
    assert '<meta charset="utf-8">' in head and '<link rel="icon" href="data:,">' in head
    assert "<script" not in page_html("index.html")  # the index has no script


def test_the_server_serves_each_page_as_page_html_writes_it(client: TestClient) -> None:
    for path, name in (("/", "index.html"), ("/charts", "charts.html"), ("/game", "game.html"),
                       ("/operate", "operate.html"), ("/kinematics", "kinematics.html"),
                       ("/kinematics/motion", "kinematics_motion.html")):
        r = client.get(path)
        assert r.status_code == 200 and r.text == page_html(name), path
        assert r.headers["cache-control"] == "no-store" and r.headers["x-content-type-options"] == "nosniff"
