"""Live while writing, without a browser: ``gui --lab``'s watcher over the ASGI app (Starlette's TestClient).

The student's folder starts with the tutorial's solution: it runs in its slot
and its checks pass.  A save with a syntax error reaches every page as one
line with file:line, and the chart that loaded last keeps running; a save
that fixes it rebuilds the robot with it (a renamed state in the diagram) and
runs the checks again.  A chart that raises while the robot runs it is shown
at its file:line; the arm holds where it stands, the session stays, and the
next good save runs on.

Every wait is for a message and bounded twice: by a number of messages (a
paused session sends a few per save) and by a generous overall time, so a
message that never comes fails the test with what it waited for and what
came instead; nothing here depends on how fast the machine is.
"""

from __future__ import annotations

import queue
import sys
import threading
import time
from collections import Counter
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

from .lab_files import RENAMED, broken, broken_line, fixed, lab_folder, raising, raising_line, save

#: The longest any one wait may take, s: only there so that a message that never comes fails instead of
#: hanging.  Generous: the longest wait, for the checks (a twin and three scenarios in a process at low
#: priority), took ~20 s on a 2-core machine with a load of 10.
WAIT_S = 180.0
#: The most messages one wait reads before it gives up (a running session sends ~30 frames a second).
MAX_MESSAGES = 20_000

Message = dict[str, Any]


def summary(m: Message) -> str:
    """One message in a few words, for a failure's report."""
    if m.get("type") == "lab":
        checks = m["checks"]
        return (f"lab(version {m['version']}, loads {m['loads']}, error {m['error']!r},"
                f" checks of chart {checks['of']} {checks['status']}, {len(checks['results'])} results)")
    if m.get("type") == "frame":
        return f"frame(t {m['t']}, steps {m['steps']}, mode {m['mode']})"
    if m.get("type") in ("reply", "error"):
        return f"{m['type']}({m.get('command')}: {m.get('text') or m.get('error')!r})"
    return str(m.get("type"))


def came(seen: list[Message]) -> str:
    if not seen:
        return "no message came"
    kinds = ", ".join(f"{n} {kind}" for kind, n in Counter(str(m.get("type")) for m in seen).items())
    return f"{len(seen)} messages came ({kinds}); the last: {'; '.join(summary(m) for m in seen[-4:])}"


class Socket:
    """The page's WebSocket, read by a thread of its own into a queue, so that every wait on it is bounded.

    (The TestClient's ``receive_json`` waits for ever when no message comes.)
    """

    def __init__(self, ws: Any) -> None:
        self.ws = ws
        self._inbox: queue.Queue[Message | BaseException] = queue.Queue()
        threading.Thread(target=self._read, name="lab-test-socket", daemon=True).start()

    def _read(self) -> None:
        while True:
            try:
                message = self.ws.receive_json()
            except BaseException as exc:  # closed (the test is over) or broken: the wait going on says so
                self._inbox.put(exc)
                return
            self._inbox.put(message)

    def send(self, message: Message) -> None:
        self.ws.send_json(message)

    def wait_for(self, what: str, condition: Callable[[Message], bool], *,
                 max_messages: int = MAX_MESSAGES, timeout_s: float = WAIT_S) -> Message:
        """The first message that meets `condition`.

        An AssertionError naming `what`, and the messages that came instead, when
        none of the next `max_messages` does, none comes within `timeout_s`
        overall, or the socket closes.
        """
        seen: list[Message] = []
        deadline = time.monotonic() + timeout_s
        while len(seen) < max_messages:
            try:
                item = self._inbox.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                raise AssertionError(f"waited {timeout_s:g} s for {what}: {came(seen)}, then none") from None
            if isinstance(item, BaseException):
                raise AssertionError(f"waiting for {what}, the socket closed ({type(item).__name__}: {item});"
                                     f" before that {came(seen)}")
            if condition(item):
                return item
            seen.append(item)
        raise AssertionError(f"{what}: not one of the {max_messages} messages read; {came(seen)}")


def lab_task(folder: Path) -> LabTask:
    ex = lab_folder(folder)
    argv = (sys.executable, "-m", "ttt_sm.lab.live", str(folder), "--nice", "5")
    return LabTask(ex.title, ex.slot, ex.chart_file, ex.class_name, argv)


@dataclass
class Lab:
    client: TestClient
    watch: LabWatch
    session: Session
    socket: Socket

    def state(self) -> Message:
        response = self.client.get("/api/lab")
        assert response.status_code == 200
        return dict(response.json())

    def wait_for_lab(self, what: str, condition: Callable[[Message], bool]) -> Message:
        """The lab's state once it meets `condition`: now (``/api/lab``), else the first ``lab`` message that does.

        The page joined before this is asked, so every change after it comes as a
        message; messages older than the state read now are passed over.
        """
        now = self.state()
        if condition(now):
            return now
        return self.socket.wait_for(
            what, lambda m: m.get("type") == "lab" and m["version"] >= now["version"] and condition(m))


@pytest.fixture
def lab(tmp_path: Path) -> Iterator[Lab]:
    watch = LabWatch(lab_task(tmp_path / "my_init3"), poll_s=0.05)
    dbg = Debugger.build(load_params(), seed=0, slots=watch.first_slots())
    session = Session(dbg, speed=None, running=False)
    app = create_app(session, lab=watch)
    with TestClient(app) as client, client.websocket_connect("/ws") as ws:
        socket = Socket(ws)
        socket.send({"type": "hello", "page": "lab"})
        socket.wait_for("the session's description, first after hello", lambda m: m["type"] == "session",
                        max_messages=1)
        yield Lab(client, watch, session, socket)


def test_a_broken_save_shows_file_and_line_and_a_fix_reloads_the_chart_and_reruns_the_checks(lab: Lab) -> None:
    first = lab.state()
    assert first["error"] is None and first["loads"] == 1
    assert first["running"].startswith("MyDriveInit3 (") and "drive_init3.py:" in first["running"]
    assert type(lab.session.debugger.robot.chart("DriveInit3")).__name__ == "MyDriveInit3"
    done = lab.wait_for_lab("the first chart's checks to end", lambda s: s["checks"]["status"] in ("done", "error"))
    assert done["checks"]["status"] == "done", done["checks"]
    assert done["checks"]["score"] == {"passed": 9, "total": 9}
    assert all(c["passed"] for c in done["checks"]["results"])
    running_class = type(lab.session.debugger.robot.chart("DriveInit3"))

    # a syntax error: one line, file:line, to the page; the chart that loaded keeps running
    save(lab.watch.task.chart_file, broken())
    m = lab.wait_for_lab("the broken save's error", lambda m: m["error"] is not None)
    assert m["error"].startswith(f"{lab.watch.task.chart_file}:{broken_line()}: syntax error")
    assert "\n" not in m["error"] and "Traceback" not in m["error"]
    assert m["loads"] == 1 and m["running"] == first["running"]
    assert type(lab.session.debugger.robot.chart("DriveInit3")) is running_class
    assert lab.session.call(lambda d: d.step(50)) is not None  # and it still runs
    assert RENAMED[1] not in lab.client.get("/api/diagram/DriveInit3").text

    # the fix: the robot built again with it, the diagram drawn anew, the checks run again
    save(lab.watch.task.chart_file, fixed())
    m = lab.wait_for_lab("the fixed save loaded (loads 2, no error)", lambda m: m["loads"] == 2 and m["error"] is None)
    assert m["checks"]["of"] == 2
    robot = lab.session.debugger.robot
    assert type(robot.chart("DriveInit3")) is not running_class and robot.steps == 0  # from power-on
    svg = lab.client.get("/api/diagram/DriveInit3?view=overview").text
    assert f'data-state="DriveInit3.{RENAMED[1]}"' in svg and f'data-state="DriveInit3.{RENAMED[0]}"' not in svg
    session_info = [c for c in lab.session.info["charts"] if c["name"] == "DriveInit3"][0]
    assert RENAMED[1] in {s["id"] for s in session_info["states"]}
    first_check = lab.wait_for_lab("the fixed chart's first check",
                                   lambda m: m["checks"]["of"] == 2 and bool(m["checks"]["results"]))
    assert first_check["checks"]["results"][0]["name"] == "drive 3 initialises from the rest pose"
    assert first_check["checks"]["results"][0]["passed"]


def test_a_class_that_does_not_fit_the_slot_is_one_line_and_the_robot_runs_on(lab: Lab) -> None:
    text = fixed().replace('        Data("ini2", "bool", False, "drive 2 is initialised"),\n', "")
    save(lab.watch.task.chart_file, text)
    m = lab.wait_for_lab("the save's error", lambda m: m["error"] is not None)
    assert "does not fit the DriveInit3 slot: missing input ini2" in m["error"]
    assert m["error"].startswith(f"{lab.watch.task.chart_file}:")
    assert m["loads"] == 1


def test_a_chart_that_raises_while_it_runs_holds_the_arm_keeps_the_session_and_a_fix_runs_on(lab: Lab) -> None:
    chart_file = lab.watch.task.chart_file
    save(chart_file, raising())
    lab.wait_for_lab("the raising chart loaded (loads 2, no error)", lambda m: m["loads"] == 2 and m["error"] is None)
    held: list[list[float]] = []

    def spy_on_setpoints(dbg: Debugger) -> None:  # the arm's setpoints from now on, as they are set
        arm = dbg.robot.arm
        set_setpoints = arm.set_setpoints

        def recorded(q: Any, fr_sw: bool = False) -> None:
            held.append([float(v) for v in q])
            set_setpoints(q, fr_sw)
        arm.set_setpoints = recorded  # type: ignore[method-assign]

    lab.session.call(spy_on_setpoints)
    lab.socket.send({"type": "run", "id": 1})

    # the error, at its file:line, to the page; the run paused, the robot where the exception left it
    m = lab.wait_for_lab("the chart's exception on the page", lambda m: m["error"] is not None)
    assert m["error"].startswith(f"{chart_file}:{raising_line()}: ZeroDivisionError: float division by zero"), m
    assert "the arm holds where it stands" in m["error"] and m["loads"] == 2
    frame = lab.socket.wait_for("a frame that says why the run stopped",
                                lambda m: m["type"] == "frame" and bool(m.get("stop")))
    assert frame["mode"] == "paused" and frame["error"] is None
    assert frame["stop"]["kind"] == "error" and "ZeroDivisionError" in frame["stop"]["text"], frame["stop"]
    session = lab.session
    assert session.mode == "paused" and session.fault is not None and session.error is None

    # the arm held: the one setpoint set since is where the drives and the servo stand
    def where_the_arm_stands(dbg: Debugger) -> tuple[int, list[float]]:
        arm = dbg.robot.arm
        return dbg.robot.steps, [*arm.encoder_angles(), arm.servo_setpoint]

    steps, pose = session.call(where_the_arm_stands)  # the session answers: it is alive
    assert held == [pose]
    # and that robot runs no more: run and step are refused with why, nothing moves
    lab.socket.send({"type": "step", "n": 5, "id": 2})
    refused = lab.socket.wait_for("the refusal of step", lambda m: m["type"] == "error" and m["id"] == 2)
    assert refused["error"].startswith("step: the robot stopped at t = 0.0000 s") and "ZeroDivisionError" in \
        refused["error"]
    lab.socket.send({"type": "run", "id": 3})
    refused = lab.socket.wait_for("the refusal of run", lambda m: m["type"] == "error" and m["id"] == 3)
    assert refused["error"].startswith("run: the robot stopped")
    assert session.call(where_the_arm_stands) == (steps, pose) and held == [pose]

    # the fix: built again from power-on, and it runs on as it did before the exception
    save(chart_file, fixed())
    m = lab.wait_for_lab("the fixed save loaded (loads 3, no error)", lambda m: m["loads"] == 3 and m["error"] is None)
    assert session.fault is None
    frame = lab.socket.wait_for("a frame of the fixed chart running",
                                lambda m: m["type"] == "frame" and m["mode"] == "running" and m["steps"] > 0)
    assert frame.get("stop") is None and frame["error"] is None


def test_the_lab_routes_say_when_there_is_no_lab() -> None:
    dbg = Debugger.build(load_params(), seed=0)
    app = create_app(Session(dbg, speed=None, running=False), manage_session=False)
    with TestClient(app) as client:
        assert client.get("/api/lab").status_code == 404
        assert "ttt-sm gui --lab DIR" in client.get("/lab").text
