"""How a game ends: its result read off the board, in words, or the error or interruption that stopped it."""

from __future__ import annotations

from ..game.rules import is_full, parse_board, winner, winning_line


class GameError(RuntimeError):
    """The game cannot go on (a chart did not finish its job in time, the camera went silent)."""


class GameInterrupted(Exception):
    """The game was stopped from outside (:meth:`.game.GameSession.interrupt`: Ctrl-C, SIGTERM); ``why`` says how."""

    def __init__(self, why: str) -> None:
        super().__init__(f"interrupted ({why})")
        self.why = why


def result_of(board: str) -> str | None:
    """'X' or 'O' for a win, 'draw' for a full board, None while the game is on."""
    b = parse_board(board)
    won = winner(b)
    if won is not None:
        return won
    return "draw" if is_full(b) else None


def winning_cells(board: str) -> list[list[int]] | None:
    """The four cells (1-based ``[row, column]``) of the four in a row on ``board``, or None (no win)."""
    line = winning_line(parse_board(board))
    return None if line is None else [list(c) for c in line]


def outcome_in_words(outcome: str | None, robot_symbol: str, person_symbol: str) -> str:
    """How a game ended, for a person to read: who won, or why there is no winner."""
    return {robot_symbol: f"the robot ({robot_symbol}) won", person_symbol: f"the person ({person_symbol}) won",
            "draw": "a draw: the board is full", "given_up": "the person gave up",
            "halted": "stopped before a result", "abandoned": "ended without a result"}.get(outcome or "abandoned",
                                                                                           str(outcome))
