"""The Tic-tac-toe page's commands over the WebSocket, without a browser: checks and refusals."""

from __future__ import annotations

import pytest
from starlette.testclient import TestClient

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
