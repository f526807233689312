"""The Tic-tac-toe page's commands over the WebSocket, without a browser: checks and refusals."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from starlette.testclient import TestClient

from ttt_sm.app.game_record import read_record
from ttt_sm.debug.debugger import Debugger
from ttt_sm.params import load_params
from ttt_sm.web.protocol import ProtocolError, parse_command
from ttt_sm.web.server import create_app
from ttt_sm.web.session import Session

from .test_protocol import Page


@pytest.mark.parametrize(("message", "error"), [
    ('{"type": "game_cell", "row": 6, "column": 1}', "game_cell: 'row' must be a whole number from 1 to 5, got 6"),
    ('{"type": "game_cell", "row": 1}', "game_cell: missing field 'column'"),
    ('{"type": "game_symbol", "symbol": "Z"}', "game_symbol: 'symbol' must be \"X\" or \"O\", got \"Z\""),
    ('{"type": "game_play", "cell": 3}', "game_play: unknown field 'cell'; fields: none"),
])
def test_a_malformed_game_command_is_refused_by_name(message: str, error: str) -> None:
    with pytest.raises(ProtocolError) as exc:
        parse_command(message)
    assert str(exc.value) == error


def test_the_game_page_on_a_session_without_a_game_says_how_to_start_one() -> None:
    session = Session(Debugger.build(load_params(), seed=0), speed=None, running=False)
    session.start()
    try:
        with TestClient(create_app(session, manage_session=False)) as c, c.websocket_connect("/ws") as ws:
            assert 'aria-label="Symbol"' in c.get("/game").text
            assert c.get("/api/game/photo.png").status_code == 404
            page = Page(ws)
            _, full = page.join()
            assert full["game"] is None
            answer = page.answer(page.send(type="game_play"))
            assert answer["type"] == "error"
            assert answer["error"] == "game_play: this session plays no game (start it with `ttt-sm gui --game`)"
    finally:
        session.stop()


def test_before_power_on_moves_the_game_refuses_a_cell_and_a_play_with_where_it_stands() -> None:
    session = Session(Debugger.build(load_params(), seed=0, game=True, person="page"), speed=None, running=False)
    session.start()
    try:
        with TestClient(create_app(session, manage_session=False)) as c, c.websocket_connect("/ws") as ws:
            page = Page(ws)
            _, full = page.join()
            assert full["game"]["message"] == "Wait for the model to be compiled."
            assert full["game"]["symbol_locked"] is False and full["game"]["plays_here"] is True
            cell = page.answer(page.send(type="game_cell", row=2, column=3))
            assert cell["type"] == "error"
            assert cell["error"] == "game_cell: it is not your turn to draw: Wait for the model to be compiled."
            assert session.call(lambda d: d.robot.board.ink_area_mm2()) == 0.0  # the hand drew nothing
            play = page.answer(page.send(type="game_play"))
            assert play["error"] == "game_play: Play is not taken now: Wait for the model to be compiled."
            symbol = page.answer(page.send(type="game_symbol", symbol="X"))
            assert symbol["ok"] and symbol["text"] == "the manipulator plays X, you play O"
            assert session.call(lambda d: (d.game.robot_symbol, d.game.person_symbol)) == ("X", "O")
    finally:
        session.stop()


def run_until(session: Session, what: Any, limit_s: float = 300.0) -> None:
    """Run the paused session in the simulation thread, chart tick by tick, until ``what(debugger)`` holds."""
    def go(d: Debugger) -> None:
        t_end = d.robot.t + limit_s
        while not what(d):
            assert d.robot.t < t_end, "the game did not get there in time"
            d.tick(1)
    session.call(go, timeout_s=900)


def test_a_replay_to_an_earlier_tick_repeats_the_persons_clicks(tmp_path: Path) -> None:
    """The person's clicks are inputs from outside the simulation: recorded with their step, replayed there."""
    dbg = Debugger.build(load_params(), seed=0, game=True, person="page", record_root=tmp_path / "gui")
    session = Session(dbg, speed=None, running=False)
    session.start()
    try:
        with TestClient(create_app(session, manage_session=False)) as c, c.websocket_connect("/ws") as ws:
            page = Page(ws)
            page.join()
            run_until(session, lambda d: d.game.awaiting == "draw")
            assert page.answer(page.send(type="game_engine", engine="thesis"))["ok"]
            assert page.answer(page.send(type="game_cell", row=3, column=3))["ok"]
            assert page.answer(page.send(type="game_play"))["ok"]
            # The manipulator answers: it has drawn its move and waits for the person again.
            run_until(session, lambda d: d.game.awaiting == "draw" and len(d.game.moves) == 2)

            def seen(d: Debugger) -> dict[str, Any]:
                g = d.game
                return {"tick": d.robot.chart_ticks, "moves": [dict(m) for m in g.moves], "truth": g.truth,
                        "board": g.board, "engine": g.engine_name, "ink": d.robot.board.ink_area_mm2(),
                        "actions": [a.describe() for a in d.actions]}

            before = session.call(seen)
            assert before["moves"][0]["by"] == "person" and before["moves"][0]["detected"] == [3, 3]
            assert before["engine"] == "thesis"
            assert [a.split(": ", 1)[1] for a in before["actions"]] == [
                "the person's engine engine=thesis", "the person's cell row=3 column=3", "the person's play"]
            # Back to the person's turn at power-on + some, then forward again to the same tick.
            answer = page.answer(page.send(type="replay", tick=before["tick"]))
            assert answer["ok"], answer
            assert "3 recorded inputs re-applied" in answer["text"]
            assert answer["identical"] is True, answer["text"]
            after = session.call(seen)
            assert after == before
            # The record written as the game goes was written again by the replayed game: the same events.
            lines = read_record(tmp_path / "gui" / "game-1" / "game.jsonl")
            events = [e["event"] for e in lines if e["event"] != "transition"]
            assert events[0] == "game" and events.count("person_drew") == 1 and events.count("robot_move") == 1
    finally:
        session.stop()


def test_engine_and_new_game_are_refused_while_the_game_is_on_and_taken_after_stop(tmp_path: Path) -> None:
    dbg = Debugger.build(load_params(), seed=0, game=True, person="page", record_root=tmp_path / "gui")
    session = Session(dbg, speed=None, running=False)
    session.start()
    try:
        with TestClient(create_app(session, manage_session=False)) as c, c.websocket_connect("/ws") as ws:
            page = Page(ws)
            page.join()
            new = page.answer(page.send(type="game_new"))
            assert new["error"] == "game_new: this game is still on: click Stop first (or play it to its end)"
            run_until(session, lambda d: d.game.awaiting == "draw")
            assert page.answer(page.send(type="game_cell", row=1, column=1))["ok"]
            engine = page.answer(page.send(type="game_engine", engine="thesis"))
            assert engine["error"] == ("game_engine: the manipulator plays with the strong engine: the engine"
                                       " cannot change after the first move")
            assert page.answer(page.send(type="game_stop"))["ok"]
            run_until(session, lambda d: d.game.driver.done)  # turned off, the flow at its end
            record = tmp_path / "gui" / "game-1" / "game.jsonl"
            lines = read_record(record)
            assert lines[-1]["event"] == "finished" and lines[-1]["outcome"] == "halted"
            new = page.answer(page.send(type="game_new"))
            assert new["ok"] and new["text"].startswith("a new game (game 2)")
            frame = page.frame()
            while not frame["full"]:
                frame = page.frame()
            assert frame["t"] == 0.0 and frame["mode"] == "paused"
            assert frame["game"]["message"] == "Wait for the model to be compiled." and frame["game"]["moves"] == 0
            assert frame["game"]["record"] == str(tmp_path / "gui" / "game-2" / "game.jsonl")
            assert session.call(lambda d: (d.actions, d.furthest_tick, d.robot.board.ink_area_mm2())) == ([], 0, 0.0)
            assert read_record(record)[-1]["event"] == "finished"  # the first game's record is left as it ended
    finally:
        session.stop()
