"""The rules of the thesis' game: 5x5 tic-tac-toe, four in a row wins (thesis 3.6.2).

A board is 25 characters, row by row from the top left: ``.`` empty, ``X``,
``O``.  Cells are 1-based ``(row, column)``.  The thesis lets the person
choose the arm's symbol and decide when the arm plays (the GUI's *Symbol*
and *Play* buttons, thesis 3.7), so either symbol may start.  What makes a
board legal:

* the counts differ by at most one, and the player with more marks moved
  last; with equal counts the player who started (``first``, X unless told)
  is to move;
* at most one player has four in a row, that player made the last move, and
  that move completed every four they have (no play after a win).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from .bitboard import FULL, LINE_MASKS, LINES, N_CELLS, SIZE, bits, cell_index, cell_of

Symbol = Literal["X", "O"]
SYMBOLS: tuple[Symbol, Symbol] = ("X", "O")
EMPTY = "."
SEPARATORS = frozenset(" \t\r\n/|")
"""Characters ignored when reading a board, so ``..X../...../`` or five lines also read."""


class GameError(ValueError):
    """Something about a board or a move breaks the rules of the game; the message says what."""


class BoardError(GameError):
    """A board text is malformed or describes a position no game can reach."""


class MoveError(GameError):
    """A move cannot be played: outside the field, on a marked cell, out of turn or after the end."""


def other(symbol: Symbol) -> Symbol:
    """The opponent's symbol."""
    return "O" if symbol == "X" else "X"


def check_symbol(symbol: str, what: str = "symbol") -> Symbol:
    """``symbol`` if it is ``X`` or ``O`` (any case), else a :class:`GameError`."""
    s = symbol.upper() if isinstance(symbol, str) else symbol
    if s not in SYMBOLS:
        raise GameError(f"{what} must be X or O, got {symbol!r}")
    return s  # type: ignore[return-value]


def check_cell(row: int, column: int) -> None:
    """Raise :class:`MoveError` unless ``(row, column)`` is on the 5x5 field."""
    if not (isinstance(row, int) and isinstance(column, int) and 1 <= row <= SIZE and 1 <= column <= SIZE):
        raise MoveError(f"cell ({row}, {column}) is off the field: row and column run from 1 to {SIZE}")


@dataclass(frozen=True)
class Board:
    """A position: the cells of X and of O as 25-bit masks (bit ``5*(row-1) + column-1``).

    Build one with :func:`parse_board` (checked) or :meth:`empty` and
    :func:`apply_move`; ``str(board)`` is the 25-character text.
    """

    x: int = 0
    o: int = 0

    @classmethod
    def empty(cls) -> Board:
        """The empty field."""
        return cls(0, 0)

    def __str__(self) -> str:
        return "".join(self.at(*cell_of(i)) for i in range(N_CELLS))

    def at(self, row: int, column: int) -> str:
        """``X``, ``O`` or ``.`` at the 1-based cell."""
        check_cell(row, column)
        bit = 1 << cell_index(row, column)
        return "X" if self.x & bit else "O" if self.o & bit else EMPTY

    def marks(self, symbol: Symbol) -> int:
        """The mask of ``symbol``'s cells."""
        return self.x if symbol == "X" else self.o

    def count(self, symbol: Symbol) -> int:
        """How many marks ``symbol`` has."""
        return self.marks(symbol).bit_count()

    @property
    def stones(self) -> int:
        """Marks on the field."""
        return (self.x | self.o).bit_count()

    @property
    def empty_cells(self) -> int:
        """The mask of the empty cells."""
        return FULL & ~(self.x | self.o)


def parse_board(text: str, first: Symbol | None = None) -> Board:
    """Read a 25-character board and check it is a position some game reaches.

    ``x``/``o`` in lower case are accepted; spaces, new lines, ``/`` and ``|``
    are ignored.  ``first`` is who started, if known; ``None`` accepts either.
    Raises :class:`BoardError` naming the first problem found.
    """
    if not isinstance(text, str):
        raise BoardError(f"a board is a text of {N_CELLS} characters, got {type(text).__name__}")
    cells = [ch for ch in text if ch not in SEPARATORS]
    for i, ch in enumerate(cells[:N_CELLS]):
        if ch.upper() not in ("X", "O", EMPTY):
            row, column = cell_of(i)
            raise BoardError(f"board character {i + 1} (row {row}, column {column}) is {ch!r}; "
                             f"use '.' for empty, 'X' or 'O'")
    if len(cells) != N_CELLS:
        raise BoardError(f"a board has {N_CELLS} cells (5 rows of 5, row by row), got {len(cells)}")
    x = sum(1 << i for i, ch in enumerate(cells) if ch.upper() == "X")
    o = sum(1 << i for i, ch in enumerate(cells) if ch.upper() == "O")
    board = Board(x, o)
    check_board(board, first)
    return board


def format_board(board: Board, grid: bool = False) -> str:
    """The 25-character text, or with ``grid`` five lines of five."""
    text = str(board)
    return "\n".join(text[i:i + SIZE] for i in range(0, N_CELLS, SIZE)) if grid else text


def _fours(mask: int) -> list[int]:
    return [m for m in LINE_MASKS if mask & m == m]


def check_board(board: Board, first: Symbol | None = None) -> None:
    """Raise :class:`BoardError` if no game started by ``first`` (either, if ``None``) reaches ``board``."""
    if board.x & board.o or (board.x | board.o) & ~FULL:
        raise BoardError("a cell holds both X and O, or a mark lies outside the 25 cells")
    nx, no = board.count("X"), board.count("O")
    if abs(nx - no) > 1:
        raise BoardError(f"impossible move counts: X has {nx} marks and O {no}; players alternate, "
                         f"so the counts differ by at most one")
    if first is not None:
        first = check_symbol(first, "first")
        n_first, n_second = board.count(first), board.count(other(first))
        if n_first - n_second not in (0, 1):
            raise BoardError(f"impossible move counts: {first} started, so {first} has as many marks as "
                             f"{other(first)} or one more, but {first} has {n_first} and {other(first)} {n_second}")
    fours = {s: _fours(board.marks(s)) for s in SYMBOLS}
    if fours["X"] and fours["O"]:
        raise BoardError("both X and O have four in a row; the game ends at the first four")
    for s in SYMBOLS:
        if not fours[s]:
            continue
        mine, theirs = board.count(s), board.count(other(s))
        moved_last = mine > theirs or (mine == theirs and (first is None or first != s))
        if not moved_last:
            raise BoardError(f"{s} has four in a row but {other(s)} played after it; the game ends at the first four")
        common = FULL
        for m in fours[s]:
            common &= m
        if not common:
            raise BoardError(f"{s} has two separate fours in a row; one move cannot complete both, "
                             f"so play went on after a win")


def winner(board: Board) -> Symbol | None:
    """The player with four in a row, if any."""
    for s in SYMBOLS:
        if _fours(board.marks(s)):
            return s
    return None


def winning_line(board: Board) -> tuple[tuple[int, int], ...] | None:
    """The 1-based cells of a completed four, if there is one."""
    for line, m in zip(LINES, LINE_MASKS, strict=True):
        if board.x & m == m or board.o & m == m:
            return tuple(cell_of(i) for i in line)
    return None


def is_full(board: Board) -> bool:
    """True if no cell is empty."""
    return not board.empty_cells


def is_draw(board: Board) -> bool:
    """True if the field is full and nobody has four in a row."""
    return is_full(board) and winner(board) is None


def is_over(board: Board) -> bool:
    """True if someone has won or the field is full."""
    return winner(board) is not None or is_full(board)


def whose_turn(board: Board, first: Symbol = "X") -> Symbol | None:
    """Who moves next in a game ``first`` started; ``None`` once the game is over."""
    first = check_symbol(first, "first")
    check_board(board, first)
    if is_over(board):
        return None
    return first if board.count(first) == board.count(other(first)) else other(first)


def legal_moves(board: Board) -> list[tuple[int, int]]:
    """The empty cells, row by row, or none once the game is over."""
    if is_over(board):
        return []
    return [cell_of(i) for i in bits(board.empty_cells)]


def apply_move(board: Board, row: int, column: int, symbol: Symbol) -> Board:
    """The board after ``symbol`` marks ``(row, column)``.

    Raises :class:`MoveError` if the cell is off the field or marked, the game
    is over, or ``symbol`` has more marks than its opponent (not its turn).
    """
    symbol = check_symbol(symbol)
    check_cell(row, column)
    if is_over(board):
        won = winner(board)
        raise MoveError("the game is over: " + (f"{won} has four in a row" if won else "the field is full"))
    bit = 1 << cell_index(row, column)
    if (board.x | board.o) & bit:
        raise MoveError(f"cell ({row}, {column}) already holds {board.at(row, column)}")
    if board.count(symbol) > board.count(other(symbol)):
        raise MoveError(f"it is not {symbol}'s turn: {symbol} has {board.count(symbol)} marks and "
                        f"{other(symbol)} {board.count(other(symbol))}")
    return Board(board.x | bit, board.o) if symbol == "X" else Board(board.x, board.o | bit)
