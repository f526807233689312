"""The debugger over a whole game: Game and AlgorithmActivator charts, the simulated person, the camera.

One game (seed 0) is stepped by the debugger to the robot's first turn;
each test starts there: a test that runs the game on leaves it elsewhere, and
the next replays it back (test workers may run the module's tests in any
order).
"""

from __future__ import annotations

import re

import pytest

from ttt_sm.app.game import GameSession
from ttt_sm.app.game_stages import Wait
from ttt_sm.charts.game import MSG_DRAWING
from ttt_sm.debug import Debugger
from ttt_sm.debug.replay import differences
from ttt_sm.debug.shell import DebugShell


@pytest.fixture(scope="module")
def first_turn(params):
    """A game in the debugger, stopped where the robot's first turn begins (Game enters drawing)."""
    dbg = Debugger.build(params, seed=0, game=True)
    dbg.add_breakpoint("enter Game.drawing")
    stop = dbg.run(150.0)
    assert dbg.game is not None
    return dbg, stop, dbg.fingerprint(), [dict(m) for m in dbg.game.moves]


@pytest.fixture
def at_first_turn(first_turn):
    """The module's game, replayed back to the robot's first turn if a test ran it on."""
    dbg, stop = first_turn[:2]
    if dbg.robot.chart_ticks != stop.chart_ticks:
        assert dbg.replay(stop.chart_ticks).identical
    return first_turn


def test_a_breakpoint_on_the_game_chart_stops_at_the_robots_turn(at_first_turn):
    dbg, stop, _, moves = at_first_turn
    assert stop.kind == "breakpoint" and stop.breakpoint is not None
    assert stop.breakpoint.spec == "enter Game.drawing" and stop.breakpoint.chart == "Game"
    where = dbg.where()
    assert where["Game"] == ["playing", "drawing"]
    assert dbg.robot.value("Game", "message") == MSG_DRAWING
    assert where["AlgorithmActivator"] == ["spent"] and dbg.robot.value("AlgorithmActivator", "activations") == 1
    assert "Drawing_O" in where["Control"]  # the robot plays O: the Control chart draws it now
    # the simulated person drew first, and the camera saw the very cell
    assert [m["by"] for m in moves] == ["person"]
    assert moves[0]["detected"] == [moves[0]["row"], moves[0]["column"]]
    assert dbg.game.pending_move is not None and dbg.game.camera.mode == "direct"


def test_the_shell_shows_the_game_and_the_game_charts_timeline(at_first_turn, capsys):
    dbg = at_first_turn[0]
    shell = DebugShell(dbg)
    shell.run_script(["where", "show game", "show timeline Game", "show data Game --diff"])
    out = capsys.readouterr().out
    assert shell.errors == 0, out
    assert "  game                robot O vs person X, 1 move; waiting for" in out
    row, column = dbg.game.moves[0]["row"], dbg.game.moves[0]["column"]
    assert f"move: person X in ({row}, {column}) at t = " in out
    assert "your_turn" in out and "drawing  " in out
    assert re.search(r"input +busy +False -> True", out)


def test_continue_plays_on_to_the_robots_next_turn(at_first_turn):
    dbg, stop, _, _ = at_first_turn
    again = dbg.run(60.0)
    assert again.kind == "breakpoint" and again.chart_ticks > stop.chart_ticks
    game = dbg.game
    assert [m["by"] for m in game.moves] == ["person", "robot", "person"]
    robot_move = game.moves[1]
    # the robot's first move is on the whiteboard, and in the board the game believes
    cell = 5 * (robot_move["row"] - 1) + robot_move["column"] - 1
    assert game.board[cell] == "O" and game.truth[cell] == "O"
    assert dbg.robot.value("AlgorithmActivator", "activations") == 2
    # the Game chart went your_turn -> drawing -> your_turn -> drawing
    window = dbg.timeline("Game")
    inner = [iv.state for iv in window.intervals if iv.state in ("your_turn", "drawing")]
    assert inner == ["your_turn", "drawing", "your_turn", "drawing"]


def test_replay_to_a_tick_in_the_game_reproduces_the_same_data(first_turn):
    dbg, stop, seen, moves = first_turn
    result = dbg.replay(stop.chart_ticks)
    assert result.identical is True, result.differences
    now = dbg.fingerprint()
    assert list(differences(seen, now)) == []
    assert now["game"]["moves"] == moves and now["charts"]["Game"]["active"] == ["drawing", "playing"]


def test_the_debugged_game_is_the_game_play_plays(at_first_turn, params):
    """GameSession.play runs the same flow with Robot.run_until: move for move, at the same times."""
    dbg = at_first_turn[0]
    dbg.run(60.0)  # on to the robot's second turn
    driven = dbg.game
    played = GameSession(params, seed=0, camera="direct", record_trace=False)
    played.record_start(25)  # the record's first line, as play() and drive() write it
    for wait in played.flow():
        played._run(wait)
        if len(played.moves) == len(driven.moves):
            break
    assert played.moves == driven.moves
    assert played.board == driven.board and played.o_pos == driven.o_pos
    def events(session: GameSession) -> list[dict]:  # think_ms is the engine's wall time
        return [{k: v for k, v in e.items() if k != "think_ms"} for e in session.record.events]

    assert events(played) == events(driven)


def test_a_game_that_cannot_go_on_stops_the_debugger_with_its_reason(params):
    session = GameSession(params, seed=0, camera="direct", record_trace=False)

    def stuck(max_moves: int = 25):
        yield Wait(lambda: False, 0.01, "a person who never comes")

    session.flow = stuck  # type: ignore[method-assign]
    session.drive()
    dbg = Debugger(session.robot)
    stop = dbg.run(1.0)
    assert stop.kind == "game"
    assert stop.detail.startswith("a person who never comes did not happen within 0 s of simulated time")
    assert stop.chart_ticks == 6  # the flow starts in tick 1 and gives up after 5 chart steps (10 ms)
    assert "the game stopped at t = " in stop.describe()
    assert dbg.run(0.1).kind == "timeout"  # reported once; the charts run on
