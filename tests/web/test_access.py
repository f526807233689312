"""Access like Jupyter's (docs/gui.md, "Threat model"): a token on every start, loopback included; no token
and no Origin is refused; another machine reaches ``--host 0.0.0.0`` with the token; ``--port 80`` works."""

from __future__ import annotations

import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest
from starlette.testclient import TestClient

from gui_process import running_gui
from ttt_sm.web.access import allowed_hosts, is_loopback, port_of, reachable_host
from ttt_sm.web.server import create_app
from ttt_sm.web.session import Session

from .test_protocol import Page, refused


def test_without_the_token_nothing_of_the_session_is_served_but_the_scripts_are(session: Session) -> None:
    app = create_app(session, token="s3cret", hosts=allowed_hosts("127.0.0.1", 8765), manage_session=False)
    with TestClient(app, base_url="http://127.0.0.1:8765") as c:
        for path in ("/", "/charts", "/game", "/operate", "/api/diagram/Control", "/api/trace.jsonl",
                     "/api/arm/ink.png"):
            assert c.get(path).status_code == 403, path
        host = {"host": "127.0.0.1:8765"}
        assert refused(c, "/ws", host) == 1008  # no Origin, no token: not a page of this server, not its owner
        assert refused(c, "/ws", {**host, "origin": "http://127.0.0.1:8765"}) == 1008  # its Origin is not enough
        assert c.get("/static/session.js").status_code == 200  # the same for everyone, nothing of the session
        ok = c.get("/charts?token=s3cret")
        assert ok.status_code == 200 and ok.headers["set-cookie"].startswith("ttt_sm_token_")
        assert ok.headers["set-cookie"].startswith("ttt_sm_token_8765=s3cret;")  # one cookie per port
        assert c.get("/charts").status_code == 200  # the cookie now
        with c.websocket_connect("/ws", headers={**host, "cookie": "ttt_sm_token_8765=s3cret"}) as ws:  # a page's
            assert Page(ws).join()[1]["full"]
        assert refused(c, "/ws", {**host, "cookie": "ttt_sm_token_8766=s3cret"}) == 1008  # another port's cookie
    with TestClient(app, base_url="http://127.0.0.1:8765") as c:
        assert c.get("/charts?token=s3cr\u00e9t").status_code == 403  # not ASCII: refused, not a 500


def test_the_port_of_a_host_header() -> None:
    assert [port_of(h) for h in ("127.0.0.1:8765", "[::1]:8000", "[::1]", "localhost", "fe80::1", "")] == \
        [8765, 8000, 80, 80, 80, 80]


def test_port_80_answers_a_host_header_without_its_port(session: Session) -> None:
    app = create_app(session, token="t", hosts=allowed_hosts("127.0.0.1", 80), manage_session=False)
    with TestClient(app, base_url="http://127.0.0.1") as c:  # a browser sends Host: 127.0.0.1
        assert c.get("/charts?token=t").status_code == 200
        assert c.get("/charts?token=t", headers={"host": "localhost"}).status_code == 200
        assert c.get("/charts?token=t", headers={"host": "evil.example"}).status_code == 403


def test_every_interface_answers_to_the_machines_addresses_and_names_and_prints_a_reachable_one() -> None:
    shown = reachable_host("0.0.0.0")
    assert shown not in ("0.0.0.0", "")
    hosts = allowed_hosts("0.0.0.0", 8765)
    assert f"{shown}:8765" in hosts and "127.0.0.1:8765" in hosts and "localhost:8765" in hosts
    assert not any(h.startswith(("evil", "0.0.0.0")) for h in hosts)
    assert allowed_hosts("192.0.2.77", 8000)[0].endswith(":8000")
    assert "192.0.2.77:8000" in allowed_hosts("192.0.2.77", 8000)


def _get(url: str) -> int:
    """The status of a GET, 0 when nothing answers."""
    try:
        return int(urllib.request.urlopen(url, timeout=30).status)
    except urllib.error.HTTPError as exc:
        return exc.code
    except OSError:
        return 0


def test_gui_on_every_interface_prints_a_reachable_address_that_serves_with_the_token(tmp_path: Path) -> None:
    with running_gui("--host", "0.0.0.0", "--paused", "--trace", str(tmp_path / "trace.jsonl"), cwd=tmp_path,
                     lines=10) as gui:
        assert gui.host is not None, "no address printed"
        host, token = gui.host, gui.token
        assert host != "0.0.0.0"
        if is_loopback(host):
            pytest.skip("this machine has no address but loopback: another machine could not reach it anyway")
        base = gui.base  # as another machine on the network asks: Host names that address
        deadline = time.monotonic() + 120
        while _get(f"{base}/static/session.js") != 200:
            assert time.monotonic() < deadline and gui.proc.poll() is None, "the cockpit did not start"
            time.sleep(0.1)
        assert _get(f"{base}/charts?token={token}") == 200
        assert _get(f"{base}/charts") == 403
        assert _get(f"{base}/charts?token=wrong") == 403
        status, err = gui.stop()
    assert status == 0, err
