"""Live while writing, without a browser: ``gui --lab``'s watcher over the ASGI app (Starlette's TestClient).

The student's folder starts with the tutorial's solution: it runs in its slot
and its checks pass.  A save with a syntax error reaches every page as one
line with file:line, and the chart that loaded last keeps running; a save
that fixes it rebuilds the robot with it (a renamed state in the diagram) and
runs the checks again.  Every wait is on a condition, with a generous timeout.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from starlette.testclient import TestClient

from ttt_sm.debug.debugger import Debugger
from ttt_sm.params import load_params
from ttt_sm.web.lab_watch import LabTask, LabWatch
from ttt_sm.web.server import create_app
from ttt_sm.web.session import Session

from .lab_files import RENAMED, broken, broken_line, fixed, lab_folder, save

#: Long: the checks run a twin and three scenarios in a process at low priority, on a busy machine.
CHECKS_TIMEOUT_S = 600.0
RELOAD_TIMEOUT_S = 120.0


def lab_task(folder: Path) -> LabTask:
    ex = lab_folder(folder)
    argv = (sys.executable, "-m", "ttt_sm.lab.live", str(folder), "--nice", "5")
    return LabTask(ex.title, ex.slot, ex.chart_file, ex.class_name, argv)


def wait_for(what: str, condition: Callable[[], Any], timeout_s: float) -> Any:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        value = condition()
        if value:
            return value
        time.sleep(0.1)
    raise AssertionError(f"waited {timeout_s:g} s for {what}")


@dataclass
class Lab:
    client: TestClient
    watch: LabWatch
    session: Session
    ws: Any

    def state(self) -> dict[str, Any]:
        response = self.client.get("/api/lab")
        assert response.status_code == 200
        return dict(response.json())

    def next_lab_message(self, condition: Callable[[dict[str, Any]], bool], timeout_s: float) -> dict[str, Any]:
        """The first ``lab`` message the page's socket gets that meets `condition` (read in this thread)."""
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            m = self.ws.receive_json()
            if m.get("type") == "lab" and condition(m):
                return dict(m)
        raise AssertionError(f"no such lab message within {timeout_s:g} s")


@pytest.fixture
def lab(tmp_path: Path) -> Iterator[Lab]:
    watch = LabWatch(lab_task(tmp_path / "my_init3"), poll_s=0.05)
    dbg = Debugger.build(load_params(), seed=0, slots=watch.first_slots())
    session = Session(dbg, speed=None, running=False)
    app = create_app(session, lab=watch)
    with TestClient(app) as client, client.websocket_connect("/ws") as ws:
        ws.send_json({"type": "hello", "page": "lab"})
        assert ws.receive_json()["type"] == "session"
        yield Lab(client, watch, session, ws)


def test_a_broken_save_shows_file_and_line_and_a_fix_reloads_the_chart_and_reruns_the_checks(lab: Lab) -> None:
    first = lab.state()
    assert first["error"] is None and first["loads"] == 1
    assert first["running"].startswith("MyDriveInit3 (") and "drive_init3.py:" in first["running"]
    assert type(lab.session.debugger.robot.chart("DriveInit3")).__name__ == "MyDriveInit3"
    done = wait_for("the first checks", lambda: (s := lab.state())["checks"]["status"] in ("done", "error") and s,
                    CHECKS_TIMEOUT_S)
    assert done["checks"]["status"] == "done", done["checks"]
    assert done["checks"]["score"] == {"passed": 9, "total": 9}
    assert all(c["passed"] for c in done["checks"]["results"])
    running_class = type(lab.session.debugger.robot.chart("DriveInit3"))

    # a syntax error: one line, file:line, to the page; the chart that loaded keeps running
    save(lab.watch.task.chart_file, broken())
    m = lab.next_lab_message(lambda m: m["error"] is not None, RELOAD_TIMEOUT_S)
    assert m["error"].startswith(f"{lab.watch.task.chart_file}:{broken_line()}: syntax error")
    assert "\n" not in m["error"] and "Traceback" not in m["error"]
    assert m["loads"] == 1 and m["running"] == first["running"]
    assert type(lab.session.debugger.robot.chart("DriveInit3")) is running_class
    assert lab.session.call(lambda d: d.step(50)) is not None  # and it still runs
    assert RENAMED[1] not in lab.client.get("/api/diagram/DriveInit3").text

    # the fix: the robot built again with it, the diagram drawn anew, the checks run again
    save(lab.watch.task.chart_file, fixed())
    m = lab.next_lab_message(lambda m: m["loads"] == 2 and m["error"] is None, RELOAD_TIMEOUT_S)
    assert m["checks"]["of"] == 2 and m["checks"]["status"] == "running"
    robot = lab.session.debugger.robot
    assert type(robot.chart("DriveInit3")) is not running_class and robot.steps == 0  # from power-on
    svg = lab.client.get("/api/diagram/DriveInit3?view=overview").text
    assert f'data-state="DriveInit3.{RENAMED[1]}"' in svg and f'data-state="DriveInit3.{RENAMED[0]}"' not in svg
    session_info = [c for c in lab.session.info["charts"] if c["name"] == "DriveInit3"][0]
    assert RENAMED[1] in {s["id"] for s in session_info["states"]}
    first_check = lab.next_lab_message(lambda m: m["checks"]["of"] == 2 and m["checks"]["results"],
                                       CHECKS_TIMEOUT_S)
    assert first_check["checks"]["results"][0]["name"] == "drive 3 initialises from the rest pose"
    assert first_check["checks"]["results"][0]["passed"]


def test_a_class_that_does_not_fit_the_slot_is_one_line_and_the_robot_runs_on(lab: Lab) -> None:
    text = fixed().replace('        Data("ini2", "bool", False, "drive 2 is initialised"),\n', "")
    save(lab.watch.task.chart_file, text)
    m = lab.next_lab_message(lambda m: m["error"] is not None, RELOAD_TIMEOUT_S)
    assert "does not fit the DriveInit3 slot: missing input ini2" in m["error"]
    assert m["error"].startswith(f"{lab.watch.task.chart_file}:")
    assert m["loads"] == 1


def test_the_lab_routes_say_when_there_is_no_lab() -> None:
    dbg = Debugger.build(load_params(), seed=0)
    app = create_app(Session(dbg, speed=None, running=False), manage_session=False)
    with TestClient(app) as client:
        assert client.get("/api/lab").status_code == 404
        assert "ttt-sm gui --lab DIR" in client.get("/lab").text
