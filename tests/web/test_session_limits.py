"""No page can kill or freeze the cockpit's session (docs/gui.md, "Limits"; docs/reliability.md, "The cockpit's
session").

Each case was a way to end or stall the one running session from a page: a
command that raised a ``TypeError`` ended the robot, a flood of commands
queued without end, a step of 600,000 control steps held the simulation thread
for seconds, a coverage scenario that never ends kept a core and the process.
Driven in-process (Starlette's test client) or straight through the session.
"""

from __future__ import annotations

import json
import queue
import threading
import time
from typing import Any

import pytest
from starlette.testclient import TestClient

from ttt_sm.debug import breakpoints as bp_module
from ttt_sm.debug import inputs as inputs_module
from ttt_sm.debug.debugger import Debugger
from ttt_sm.debug.errors import DebugError
from ttt_sm.params import load_params
from ttt_sm.web import server as server_module
from ttt_sm.web.coverage import CoverageRuns
from ttt_sm.web.pages import PAGE_QUEUE
from ttt_sm.web.protocol import parse_command
from ttt_sm.web.server import create_app
from ttt_sm.web.session import Session

from .test_protocol import Page

WAIT_S = 120.0


class Held:
    """Holds the simulation thread (a job that waits) until the block ends: the session is busy."""

    def __init__(self, session: Session) -> None:
        self.session = session
        self.release = threading.Event()
        self.holding = threading.Event()

    def __enter__(self) -> Held:
        def hold(_dbg: Debugger) -> None:
            self.holding.set()
            self.release.wait(WAIT_S)
        self.session.call_soon(hold, lambda value, error: None)
        assert self.holding.wait(WAIT_S)
        return self

    def __exit__(self, *exc: object) -> None:
        self.release.set()


# -- a command's failure is an error reply, the session goes on ------------------------------------------------


@pytest.mark.parametrize("key", ["event", "self"])
def test_a_post_whose_data_take_a_name_the_charts_callbacks_use_is_refused(client: TestClient, session: Session,
                                                                            key: str) -> None:
    """The issue's killer: ``{"type":"post","chart":"Control","event":"button","data":{"event":1}}``."""
    with client.websocket_connect("/ws") as ws:
        page = Page(ws)
        page.join()
        answer = page.answer(page.send(type="post", chart="Control", event="button", data={key: 1}))
        assert answer["type"] == "error" and f"datum named {key!r}" in answer["error"]
        assert "TypeError" not in answer["error"]
        assert session.fault is None
        assert page.answer(page.send(type="tick", n=2))["ok"]  # the robot runs on
    assert session.fault is None and session.error is None


def test_a_post_with_a_datum_named_chart_is_taken_and_handled(client: TestClient, session: Session) -> None:
    with client.websocket_connect("/ws") as ws:
        page = Page(ws)
        page.join()
        assert page.answer(page.send(type="post", chart="Control", event="button", data={"chart": 1}))["ok"]
        assert page.answer(page.send(type="tick", n=2))["ok"]
    assert session.fault is None and session.call(lambda d: d.robot.charts["Control"].pending_events) == []


def test_a_handler_that_breaks_is_an_error_reply_in_words_and_the_robot_is_untouched(
        client: TestClient, session: Session, monkeypatch: pytest.MonkeyPatch) -> None:
    def broken(*args: Any, **kwargs: Any) -> None:
        raise RuntimeError("internal detail")

    monkeypatch.setattr(session.debugger, "release", broken)
    with client.websocket_connect("/ws") as ws:
        page = Page(ws)
        page.join()
        answer = page.answer(page.send(type="release"))
        assert answer["type"] == "error" and "failed inside the session before it changed anything" in answer["error"]
        assert "RuntimeError" not in answer["error"] and "internal detail" not in answer["error"]
        monkeypatch.undo()
        assert page.answer(page.send(type="step"))["ok"]
    assert session.fault is None and session._thread is not None and session._thread.is_alive()


def test_a_protocol_error_echoes_the_messages_id_and_command(client: TestClient) -> None:
    with client.websocket_connect("/ws") as ws:
        ws.send_text(json.dumps({"type": "step", "n": -3, "id": 42}))
        answer = ws.receive_json()
        assert (answer["type"], answer["id"], answer["command"]) == ("error", 42, "step")
        ws.send_text(json.dumps({"type": "launch", "id": "a7"}))
        answer = ws.receive_json()
        assert (answer["id"], answer["command"]) == ("a7", None)


def test_a_session_whose_thread_dies_tells_every_page_and_its_server_and_refuses_commands() -> None:
    s = Session(Debugger.build(load_params(), seed=0), speed=None, running=False)
    heard: list[dict[str, Any]] = []
    told: queue.Queue[str] = queue.Queue()
    cid = s.pages.connect(lambda text: heard.append(json.loads(text)))
    s.death_listeners.append(told.put)
    s.join(cid, "charts")  # joined: it gets what every page gets

    def broken() -> None:
        raise OSError("the disk is gone")

    s._flush = broken  # type: ignore[method-assign]
    s.start()
    try:
        why = told.get(timeout=WAIT_S)
        assert s.ended.wait(WAIT_S)
        assert "the session stopped (the disk is gone); restart ttt-sm gui" == why == s.error
        assert {"type": "error", "id": None, "command": None, "error": why, "fatal": True} in heard
        s.submit(cid, parse_command('{"type": "step", "id": 3}'))
        assert heard[-1]["type"] == "error" and heard[-1]["id"] == 3 and why in heard[-1]["error"]
    finally:
        s.stop()


# -- bounded queues and work --------------------------------------------------------------------------------


def test_a_page_may_have_16_commands_waiting_and_more_are_refused_at_once(session: Session) -> None:
    flood: list[dict[str, Any]] = []
    other: list[dict[str, Any]] = []
    a = session.pages.connect(lambda text: flood.append(json.loads(text)))
    b = session.pages.connect(lambda text: other.append(json.loads(text)))
    try:
        with Held(session):
            for i in range(40):
                session.submit(a, parse_command(json.dumps({"type": "pause", "id": i})))
            refused = [m for m in flood if m["type"] == "error"]
            assert [m["id"] for m in refused] == list(range(PAGE_QUEUE, 40))  # refused at once, while it is busy
            assert "16 commands waiting" in refused[0]["error"]
            session.submit(b, parse_command('{"type": "pause", "id": "b"}'))  # another page is not refused
            assert other == []
        replies = session.call(lambda d: None) or None  # the queue drained
        assert replies is None
        assert [m["id"] for m in flood if m["type"] == "reply"] == list(range(PAGE_QUEUE))
        assert [m["id"] for m in other] == ["b"] and other[0]["type"] == "reply"
        session.submit(a, parse_command('{"type": "pause", "id": "again"}'))  # the page's queue is free again
        session.call(lambda d: None)
        assert flood[-1]["id"] == "again" and flood[-1]["type"] == "reply"
    finally:
        session.pages.disconnect(a)
        session.pages.disconnect(b)


def test_a_step_of_600000_control_steps_pauses_after_its_budget_of_wall_time(client: TestClient,
                                                                            session: Session) -> None:
    with client.websocket_connect("/ws") as ws:
        page = Page(ws)
        page.join()
        before = session.call(lambda d: d.robot.steps)
        answer = page.answer(page.send(type="step", n=600_000))
        after = session.call(lambda d: d.robot.steps)
    assert answer["ok"] and answer["budget"] and "send it again to go on" in answer["text"]
    assert 0 < after - before < 600_000  # 600 simulated seconds: no machine runs that in the budget
    assert session.mode == "paused" and session.fault is None


def test_breakpoints_are_bounded_in_number_and_in_the_length_of_their_conditions(session: Session) -> None:
    def fill(dbg: Debugger) -> tuple[int, str, str]:
        dbg.delete(None)
        try:
            for _ in range(bp_module.MAX_BREAKPOINTS):
                dbg.add_breakpoint("enter DriveInit1.turn_back")
            try:
                dbg.add_breakpoint("enter DriveInit1.turn_back")
            except DebugError as exc:
                many = str(exc)
            dbg.delete(None)
            cond = "when " + " or ".join(["DriveInit1.pos_Encoder > 1000000"] * 14)  # 505 characters
            added = 0
            try:
                while True:
                    dbg.add_breakpoint(cond)
                    added += 1
            except DebugError as exc:
                long = str(exc)
            return added, many, long
        finally:
            dbg.delete(None)

    added, many, long = session.call(fill)
    assert "at most 50 breakpoints" in many
    assert added == bp_module.MAX_CONDITIONS_CHARS // 505 and "characters of conditions" in long


def test_posts_are_bounded_by_the_events_a_chart_holds_and_the_inputs_a_replay_repeats(
        session: Session, monkeypatch: pytest.MonkeyPatch) -> None:
    def flood(dbg: Debugger) -> tuple[int, str, str]:
        posted = 0
        try:
            while True:
                dbg.post("Control", "button")
                posted += 1
        except DebugError as exc:
            full = str(exc)
        dbg.tick(1)  # handled: room again
        monkeypatch.setattr(inputs_module, "MAX_ACTIONS", len(dbg.actions) + 1)
        dbg.post("Control", "button")
        try:
            dbg.post("Control", "button")
        except DebugError as exc:
            recorded = str(exc)
        dbg.tick(1)
        return posted, full, recorded

    posted, full, recorded = session.call(flood)
    assert posted == inputs_module.MAX_PENDING_EVENTS and "events waiting for its next chart tick" in full
    assert "the most a replay repeats" in recorded


NEVER = """\
name: never ends
max_step_s: 1.0e+300
steps:
  - run_until: {condition: "DriveInit1.pos_Encoder > 1000", timeout_s: 1.0e+12}
"""


def test_a_coverage_scenario_that_never_ends_is_ended_by_its_limit_and_by_close() -> None:
    from ttt_sm.web.coverage import run_for_coverage, scenario_from_text

    sent: queue.Queue[tuple[int, dict[str, Any]]] = queue.Queue()
    params = load_params()
    charts = {n: type(c) for n, c in Debugger.build(params, seed=0).robot.charts.items()}
    runs = CoverageRuns(params, charts, {}, lambda cid, m: sent.put((cid, m)), lambda m: None)
    scenario = scenario_from_text("never.yaml", NEVER)
    try:
        assert runs._worker.daemon  # never keeps the process alive after SIGTERM
        runs.limit_s = 0.5
        runs.start(4, "coverage_scenario", lambda check: run_for_coverage([scenario], params, charts, check=check))
        cid, m = sent.get(timeout=WAIT_S)
        assert cid == 4 and m["type"] == "error" and "stopped after 0.5 s of wall time" in m["error"]
        # a later run is not blocked by it; this one the session's stop ends
        runs.limit_s = 3600
        runs.start(4, "coverage_scenario", lambda check: run_for_coverage([scenario], params, charts, check=check))
        give_up = time.monotonic() + WAIT_S
        while not runs.running and time.monotonic() < give_up:
            time.sleep(0.01)
    finally:
        runs.close(timeout_s=WAIT_S)
    assert not runs._worker.is_alive()
    assert "the session stopped" in sent.get(timeout=WAIT_S)[1]["error"]


def test_a_request_that_needs_a_busy_session_gets_503_and_other_routes_are_served(
        client: TestClient, session: Session, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(server_module, "SESSION_WAIT_S", 0.3)
    with Held(session):
        ink = client.get("/api/arm/ink.png")
        assert ink.status_code == 503 and "did not answer within 0.3 s" in ink.text
        assert client.get("/api/diagram/Control?view=overview").status_code == 200  # never waits for the session
    assert client.get("/api/arm/ink.png").status_code == 200


def test_the_servers_own_commands_are_not_bounded_as_a_pages(session: Session) -> None:
    """``cid`` 0 is no page (the bench sends its commands so): never refused, never dropped."""
    for value in (2.0, "max"):
        session.submit(0, parse_command(json.dumps({"type": "speed", "value": value})))
    session.call(lambda d: None)
    assert session.speed is None


def test_a_page_that_has_used_its_share_of_the_session_is_refused_and_another_is_not(
        session: Session, monkeypatch: pytest.MonkeyPatch) -> None:
    from ttt_sm.web import pages as session_module

    monkeypatch.setattr(session_module, "PAGE_BURST_S", 0.0)  # no burst: any use at all is over the share
    monkeypatch.setattr(session_module, "PAGE_SHARE", 1e-9)  # ... and it does not fall back during the test
    greedy: list[dict[str, Any]] = []
    other: list[dict[str, Any]] = []
    a = session.pages.connect(lambda text: greedy.append(json.loads(text)))
    b = session.pages.connect(lambda text: other.append(json.loads(text)))
    try:
        session.submit(a, parse_command('{"type": "tick", "id": 1}'))
        session.call(lambda d: None)
        session.submit(a, parse_command('{"type": "tick", "id": 2}'))
        session.submit(b, parse_command('{"type": "pause", "id": 3}'))
        session.call(lambda d: None)
    finally:
        session.pages.disconnect(a)
        session.pages.disconnect(b)
    assert [(m["type"], m["id"]) for m in greedy] == [("reply", 1), ("error", 2)]
    assert "used the session more than one page may" in greedy[1]["error"]
    assert [(m["type"], m["id"]) for m in other] == [("reply", 3)]


def test_a_warning_reaches_every_page_and_the_session_runs_on(session: Session) -> None:
    heard: list[dict[str, Any]] = []
    cid = session.pages.connect(lambda text: heard.append(json.loads(text)))
    try:
        session.join(cid, "charts")
        session.warn_pages("tracing stopped: out/gui/trace.jsonl: No space left on device")
    finally:
        session.pages.disconnect(cid)
    assert heard[-1] == {"type": "error", "id": None, "command": None, "fatal": False,
                         "error": "tracing stopped: out/gui/trace.jsonl: No space left on device"}
    assert session.error is None and session.call(lambda d: True)


def test_the_streamed_trace_is_served_as_written_so_far(tmp_path: Any) -> None:
    dbg = Debugger.build(load_params(), seed=0, trace_path=tmp_path / "trace.jsonl")
    s = Session(dbg, speed=None, running=False)
    s.start()
    try:
        s.call(lambda d: d.step(3000))
        with TestClient(create_app(s, manage_session=False)) as c:
            got = c.get("/api/trace.jsonl")
        written = (tmp_path / "trace.jsonl").read_bytes()
        assert got.status_code == 200 and written.startswith(got.content) and got.content.count(b"\n") >= 2
    finally:
        s.stop()


def test_a_page_over_its_share_has_its_messages_dropped_unparsed_and_is_told_once_a_window(
        client: TestClient, session: Session, monkeypatch: pytest.MonkeyPatch) -> None:
    """A flood costs the server a check per message, not a parse and a reply each (issue 28: the robot's pace
    under a flood of 20,000 ``hello``s)."""
    from ttt_sm.web import pages as session_module

    monkeypatch.setattr(session_module, "PAGE_BURST_S", 0.0)  # no burst: any use at all is over the share
    monkeypatch.setattr(session_module, "PAGE_SHARE", 1e-9)  # ... and it does not fall back during the test
    monkeypatch.setattr(session_module, "DROP_NOTICE_S", 1e9)  # one window: the whole test
    flood = 300
    watcher = session.pages.connect(lambda text: None)  # another page: the one a flood must not starve
    with client.websocket_connect("/ws") as ws:
        cid = max(session.pages.ids())
        ws.send_text('{"type": "tick", "id": 1}')
        assert json.loads(ws.receive_text())["id"] == 1  # handled: the page has used the session now ...
        session.call(lambda d: None)  # ... and its use is counted (after the reply went out)
        for i in range(flood):  # hellos (a full frame each) and text that is no JSON at all
            ws.send_text(json.dumps({"type": "hello", "id": i + 2}) if i % 2 else "{not json")
        notice = json.loads(ws.receive_text())
        deadline = time.monotonic() + 60  # a timeout for a loaded machine, not a measurement
        while session.pages.counts(cid)["dropped"] < flood and time.monotonic() < deadline:
            time.sleep(0.01)
        counts = session.pages.counts(cid)
    session.pages.disconnect(watcher)
    assert counts == {"parsed": 1, "dropped": flood, "refused": 0}  # none parsed, none refused after parsing
    assert notice["type"] == "error" and notice["id"] is None and notice["dropped"] == 1
    assert notice["error"].startswith("refused: 1 message(s) dropped unread: this page's commands have used")


def test_one_page_alone_with_the_robot_paused_is_never_held_back(
        session: Session, monkeypatch: pytest.MonkeyPatch) -> None:
    # a loaded run of the suite: a replay took over 2 s of the thread, and the page's next Run was refused
    # (the page waited for a breakpoint that never came); nobody else needed the thread
    from ttt_sm.web import pages as session_module

    monkeypatch.setattr(session_module, "PAGE_BURST_S", 0.0)  # any use at all is over the burst
    monkeypatch.setattr(session_module, "PAGE_SHARE", 1e-9)  # ... and it does not fall back during the test
    heard: list[dict[str, Any]] = []
    alone = session.pages.connect(lambda text: heard.append(json.loads(text)))
    try:
        session.submit(alone, parse_command('{"type": "tick", "id": 1}'))
        session.call(lambda d: None)
        assert not session.pages.refusing(alone, time.perf_counter())
        session.submit(alone, parse_command('{"type": "tick", "id": 2}'))
        session.call(lambda d: None)
        other = session.pages.connect(lambda text: None)  # now someone else needs the thread too: held back
        try:
            assert session.pages.refusing(alone, time.perf_counter())
        finally:
            session.pages.disconnect(other)
    finally:
        session.pages.disconnect(alone)
    assert [(m["type"], m["id"]) for m in heard] == [("reply", 1), ("reply", 2), ("error", None)]
    assert "used the session more than one page may" in heard[2]["error"]  # told when held back, not before


def test_a_joined_page_that_says_hello_again_gets_its_full_frame_with_the_next_frame_not_one_per_hello() -> None:
    """A flood of ``hello``s from a page that joined costs the robot one full frame a frame period, not one
    per hello (issue 28: the robot's pace under a flood of 20,000 ``hello``s)."""
    session = Session(Debugger.build(load_params(), seed=0), speed=None, running=False)
    got: list[dict[str, Any]] = []
    watched: list[dict[str, Any]] = []
    cid = session.pages.connect(lambda text: got.append(json.loads(text)))
    watcher = session.pages.connect(lambda text: watched.append(json.loads(text)))
    session.start()
    try:
        session.submit(watcher, parse_command('{"type": "hello"}'))
        session.submit(cid, parse_command('{"type": "hello"}'))
        session.call(lambda d: None)
        assert [m["type"] for m in got[:2]] == ["session", "frame"] and got[1]["full"]
        while session.call(lambda d: session._dirty):  # the frame due after power-on has gone out
            time.sleep(0.01)
        mark = len(got)
        seq = got[-1]["seq"]

        def burst(d: Debugger) -> None:  # ten hellos handled between the same two frames
            for _ in range(10):
                session._handle(cid, parse_command('{"type": "hello"}'))
            d.step(200)
        session.call(burst)
        deadline = time.monotonic() + 60  # a timeout for a loaded machine, not a measurement
        while not [m for m in got[mark:] if m["type"] == "frame"] and time.monotonic() < deadline:
            time.sleep(0.01)
        steps = session.call(lambda d: d.robot.steps)
    finally:
        session.stop()
    again = got[mark:]
    assert [m["type"] for m in again] == ["session", "frame"]  # once for the ten, with the next frame
    frames = again[1:]
    assert frames[0]["full"] and frames[0]["seq"] > seq and again[0]["info"]["charts"]
    assert frames[0]["steps"] == steps and frames[0]["data"]  # the robot as it is now, whole
    others = [m for m in watched if m["type"] == "frame" and m["seq"] == frames[0]["seq"]]
    assert len(others) == 1 and not others[0]["full"]  # the other page gets the same frame, as a change only
