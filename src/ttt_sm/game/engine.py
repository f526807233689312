"""What every engine answers: ``engine.move(board, symbol)`` is a :class:`Move` or a :class:`GameOver`.

An engine is anything with that method (:class:`Engine`).  The checks every
engine shares live here: the board must be legal and it must be ``symbol``'s
turn; a finished game gives a :class:`GameOver` instead of a cell.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple, Protocol

from .rules import Board, MoveError, Symbol, check_board, check_symbol, is_full, other, parse_board, winner


class Move(NamedTuple):
    """The cell an engine plays, 1-based; unpacks as ``row, column = move``."""

    row: int
    column: int


@dataclass(frozen=True)
class GameOver:
    """The game had ended before the engine's turn: who won (``None``: a full field, a draw).

    ``thesis_output`` is what the thesis' Matlab block would have sent to the
    arm instead of a cell (the out-of-range coordinate of step 2), if any.
    """

    winner: Symbol | None
    reason: str
    thesis_output: tuple[int, int] | None = None


class Engine(Protocol):
    """A player: given a legal board and its own symbol, choose a cell."""

    name: str

    def move(self, board: Board | str, symbol: Symbol) -> Move | GameOver:
        """The engine's cell on ``board`` playing ``symbol``, or why there is none."""
        ...


def prepare(board: Board | str, symbol: str) -> tuple[Board, Symbol, GameOver | None]:
    """Check ``board`` and whose turn it is; say if the game is already over.

    Raises :class:`~ttt_sm.game.rules.BoardError` for an illegal board and
    :class:`~ttt_sm.game.rules.MoveError` if ``symbol`` has more marks than
    its opponent (it moved last, so it is not its turn).
    """
    me = check_symbol(symbol)
    b = parse_board(board) if isinstance(board, str) else board
    check_board(b)
    won = winner(b)
    if won is not None:
        who = "the engine" if won == me else "the opponent"
        return b, me, GameOver(won, f"{won} has four in a row: {who} has won")
    if is_full(b):
        return b, me, GameOver(None, "the field is full: a draw")
    if b.count(me) > b.count(other(me)):
        raise MoveError(f"it is not {me}'s turn: {me} has {b.count(me)} marks and {other(me)} "
                        f"{b.count(other(me))}, so {me} moved last")
    return b, me, None
