"""The Operational page's commands over the WebSocket, without a browser: checks, refusals, the stream."""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

import pytest
from starlette.testclient import TestClient

from ttt_sm.app.precision import run_staircase
from ttt_sm.debug.debugger import Debugger
from ttt_sm.params import load_params
from ttt_sm.web.operate import (
    COLUMNS,
    MSG_DRAWING,
    MSG_INITIALISING,
    MSG_READY,
    MSG_STAIRCASE,
    SAMPLE_PERIOD_S,
    speed_mm_s,
)
from ttt_sm.web.protocol import ProtocolError, parse_command
from ttt_sm.web.server import create_app
from ttt_sm.web.session import Session

from .test_protocol import Page, state_of


@pytest.mark.parametrize(("message", "error"), [
    ('{"type": "operate_trigger", "symbol": "O", "magnitude_cm": 12, "speed": 3}',
     "operate_trigger: 'magnitude_cm' must be a number from 0 to 10, got 12"),
    ('{"type": "operate_trigger", "symbol": "O", "magnitude_cm": -0.5, "speed": 3}',
     "operate_trigger: 'magnitude_cm' must be a number from 0 to 10, got -0.5"),
    ('{"type": "operate_trigger", "symbol": "O", "magnitude_cm": 6, "speed": 5.5}',
     "operate_trigger: 'speed' must be a number from 0 to 5, got 5.5"),
    ('{"type": "operate_trigger", "symbol": "O", "magnitude_cm": "6", "speed": 3}',
     "operate_trigger: 'magnitude_cm' must be a number from 0 to 10, got \"6\""),
    ('{"type": "operate_trigger", "symbol": "square", "magnitude_cm": 6, "speed": 3}',
     "operate_trigger: 'symbol' must be \"X\", \"O\", \"sine\" or \"staircase\", got \"square\""),
    ('{"type": "operate_trigger", "symbol": "staircase", "magnitude_cm": 0, "speed": 0, "axis": "w"}',
     "operate_trigger: 'axis' must be \"x\", \"y\" or \"z\", got \"w\""),
    ('{"type": "operate_trigger", "symbol": "staircase", "magnitude_cm": 0, "speed": 0, "steps": "huge"}',
     "operate_trigger: 'steps' must be \"small\" or \"big\", got \"huge\""),
    ('{"type": "operate_trigger", "symbol": "O", "speed": 3}', "operate_trigger: missing field 'magnitude_cm'"),
    ('{"type": "operate_stop", "now": true}', "operate_stop: unknown field 'now'; fields: none"),
])
def test_a_malformed_operate_command_is_refused_by_name(message: str, error: str) -> None:
    with pytest.raises(ProtocolError) as exc:
        parse_command(message)
    assert str(exc.value) == error


def test_the_speed_slider_maps_linearly_from_5_to_30_mm_s() -> None:
    assert [speed_mm_s(s) for s in (0, 1, 3, 5)] == [5.0, 10.0, 20.0, 30.0]


@contextmanager
def _operating() -> Iterator[tuple[Session, Any, Page, dict[str, Any]]]:
    """A paused session at power-on, as fast as it goes, with one page joined over the test client.

    Also the full frame the page got when it joined.
    """
    session = Session(Debugger.build(load_params(), seed=0), speed=None, running=False)
    session.start()
    try:
        with TestClient(create_app(session, manage_session=False)) as client, client.websocket_connect("/ws") as ws:
            page = Page(ws)
            _, full = page.join()
            yield session, client, page, full
    finally:
        session.stop()


@pytest.fixture(scope="module")
def operating() -> Iterator[tuple[Session, Any, Page, dict[str, Any]]]:
    """One session for the module's drawings (each test waits for the arm's waiting pose itself)."""
    with _operating() as it:
        yield it


@pytest.fixture
def at_power_on(operating: tuple[Session, Any, Page, dict[str, Any]]
                ) -> Iterator[tuple[Session, Any, Page, dict[str, Any]]]:
    """The module's session while it has not run yet; otherwise one of its own (test workers may run the
    module's tests on different sessions, in any order)."""
    if operating[0].call(lambda d: d.robot.t) == 0.0:
        yield operating
        return
    with _operating() as it:
        yield it


def test_before_the_arm_waits_trigger_is_refused_and_says_why(
        at_power_on: tuple[Session, Any, Page, dict[str, Any]]) -> None:
    session, client, page, full = at_power_on
    assert '<label for="magnitude">Magnitude</label>' in client.get("/operate").text
    op = full["operate"]
    assert op["status"] == MSG_INITIALISING
    assert op["trigger"] is False and "not at its waiting pose yet" in op["why"]
    assert full["plot"]["columns"] == list(COLUMNS) and full["plot"]["reset"] is True
    before = state_of(session)
    answer = page.answer(page.send(type="operate_trigger", symbol="O", magnitude_cm=6, speed=3))
    assert answer["type"] == "error"
    assert answer["error"].startswith("operate_trigger: Trigger is not taken now: the manipulator is not at its"
                                      " waiting pose yet")
    assert state_of(session) == before  # nothing was set, nothing posted
    page.send(type="operate_trigger", symbol="O", magnitude_cm=10.5, speed=3)
    bad = page.answer()  # refused before it is a command: no id
    assert bad["error"] == "operate_trigger: 'magnitude_cm' must be a number from 0 to 10, got 10.5"
    stop = page.answer(page.send(type="operate_stop"))
    assert stop["error"] == ("operate_stop: the manipulator has not been started: nothing to turn off"
                             " (Run_simulation first)")
    assert state_of(session) == before


def test_trigger_at_the_waiting_pose_draws_and_the_frames_carry_samples_in_simulated_time(
        operating: tuple[Session, Any, Page, dict[str, Any]]) -> None:
    session, client, _, _ = operating
    # the arm initialises, draws the field and waits at its waiting pose
    session.call(lambda d: d.robot.run_until(lambda: d.robot.control.ready, 200.0), timeout_s=300)
    # a page that joins now (frames carry the operate part only when it changed)
    with client.websocket_connect("/ws") as ws:
        page = Page(ws)
        _, full = page.join()
        _draw_an_x(session, page, full["operate"])


def _draw_an_x(session: Session, page: Page, op: dict[str, Any]) -> None:
    assert op["status"] == MSG_READY
    assert op["trigger"] is True and op["why"] == ""
    drawn = op["drawings"]  # by the module's other tests, if they ran first
    dot = page.answer(page.send(type="operate_trigger", symbol="X", magnitude_cm=0.2, speed=3))
    assert dot["error"] == ("operate_trigger: an X of 0.2 cm is a dot: choose a Magnitude of 0.4 cm or more")
    ok = page.answer(page.send(type="operate_trigger", symbol="X", magnitude_cm=2.5, speed=4))
    assert ok["type"] == "reply" and ok["text"] == "Trigger: an X, 2.5 cm side, speed 4 (25 mm/s)"
    control = session.call(lambda d: (d.robot.control.size, d.robot.control.speed, d.robot.control.symbol))
    assert control == (pytest.approx(0.025), pytest.approx(0.025), 1)
    again = page.answer(page.send(type="operate_trigger", symbol="X", magnitude_cm=2.5, speed=4))
    assert again["error"] == ("operate_trigger: Trigger is not taken now: the manipulator is drawing: Trigger"
                              " again when it waits at its waiting pose")
    page.send(type="run")
    rows: list[list[Any]] = []
    statuses = set()
    while True:
        f = page.frame()
        rows += f.get("plot", {}).get("rows", [])
        if "operate" in f:
            statuses.add(f["operate"]["status"])
            if f["operate"]["drawings"] == drawn + 1:
                break
    page.send(type="pause")
    result = f["operate"]["precision"]
    assert result["symbol"] == "X" and result["speed_mm_s"] == 25.0
    assert 0 < result["rms_error_mm"] < 0.5 and result["closure_gap_mm"] is None
    assert statuses >= {MSG_DRAWING, MSG_READY}
    # the samples: 25 a simulated second, in order, each row every column
    t = [r[0] for r in rows]
    assert all(len(r) == len(COLUMNS) for r in rows)
    assert all(math.isclose(b - a, SAMPLE_PERIOD_S, abs_tol=1e-6) for a, b in zip(t, t[1:], strict=False))
    assert len(rows) >= 10 * (t[-1] - t[0])
    # while the X is drawn the desired pen is on the board and the encoders' forward kinematics follows it
    down = [r for r in rows if r[5] is not None and r[5] < 0]
    assert down and max(abs(r[1] - r[2]) for r in down) < 2.0


def test_the_sine_waves_magnitude_is_its_peak_to_peak_on_the_whiteboard(
        operating: tuple[Session, Any, Page, dict[str, Any]]) -> None:
    session, _, page, _ = operating
    session.call(lambda d: d.robot.run_until(lambda: d.robot.control.ready, 200.0), timeout_s=300)
    strokes_before = session.call(lambda d: len(d.robot.board.strokes))
    ok = page.answer(page.send(type="operate_trigger", symbol="sine", magnitude_cm=4, speed=5))
    assert ok["text"] == "Trigger: a sine wave, 4 cm peak to peak, speed 5 (30 mm/s)"
    assert session.call(lambda d: d.robot.control.sine_amplitude) == pytest.approx(0.02)
    done = session.call(lambda d: d.robot.run_until(lambda: bool(session.operate.results)
                                                    and session.operate.results[-1]["symbol"] == "sine", 200.0),
                        timeout_s=300)
    assert done
    ink = session.call(lambda d: [s.points for s in d.robot.board.strokes[strokes_before:] if s.author == "robot"])
    y = [p[1] for points in ink for p in points]
    assert abs((max(y) - min(y)) - 0.040) < 0.001  # the pen's centre line: 40 mm from crest to trough
    result = session.call(lambda d: session.operate.results[-1])
    assert result["speed_mm_s"] == 30.0 and result["closure_gap_mm"] is None and result["rms_error_mm"] < 0.5


@pytest.fixture
def fresh() -> Iterator[tuple[Session, Any, Page, dict[str, Any]]]:
    """A session of its own, from power-on: what the arm drew before decides which side of the gears' clearance
    it rests on, and the module's session has drawn whatever the tests that ran on it asked."""
    with _operating() as it:
        yield it


def test_the_staircase_plays_from_the_waiting_pose_and_back_and_is_measured_as_the_cli_measures_it(
        fresh: tuple[Session, Any, Page, dict[str, Any]]) -> None:
    """Section 3.5's experiment on the Operational page: Trigger with "staircase" (issue: a Staircase choice).

    From power-on, as ``ttt-sm precision staircase`` runs it: the two are compared at rest, where the gears'
    clearance shows."""
    session, _, page, _ = fresh
    session.call(lambda d: d.robot.run_until(lambda: d.robot.control.ready, 200.0), timeout_s=300)
    wait_pose = session.call(lambda d: (d.robot.control.X_out, d.robot.control.Y_out, d.robot.control.Z_out))
    ok = page.answer(page.send(type="operate_trigger", symbol="staircase", magnitude_cm=0, speed=0, axis="x",
                               steps="big"))
    assert ok["text"].startswith("Trigger: the staircase of section 3.5 along X, 5 big stairs of 10 mm"), ok
    busy = page.answer(page.send(type="operate_trigger", symbol="O", magnitude_cm=3, speed=3))
    assert "the manipulator follows the staircase" in busy["error"]
    assert "follows the staircase" in page.answer(page.send(type="operate_stop"))["error"]
    assert session.call(lambda d: session.operate.view()["status"]) == MSG_STAIRCASE
    # the arm leaves its waiting pose for the staircase's start, 2.5 cm before the field (section 3.5)
    session.call(lambda d: d.run(1.5), timeout_s=300)  # the debugger's run: its history can be replayed
    x_tool = session.call(lambda d: d.robot.truth.tool_pose()[0])
    assert abs(x_tool - wait_pose[0]) > 0.005
    session.call(lambda d: d.run(16.0), timeout_s=300)  # the staircase takes 16.9 s of simulated time
    result = session.call(lambda d: session.operate.results[-1])
    assert result["axis"] == "x" and result["steps"] == "big" and result["thesis_figure"] == "3.18"
    s = result["summary"]
    assert s["desired_vs_sensor"]["max_static_mm"] <= 0.1  # the target with our tuning
    # each 10 mm stair is a slew: the tool lags it by far more than it misses at rest
    assert s["desired_vs_fk"]["max_dynamic_mm"] > 0.3 > 10 * s["desired_vs_fk"]["max_static_mm"]
    assert len(result["reading"]) >= 3
    cli = run_staircase(load_params(), "x", "big").summary  # ttt-sm precision staircase --axis x --steps big
    for comparison in ("desired_vs_fk", "desired_vs_sensor"):  # the lag alike; at rest the gears' clearance
        # may sit on its other side after the field was drawn: within the clearance bound (~0.1 mm) of the CLI's
        assert s[comparison]["max_dynamic_mm"] == pytest.approx(cli[comparison]["max_dynamic_mm"], rel=0.1)
        assert s[comparison]["max_static_mm"] == pytest.approx(cli[comparison]["max_static_mm"], abs=0.03)
    # back at the waiting pose, where Trigger is taken again
    tool = session.call(lambda d: d.robot.truth.tool_pose()[:3])
    assert max(abs(a - b) for a, b in zip(tool, wait_pose, strict=True)) < 0.001
    assert session.call(lambda d: session.operate.view()["trigger"]) is True
    # recorded: a replay from power-on plays the same staircase again, to the same state as the run stopped in
    replay = session.call(lambda d: d.replay_to_step(d.robot.steps), timeout_s=300)
    assert replay.identical is True, replay.differences
    assert "the staircase of section 3.5 along x, big steps" in session.call(
        lambda d: "; ".join(a.describe() for a in d.actions))


def test_drive_1_stops_where_it_is_and_is_released_back_into_the_state_it_left() -> None:
    """Thesis section 3.1.2: drive 1's ``stop`` input, from the cockpit and the Operational page (drive1_stop)."""
    with _operating() as (session, _, page, full):
        assert full["drive1"] == {"stop": False, "stopped": False}
        assert page.answer(page.send(type="tick", n=400))["ok"]  # drive 1 turns, searching its index
        before = session.call(lambda d: (sorted(d.robot.active("DriveInit1")), d.robot.arm.encoder_angles()[0]))
        assert before[0] == ["initialise", "run", "turn_fwd"], before
        stop = page.answer(page.send(type="drive1_stop", stop=True))
        assert stop["ok"] and stop["text"].startswith("Drive 1 stops where it is"), stop
        again = page.answer(page.send(type="drive1_stop", stop=True))
        assert again["error"] == "drive1_stop: drive 1 is stopped already"
        assert page.answer(page.send(type="tick", n=500))["ok"]  # one simulated second
        q1 = session.call(lambda d: d.robot.arm.encoder_angles()[0])
        assert session.call(lambda d: "stopped" in d.robot.active("DriveInit1"))
        assert abs(q1 - before[1]) < 0.02  # it turned at most a few encoder counts past where it was stopped
        frame = page.frame()
        while "drive1" not in frame:
            frame = page.frame()
        assert frame["drive1"] == {"stop": True, "stopped": True}
        assert "set DriveInit1.stop True" in " ".join(session.call(lambda d: [a.describe() for a in d.actions]))
        release = page.answer(page.send(type="drive1_stop", stop=False))
        assert release["ok"] and release["text"].startswith("Drive 1 released"), release
        assert page.answer(page.send(type="tick", n=400))["ok"]
        after = session.call(lambda d: (sorted(d.robot.active("DriveInit1")), d.robot.arm.encoder_angles()[0]))
        assert after[0] == before[0]  # back in turn_fwd through the history state
        assert abs(after[1] - q1) > 0.02  # and turning again
