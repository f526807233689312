"""The Tic-tac-toe page's commands (``/game``, :mod:`..game`): the thesis' Symbol, Play, Stop, a cell clicked.

Each is the person's input to the game, recorded by the debugger
(``Debugger.game_input``), so a replay plays it again; the game, not the page,
decides whether it is taken (a click when it is not the person's turn gets the
game's words back as the error).
"""

from __future__ import annotations

from dataclasses import replace

from ...app.game import GameSession
from ...debug.debugger import Debugger
from ...debug.replay import GameRecipe
from ..fields import integer, one_of
from ..game import ENGINES, game_of_debugger, not_started
from .spec import Cockpit, Reply, command


def _game(debugger: Debugger, command: str) -> GameSession:
    game = game_of_debugger(debugger)
    if game is None:
        raise ValueError(f"{command}: this session plays no game (start it with `ttt-sm gui --game`)")
    if not game.remote:
        raise ValueError(f"{command}: a simulated person plays this game; start `ttt-sm gui --game`"
                         " with --person page to play it in the page")
    return game


@command("game_symbol", symbol=one_of("X", "O"))
def symbol(session: Cockpit, cid: int, symbol: str) -> Reply:
    """Symbol: the manipulator plays ``symbol``, ``"X"`` or ``"O"`` (before the first move only)."""
    debugger = session.debugger
    game = _game(debugger, "game_symbol")
    debugger.game_input("symbol", symbol=symbol)
    return {"text": f"the manipulator plays {game.robot_symbol}, you play {game.person_symbol}"}


@command("game_cell", row=integer(1, 5), column=integer(1, 5))
def cell(session: Cockpit, cid: int, row: int, column: int) -> Reply:
    """A click on a cell (``row``, ``column``: 1..5): the simulated hand draws the person's symbol there."""
    debugger = session.debugger
    game = _game(debugger, "game_cell")
    debugger.game_input("cell", row=row, column=column)
    return {"text": f"you drew {game.person_symbol} in row {row}, column {column}; click Play when you are done"}


@command("game_play")
def play(session: Cockpit, cid: int) -> Reply:
    """Play: the manipulator's move (the AlgorithmActivator's trigger, pulled by the game's flow)."""
    debugger = session.debugger
    game = _game(debugger, "game_play")
    debugger.game_input("play")
    return {"text": "Play: the camera looks at the board" if game.awaiting == "draw" else "Play: the manipulator moves"}


@command("game_stop")
def stop(session: Cockpit, cid: int) -> Reply:
    """Stop (the thesis' Stop_sim): the Game chart turns the arm off; it returns to its start pose, then stops."""
    debugger = session.debugger
    game = _game(debugger, "game_stop")
    if game.game.ended:
        raise ValueError("game_stop: the game is over and the arm off already")
    if session.mode != "running" and not_started(game):
        # Not started: a stop posted now would wait for Run and turn the arm off at once (a game of no moves).
        raise ValueError("game_stop: the robot has not been started, so there is nothing to stop;"
                         " click Run to start the game")
    debugger.post(game.game.chart_name, "stop")
    text = "Stop: the manipulator returns to its start pose avoiding the board, then stops"
    if session.mode != "running":
        text += " (the session is paused: it does so once it runs)"
    return {"text": text}


@command("game_engine", engine=one_of(*ENGINES))
def engine(session: Cockpit, cid: int, engine: str) -> Reply:
    """The engine: the manipulator's game algorithm, ``"strong"`` or ``"thesis"`` (before the first move only)."""
    debugger = session.debugger
    _game(debugger, "game_engine")
    debugger.game_input("engine", engine=engine)
    return {"text": f"the manipulator plays with the {ENGINES[engine]}"}


@command("game_new")
def new_game(session: Cockpit, cid: int) -> Reply:
    """A new game: a new robot from power-on (the thesis' Run_sim again), paused, the symbol and engine kept.

    Only once this game is over (its result and the arm turned off, or Stop)
    or cannot go on; the new game's record goes beside the last one
    (``game-<n+1>``).  The pages' views start over; Run starts the robot.
    """
    debugger = session.debugger
    game = _game(debugger, "game_new")
    recipe = debugger.recipe
    if not isinstance(recipe, GameRecipe):
        raise ValueError("game_new: this session's robot was not built for a game")
    driver = game.driver
    if not (game.game.ended or (driver is not None and driver.error is not None)):
        raise ValueError("game_new: this game is still on: click Stop first (or play it to its end)")
    with session.robot_replaced(replaying=False):
        debugger.start_over(replace(recipe, robot_symbol=game.robot_symbol, engine=game.engine_name,
                                    number=recipe.number + 1))
    session.mode = "paused"
    session.last_stop = None
    return {"text": f"a new game (game {recipe.number + 1}): the robot is powered on; click Run"}
