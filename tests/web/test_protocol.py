"""The cockpit's WebSocket protocol through Starlette's ASGI test client: no browser, no socket.

What a page sends is checked before the session sees it; what is wrong gets an
error that names it, and the session goes on unchanged.  The session's frames
carry every transition since the frame before, and the debugger's commands
do what ``ttt-sm debug`` does.
"""

from __future__ import annotations

import inspect
import json
import random
import re
import time
import types
from typing import Any

import pytest
from starlette.testclient import TestClient
from starlette.websockets import WebSocketDisconnect

from ttt_sm.debug.debugger import Debugger
from ttt_sm.params import load_params
from ttt_sm.web.commands import SPECS
from ttt_sm.web.commands.spec import collect, command
from ttt_sm.web.fields import integer
from ttt_sm.web.protocol import COMMANDS, ProtocolError, parse_command
from ttt_sm.web.server import create_app
from ttt_sm.web.session import Session


class Page:
    """One WebSocket, as a page holds it: send commands, read messages by type."""

    def __init__(self, ws: Any) -> None:
        self.ws = ws
        self.n = 0

    def send(self, **command: Any) -> int:
        self.n += 1
        self.ws.send_text(json.dumps({**command, "id": self.n}))
        return self.n

    def answer(self, msg_id: int | None = None) -> dict[str, Any]:
        """The reply or error to a command (frames in between are skipped)."""
        while True:
            m = self.ws.receive_json()
            if m["type"] in ("reply", "error") and (msg_id is None or m["id"] == msg_id):
                return m

    def frame(self) -> dict[str, Any]:
        while True:
            m = self.ws.receive_json()
            if m["type"] == "frame":
                return m

    def join(self) -> tuple[dict[str, Any], dict[str, Any]]:
        self.send(type="hello")
        info = self.ws.receive_json()
        assert info["type"] == "session"
        full = self.ws.receive_json()
        assert full["type"] == "frame" and full["full"]
        return info["info"], full


def state_of(session: Session) -> tuple[Any, ...]:
    """What must not change when a page sends nonsense: the robot's whole state and the debugger's."""
    def read(dbg: Debugger) -> tuple[Any, ...]:
        return (json.dumps(dbg.fingerprint(), sort_keys=True, default=str),
                [(b.id, b.spec, b.enabled) for b in dbg.breakpoints], [a.describe() for a in dbg.actions])
    return (*session.call(read), session.mode, session.speed)


# -- messages checked one by one --------------------------------------------------------------------


@pytest.mark.parametrize("message, named", [
    ("not json", "not JSON"),
    ("[1, 2]", "JSON object"),
    ('{"kind": "step"}', '"type"'),
    ('{"type": "launch"}', "unknown command type \"launch\""),
    ('{"type": "step", "n": -3}', "step: 'n' must be a whole number from 1"),
    ('{"type": "step", "n": 1.5}', "'n' must be a whole number"),
    ('{"type": "step", "n": true}', "'n' must be a whole number"),
    ('{"type": "step", "count": 2}', "unknown field 'count'"),
    ('{"type": "speed", "value": 11}', "'value' must be a number from 0.1 to 10"),
    ('{"type": "speed", "value": NaN}', "not JSON"),
    ('{"type": "speed", "value": 1e999}', "'value' must be a number"),
    ('{"type": "break"}', "break: missing field 'spec'"),
    ('{"type": "break", "spec": ""}', "'spec' is empty"),
    ('{"type": "break", "spec": "x\\u0000y"}', "control characters"),
    ('{"type": "set", "chart": "Control; rm", "name": "row", "value": 1}', "'chart' must be a name"),
    ('{"type": "post", "chart": "Control", "event": "button", "data": [1]}', "'data' must be an object"),
    ('{"type": "replay", "tick": "12"}', "'tick' must be a whole number"),
    ('{"type": "replay", "tick": 3, "drop": "yes"}', "'drop' must be"),
    ('{"type": "drive1_stop"}', "drive1_stop: missing field 'stop'"),
    ('{"type": "drive1_stop", "stop": 1}', "'stop' must be"),
    ('{"type": "break_delete", "breakpoint": 0}', "'breakpoint' must be a whole number from 1"),
    ('{"type": "step", "id": {"a": 1}}', "'id' must be"),
    ("[" * 100000 + "]" * 100000, "nested too deeply"),
])
def test_a_bad_message_is_named(message: str, named: str) -> None:
    with pytest.raises(ProtocolError) as err:
        parse_command(message)
    assert named in str(err.value)


def test_every_command_with_its_defaults_is_accepted() -> None:
    assert parse_command('{"type": "step"}').args == {"n": 1}
    assert parse_command('{"type": "speed", "value": "max"}').args == {"value": None}
    assert parse_command('{"type": "break_delete", "breakpoint": "all"}').args == {"breakpoint": None}
    assert parse_command('{"type": "next", "id": "a"}').args == {"timeout_s": 10.0}
    assert parse_command(b'{"type": "tick", "n": 3}').args == {"n": 3}
    assert set(COMMANDS) >= {"run", "pause", "step", "tick", "next", "speed", "break", "set", "post", "replay"}


def test_a_message_too_long_is_refused_before_it_is_read() -> None:
    with pytest.raises(ProtocolError, match="at most"):
        parse_command('{"type": "break", "spec": "' + "x" * 600_000 + '"}')


def test_each_command_is_declared_once_beside_its_handler() -> None:
    """The protocol's fields are the handlers' declarations; a handler takes exactly the fields declared."""
    assert {kind: dict(fields) for kind, fields in COMMANDS.items()} == \
        {kind: dict(spec.fields) for kind, spec in SPECS.items()}
    for kind, spec in SPECS.items():
        assert spec.type == kind and (spec.handler.__doc__ or "").strip(), kind
        assert list(inspect.signature(spec.handler).parameters)[2:] == list(spec.fields), kind
    assert [k for k, s in SPECS.items() if not s.queued] == ["ack"]  # noted in the server's thread, not queued


def test_a_handler_that_does_not_take_its_declared_fields_is_refused_when_declared() -> None:
    def step(session: Any, cid: int, count: int) -> None:
        """Steps."""
    with pytest.raises(TypeError, match="command 'step': .*step takes count after .*declared fields are n"):
        command("step", n=integer(1, 5))(step)
    with pytest.raises(TypeError, match="declared twice"):
        collect([types.SimpleNamespace(a=SPECS["run"]), types.SimpleNamespace(b=SPECS["run"])])  # type: ignore[list-item]


# -- the session through the WebSocket --------------------------------------------------------------


def test_a_page_joins_and_gets_what_runs_and_a_full_frame(client: TestClient, session: Session) -> None:
    with client.websocket_connect("/ws") as ws:
        info, full = Page(ws).join()
    assert [c["name"] for c in info["charts"]] == ["DriveInit1", "DriveInit2", "DriveInit3", "Control", "Safety"]
    control = next(c for c in info["charts"] if c["name"] == "Control")
    wait_1 = next(s for s in control["states"] if s["id"] == "wait_1")
    assert wait_1["qname"] == "Control.start_stop.wait_1"
    assert {"overview", "whole"} <= {v["key"] for v in control["views"]}
    q_true = next(s for s in info["signals"] if s["name"] == "q_true")
    assert q_true["simulation_only"] and q_true["unit"] == "rad"
    robot_active = session.call(lambda d: {n: sorted(c.configuration_values) for n, c in d.robot.charts.items()})
    assert full["active"] == robot_active
    units = {d["name"]: d["unit"] for d in next(c for c in info["charts"] if c["name"] == "DriveInit1")["data"]}
    assert units["pos_out"] == "rad" and full["data"]["DriveInit1"]["pos_out"].endswith("deg)")


def test_step_and_tick_advance_by_one(client: TestClient, session: Session) -> None:
    with client.websocket_connect("/ws") as ws:
        page = Page(ws)
        _, full = page.join()
        steps = full["steps"]
        assert page.answer(page.send(type="step"))["ok"]
        frame = page.frame()
        assert (frame["steps"], frame["tick"]) == (steps + 1, session.call(lambda d: d.robot.chart_ticks))
        before = frame["tick"]
        reply = page.answer(page.send(type="tick"))
        assert "done" in reply["text"]
        frame = page.frame()
        assert frame["tick"] == before + 1


def test_frames_carry_every_transition_once_and_in_order(client: TestClient, session: Session) -> None:
    with client.websocket_connect("/ws") as ws:
        page = Page(ws)
        page.join()
        first = session.call(lambda d: len(d.trace.records))
        start = session.call(lambda d: d.robot.steps)
        seen: list[dict[str, Any]] = []
        while (done := session.call(lambda d: d.robot.steps)) < start + 12_000:  # the init charts' first transitions
            msg_id = page.send(type="step", n=start + 12_000 - done)  # a long one pauses after 1 s of wall time
            while (m := ws.receive_json())["type"] != "reply" or m["id"] != msg_id:
                if m["type"] == "frame":
                    assert m["transitions_total"] == len(m["transitions"])
                    seen += m["transitions"]
        steps_end = done
        while True:
            frame = page.frame()
            seen += frame["transitions"]
            assert frame["transitions_total"] == len(frame["transitions"])  # none left out here
            if frame["steps"] >= steps_end and not frame["transitions"]:
                break
            if len(seen) and frame["steps"] >= steps_end:
                break
        records = session.call(lambda d: list(d.trace.records))[first:]
    assert [(t["chart"], t["source"], t["target"], t["tick"]) for t in seen] == \
        [(r.chart, r.source, r.target, r.tick) for r in records]
    assert len(seen) >= 5 and [t["n"] for t in seen] == sorted(t["n"] for t in seen)
    structures = {name: type(c).structure() for name, c in session.debugger.robot.charts.items()}
    for t in seen:
        info = structures[t["chart"]].transitions[t["index"]]
        assert (info.source, info.target) == (t["source"], t["target"])


def test_commands_of_the_debugger_answer_as_the_shell_does(client: TestClient, session: Session) -> None:
    with client.websocket_connect("/ws") as ws:
        page = Page(ws)
        page.join()
        ok = page.answer(page.send(type="break", spec="enter DriveInit1.turn_bak"))
        assert ok["type"] == "error" and "did you mean 'turn_back'" in ok["error"]
        ok = page.answer(page.send(type="break", spec="when DriveInit1.pos_Encoder > > 1"))
        assert ok["type"] == "error" and "column" in ok["error"]
        ok = page.answer(page.send(type="set", chart="DriveInit1", name="stop", value="maybe"))
        assert ok["type"] == "error" and "flag" in ok["error"]
        ok = page.answer(page.send(type="post", chart="DriveInit1", event="stop"))
        assert ok["type"] == "error"
        bp = page.answer(page.send(type="break", spec="enter DriveInit1.turn_back"))
        assert bp["ok"] and bp["breakpoint"] >= 1
        assert page.answer(page.send(type="break_delete", breakpoint=bp["breakpoint"]))["ok"]


def test_a_thousand_malformed_or_random_messages_each_get_an_error_and_change_nothing(
        client: TestClient, session: Session) -> None:
    rng = random.Random(11)
    junk_values: list[Any] = [None, True, -1, 2**70, -1e308, "", "x" * 300, [], {}, [1, [2]], {"a": {}},
                              "enter", "DriveInit1", "'; DROP", "\u202e", "🤖"]
    kinds = [*COMMANDS, "", "Run", "eval", "__import__", "hello ", None, 5]
    fields = ["n", "value", "spec", "chart", "name", "tick", "breakpoint", "files", "report", "data", "force", "x"]

    def message(i: int) -> str:
        form = i % 5
        if form == 0:  # not JSON, or not an object
            return rng.choice(["", "{", "}", "null", "[]", "1", '"run"', "{'type': 'run'}", "\x00\x01",
                               "{\"type\": \"run\",}", "{\"type\": NaN}", "[" * 50])
        if form == 1:  # an unknown command type
            return json.dumps({"type": rng.choice(["launch", "Run", "eval", "", "hello ", "_call", "__init__"])})
        kind = rng.choice([k for k in kinds if isinstance(k, str) and k in COMMANDS
                           and k not in ("hello", "run", "pause", "coverage_clear", "ack",
                                         "drive1_stop")])  # a flag its only field: junk may be a valid one
        body: dict[str, Any] = {"type": kind}
        if form == 2:  # wrong types and ranges in known fields
            for name in COMMANDS[kind]:
                body[name] = rng.choice(junk_values)
            if not COMMANDS[kind]:
                body["x"] = 1
        elif form == 3:  # fields the command does not have
            body[rng.choice(fields) + "_"] = rng.choice(junk_values)
        else:  # names the session does not know: refused by the debugger, one line
            body.update({"chart": "NoSuchChart", "name": "nothing", "value": "1", "event": "nothing",
                         "spec": "enter NoSuchChart.state", "breakpoint": 1, "enabled": True, "files": ["none.yaml"],
                         "report": {"NoSuchChart": {"entered": [], "taken": []}}})
            body = {k: v for k, v in body.items() if k == "type" or k in COMMANDS[kind]}
            if kind in ("step", "tick", "next", "speed", "replay", "timeline", "release", "coverage_scenario"):
                body = {"type": kind, "junk": 1}
        return json.dumps(body) if rng.random() < 0.9 else json.dumps(body).encode().decode()

    before = state_of(session)
    with client.websocket_connect("/ws") as ws:
        page = Page(ws)
        page.join()
        for i in range(1000):
            ws.send_text(message(i))
            answer = page.answer()
            assert answer["type"] == "error", (i, message, answer)
            assert answer["error"] and len(answer["error"]) < 600
        # the connection is still good, and the session answers
        assert page.answer(page.send(type="speed", value="max"))["ok"]
    assert state_of(session) == before


def test_closing_one_page_changes_nothing_for_another(client: TestClient, session: Session) -> None:
    with client.websocket_connect("/ws") as ws_a:
        a = Page(ws_a)
        a.join()
        with client.websocket_connect("/ws") as ws_b:
            b = Page(ws_b)
            b.join()
            assert b.answer(b.send(type="tick", n=2))["ok"]
            b.frame()
        seq_before = a.frame()["seq"]
        assert a.answer(a.send(type="tick"))["ok"]
        assert a.frame()["seq"] > seq_before
    assert len(session.pages) == 0


def test_the_trace_is_saved_when_the_session_stops(tmp_path) -> None:
    dbg = Debugger.build(load_params(), seed=0)
    s = Session(dbg, speed=None, running=True, trace_path=tmp_path / "gui" / "trace.jsonl")
    s.start()
    s.call(lambda d: d.robot.steps)  # let it run a little
    reached = s.call(lambda d: d.next(5.0).kind)
    assert reached == "transition"
    path = s.stop()
    assert path == tmp_path / "gui" / "trace.jsonl"
    lines = path.read_text().splitlines()
    assert len(lines) == len(dbg.trace.records) >= 1
    assert json.loads(lines[0])["chart"] == dbg.trace.records[0].chart


# -- the token, the Host and the Origin ---------------------------------------------------------------


def refused(client: TestClient, path: str, headers: dict[str, str] | None = None) -> int:
    """The close code of a WebSocket the server refuses before accepting it."""
    with pytest.raises(WebSocketDisconnect) as err, client.websocket_connect(path, headers=headers or {}) as ws:
        ws.receive_text()
    return err.value.code


def test_another_host_needs_the_token_and_a_request_without_it_gets_403(session: Session) -> None:
    app = create_app(session, token="s3cret", hosts=["testserver"], manage_session=False)
    with TestClient(app) as c:
        assert c.get("/charts").status_code == 403
        assert "token" in c.get("/").text
        ok = c.get("/charts?token=s3cret")
        assert ok.status_code == 200 and "ttt_sm_token" in ok.headers["set-cookie"]
        assert c.get("/").status_code == 200  # the cookie now
        with TestClient(app) as fresh:
            assert refused(fresh, "/ws") == 1008
        with TestClient(app) as fresh, fresh.websocket_connect("/ws?token=s3cret") as ws:
            assert Page(ws).join()[1]["full"]
    with TestClient(app) as fresh:
        assert fresh.get("/charts?token=wrong").status_code == 403


def test_a_foreign_host_header_or_origin_is_refused(session: Session) -> None:
    app = create_app(session, hosts=["127.0.0.1:8765"], manage_session=False)
    with TestClient(app, base_url="http://127.0.0.1:8765") as c:
        assert c.get("/").status_code == 200
        assert c.get("/", headers={"host": "evil.example:8765"}).status_code == 403
        host = {"host": "127.0.0.1:8765"}
        assert refused(c, "/ws", {**host, "origin": "http://evil.example"}) == 1008
        with c.websocket_connect("/ws", headers={**host, "origin": "http://127.0.0.1:8765"}) as ws:
            assert Page(ws).join()[1]["full"]


def test_diagrams_are_served_annotated_and_unknown_ones_are_404(client: TestClient) -> None:
    svg = client.get("/api/diagram/Control?view=overview&open=start_stop").text
    assert 'data-state="Control.start_stop.wait_1"' in svg and 'data-subchart="Erase"' in svg
    assert client.get("/api/diagram/Nothing").status_code == 404
    assert "no sub-chart 'Nope'" in client.get("/api/diagram/Control?open=Nope").text
    assert client.get("/api/diagram/DriveInit2?view=overview").status_code == 200  # its one picture


def test_the_timeline_of_a_chart_is_the_debuggers(client: TestClient, session: Session) -> None:
    with client.websocket_connect("/ws") as ws:
        page = Page(ws)
        page.join()
        page.answer(page.send(type="step", n=4000))
        page.send(type="timeline", chart="DriveInit1", seconds=20)
        while (m := ws.receive_json())["type"] != "timeline":
            pass
    window = session.call(lambda d: d.timeline("DriveInit1", 20))
    shown = {(row["state"], a, b) for row in m["rows"] for a, b in row["intervals"]}
    assert shown == {(iv.state, max(iv.entered, window.first), iv.left) for iv in window.intervals}
    assert ("turn_fwd", 1, None) in shown or any(s == "turn_back" for s, _, _ in shown)
    assert next(r for r in m["rows"] if r["state"] == "run")["qname"] == "DriveInit1.run"


# -- frames: throttled, never one per tick --------------------------------------------------------------


class _TimedSession(Session):
    """A Session that notes when each frame is published (its one place that sends frames)."""

    published: list[float]

    def publish(self) -> None:
        self.published.append(time.perf_counter())
        super().publish()


def test_frames_are_throttled_and_carry_every_transition_since_the_last() -> None:
    session = _TimedSession(Debugger.build(load_params(), seed=0), speed=None, running=False)
    session.published = []
    frames: list[dict[str, Any]] = []
    cid = session.pages.connect(lambda text: frames.append(json.loads(text)))
    session.start()
    try:
        session.submit(cid, parse_command('{"type": "hello"}'))
        first = session.call(lambda d: len(d.trace.records))
        session.submit(cid, parse_command('{"type": "run"}'))
        # as fast as it goes until the three drives are initialised: thousands of chart ticks
        while not session.call(lambda d: d.robot.initialised):
            time.sleep(0.05)
        session.submit(cid, parse_command('{"type": "pause"}'))
        steps, ticks, active, records = session.call(lambda d: (
            d.robot.steps, d.robot.chart_ticks,
            {n: sorted(c.configuration_values) for n, c in d.robot.charts.items()}, list(d.trace.records)[first:]))
        while not [f for f in frames if f["type"] == "frame" and f["steps"] == steps and f["mode"] == "paused"]:
            time.sleep(0.05)  # the frame of the pause
    finally:
        session.stop()
    gaps = [b - a for a, b in zip(session.published, session.published[1:], strict=False)]
    assert len(gaps) >= 3 and min(gaps) >= session.frame_period * 0.999  # at most 30 frames a second
    live = [f for f in frames if f["type"] == "frame" and not f["full"]]
    assert ticks > 10 * len(live)  # never a frame per tick
    assert all(f["transitions_total"] == len(f["transitions"]) for f in live)  # none left out
    seen = [(t["chart"], t["source"], t["target"], t["tick"]) for f in live for t in f["transitions"]]
    assert seen == [(r.chart, r.source, r.target, r.tick) for r in records] and len(seen) >= 10
    assert live[-1]["active"] == active  # the latest state


def test_a_game_session_shows_the_game_charts_too() -> None:
    game = Session(Debugger.build(load_params(), seed=0, game=True), speed=None, running=False)
    game.start()
    try:
        with TestClient(create_app(game, manage_session=False)) as c, c.websocket_connect("/ws") as ws:
            page = Page(ws)
            info, full = page.join()
            assert {"Game", "AlgorithmActivator", "Control", "DriveInit1"} <= {ch["name"] for ch in info["charts"]}
            assert full["active"]["Game"] == game.call(lambda d: sorted(d.robot.charts["Game"].configuration_values))
            assert 'data-state="Game.' in c.get("/api/diagram/Game?view=whole").text
            assert page.answer(page.send(type="tick", n=3))["ok"]
    finally:
        game.stop()


def test_the_robots_objects_are_kept_out_of_the_collectors_passes_while_a_session_runs() -> None:
    import gc

    s = Session(Debugger.build(load_params(), seed=0), speed=None, running=False)
    s.start()
    try:
        frozen = s.call(lambda d: gc.get_freeze_count())
        assert frozen > 50_000  # the robot's objects: not scanned by every full collection (a 0.3 s stall)
    finally:
        s.stop()
    assert gc.get_freeze_count() == 0


def test_the_slider_keeps_the_inputs_given_after_its_tick_unless_told_to_drop_them(client: Any) -> None:
    """As ``replay`` and ``replay --drop`` in ttt-sm debug: going back does not lose the future you gave."""
    with client.websocket_connect("/ws") as ws:
        page = Page(ws)
        page.join()
        assert page.answer(page.send(type="tick", n=3))["ok"]
        assert page.answer(page.send(type="set", chart="DriveInit1", name="stop", value=False))["ok"]
        assert page.answer(page.send(type="tick", n=2))["ok"]
        kept = page.answer(page.send(type="replay", tick=1))
        # (the module's session: an earlier test may have given inputs too)
        assert kept["ok"] and re.search(r"\d+ later ones? kept", kept["text"]) and "dropped" not in kept["text"], kept
        dropped = page.answer(page.send(type="replay", tick=1, drop=True))
        assert dropped["ok"] and re.search(r"\d+ later ones? dropped", dropped["text"]), dropped
        assert "kept" not in dropped["text"], dropped
