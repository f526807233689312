"""The Tic-tac-toe page (``/game``, thesis section 3.7, fig. 3.35) over the session's game.

The page is a view of the same :class:`~.session.Session` as the chart cockpit:
its buttons are commands (``game_symbol``, ``game_cell``, ``game_play``,
``game_stop``, ``game_engine``, ``game_new``; Run is the session's ``run``),
declared and handled in :mod:`.commands.game`, in the simulation thread between
two control steps, and what it draws comes in each frame's ``game`` part
(:func:`game_view`), sent when it changed.

A click on a cell is the person's move: the simulated hand draws the person's
symbol on the simulated whiteboard (:meth:`GameSession.person_draws`); Play
(:meth:`GameSession.press_play`) lets the game's flow take a photo, read the
move through percent-process and pull the AlgorithmActivator's trigger, as
``ttt-sm play`` does.  Nothing here sets the board the robot believes.

The camera's picture is served as PNG at ``/api/game/photo.png``
(:func:`photo_png`); the frame says how many photos have been taken, and the
page asks for the picture again when that number changes.
"""

from __future__ import annotations

from typing import Any

import cv2

from ..app.game import GameSession
from ..app.game_outcome import outcome_in_words, winning_cells
from ..app.person import RemotePerson
from ..charts.game import (
    MSG_COMPILING,
    MSG_DRAWING,
    MSG_ERASING,
    MSG_INITIALISING,
    MSG_TURNING_OFF,
    MSG_YOUR_TURN,
    RESULT_MESSAGES,
)
from ..debug.debugger import Debugger

#: Person messages a frame carries at most (the newest).
MESSAGES_SHOWN = 8

#: Text box2's messages (the Game chart's): the page shows them there, not among what the game told.
CHART_MESSAGES = frozenset((MSG_COMPILING, MSG_INITIALISING, MSG_YOUR_TURN, MSG_DRAWING, MSG_ERASING,
                            MSG_TURNING_OFF, *RESULT_MESSAGES.values()))

#: The engines the page offers, by the name the game knows them by.
ENGINES = {"strong": "strong engine (an opening book and an exact search: it never loses)",
           "thesis": "thesis' engine (section 3.6.2: three-ply minimax)"}

TEXT_BOX1_FREE = "You can change the manipulator's symbol: it plays {robot}, you play {person}."
TEXT_BOX1_LOCKED = "The manipulator plays {robot}, you play {person}: the symbol cannot change after the first move."


def game_of_debugger(debugger: Debugger) -> GameSession | None:
    """The game the session's robot plays, or None (a session without ``--game``)."""
    return debugger.game


def not_started(game: GameSession) -> bool:
    """Whether the Game chart still waits at power-on (its first message): Run has not started the robot."""
    return str(game.game.message) == MSG_COMPILING


def game_view(debugger: Debugger) -> dict[str, Any] | None:
    """The ``game`` part of a frame: what the Tic-tac-toe page shows, plain data (None: no game)."""
    game = game_of_debugger(debugger)
    if game is None:
        return None
    robot, person = game.robot_symbol, game.person_symbol
    driver = game.driver
    view = game.last_view
    told: list[str] = []
    told_total = 0
    if isinstance(game.person, RemotePerson):
        told = [m for m in game.person.messages if m not in CHART_MESSAGES][-MESSAGES_SHOWN:]
        told_total = game.person.told
    return {
        "message": str(game.game.message),
        "robot_symbol": robot,
        "person_symbol": person,
        "symbol_locked": game.symbol_locked,
        "text_box1": (TEXT_BOX1_LOCKED if game.symbol_locked else TEXT_BOX1_FREE).format(robot=robot, person=person),
        "plays_here": game.remote,
        "awaiting": game.awaiting,
        "board": game.board,
        "truth": game.truth,
        "drawn": [list(c) for c in game.drawn],
        "moves": len(game.moves),
        "percentages": None if view is None else [round(float(p), 1) for p in view[0]],
        "read": None if view is None else view[1],
        "photos": game.photos,
        "outcome": game.outcome,
        "result": None if game.outcome is None else outcome_in_words(game.outcome, robot, person),
        # the four in a row the game ended on (the board the game believes), marked on the page's board
        "winning_line": winning_cells(game.board) if game.outcome in (robot, person) else None,
        "ended": bool(game.game.ended),
        "error": None if driver is None or driver.error is None else str(driver.error),
        "told": told,
        "told_total": told_total,  # all told, Text box2's messages too
        "engine": game.engine_name,
        "engine_locked": game.symbol_locked,
        "record": None if game.record.path is None else str(game.record.path),
        "record_ended": game.record.ended,
        "can_start_over": bool(game.game.ended or (driver is not None and driver.error is not None)),
    }


def photo_png(debugger: Debugger) -> bytes | None:
    """The camera's last photo as PNG, or None before the first (or without a game)."""
    game = game_of_debugger(debugger)
    photo = None if game is None else game.camera.last_photo
    if photo is None:
        return None
    ok, data = cv2.imencode(".png", photo)
    if not ok:
        raise RuntimeError("OpenCV could not encode the camera's photo as PNG")
    return bytes(data)
