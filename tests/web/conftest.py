"""A live cockpit for the browser tests: a Session served by uvicorn on a free loopback port.

``cockpit`` is module-scoped: building the robot costs a second or more, and each
test module's tests share one session (they say what state they need: a
replay to power-on, a paused run, ...).
"""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
import uvicorn
from starlette.testclient import TestClient

from ttt_sm.debug.debugger import Debugger
from ttt_sm.params import load_params
from ttt_sm.web.coverage import scenario_dir_files
from ttt_sm.web.lab_watch import LabWatch
from ttt_sm.web.server import create_app
from ttt_sm.web.session import Session

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"


@dataclass
class Cockpit:
    url: str
    session: Session
    server: uvicorn.Server

    def page_url(self, path: str = "/charts") -> str:
        return self.url + path


def open_page(page: Any, cockpit: Cockpit, path: str = "/charts", timeout_ms: int = 30_000) -> None:
    """Open one of the cockpit's pages and wait until its socket is connected (the mode no longer 'connecting')."""
    page.goto(cockpit.page_url(path))
    page.wait_for_function("document.querySelector('[data-role=mode]').textContent !== 'connecting'",
                           timeout=timeout_ms)


def text_of(page: Any, role: str) -> str:
    """The text of the page's element ``data-role=role``, trimmed."""
    return str(page.locator(f'[data-role="{role}"]').text_content()).strip()


@contextmanager
def served(session: Session, lab: LabWatch | None = None) -> Iterator[Cockpit]:
    """``session`` served on a free loopback port while the block runs (the session with the app); stopped after.

    ``lab``: a student's chart watched and reloaded into it (``ttt-sm gui --lab``).
    """
    server, thread, url = serve(session, lab=lab)
    try:
        yield Cockpit(url, session, server)
    finally:
        server.should_exit = True
        thread.join(30)


def serve(session: Session, token: str | None = None,
          lab: LabWatch | None = None) -> tuple[uvicorn.Server, threading.Thread, str]:
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.bind(("127.0.0.1", 0))
    port = sock.getsockname()[1]
    hosts = [f"127.0.0.1:{port}", f"localhost:{port}"]
    app = create_app(session, token=token, hosts=hosts, lab=lab)
    server = uvicorn.Server(uvicorn.Config(app, log_level="warning", lifespan="on"))
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, daemon=True)
    thread.start()
    deadline = time.monotonic() + 30
    while not server.started:
        if time.monotonic() > deadline or not thread.is_alive():
            raise RuntimeError("the cockpit's server did not start")
        time.sleep(0.02)
    return server, thread, f"http://127.0.0.1:{port}"


# A paused session and a test client of its app, shared by the protocol tests of a module.
@pytest.fixture(scope="module")
def session() -> Iterator[Session]:
    s = Session(Debugger.build(load_params(), seed=0), speed=None, running=False)
    s.start()
    try:
        yield s
    finally:
        s.stop()


@pytest.fixture(scope="module")
def client(session: Session) -> Iterator[TestClient]:
    with TestClient(create_app(session, manage_session=False)) as c:
        yield c


@pytest.fixture(scope="module")
def cockpit(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Cockpit]:
    """A paused session at power-on, as fast as it goes when run, served on 127.0.0.1."""
    dbg = Debugger.build(load_params(), seed=0)
    trace = tmp_path_factory.mktemp("cockpit") / "trace.jsonl"
    session = Session(dbg, speed=None, running=False, scenarios=scenario_dir_files(SCENARIOS), trace_path=trace)
    with served(session) as cockpit:
        yield cockpit
