"""Why a game stops before its end: an error of the game itself, or a stop from outside."""

from __future__ import annotations


class GameError(RuntimeError):
    """The game cannot go on (a chart did not finish its job in time, the camera went silent)."""


class GameInterrupted(Exception):
    """The game was stopped from outside (:meth:`.game.GameSession.interrupt`: Ctrl-C, SIGTERM); ``why`` says how."""

    def __init__(self, why: str) -> None:
        super().__init__(f"interrupted ({why})")
        self.why = why

