"""Who plays against the robot (thesis section 3.7, the Tic-tac-toe GUI's person).

A :class:`Person` chooses a cell and is told the game's messages: a
:class:`SimulatedPerson` at one of :data:`PERSON_STRENGTHS`, the
:class:`TerminalPerson` typing cells, or the :class:`RemotePerson` at the
browser's ``/game`` page, whose clicks reach the
:class:`~.game.GameSession` directly.
"""

from __future__ import annotations

import sys
from collections import deque
from collections.abc import Callable
from typing import Any, Protocol

import numpy as np

from ..game.bitboard import FULL, bits, cell_index, cell_of, win_cells
from ..game.rules import parse_board
from .game_outcome import GameError

#: A cell of the 5x5 field, 1-based: (row, column).
Cell = tuple[int, int]

#: The strengths of the simulated person (``ttt-sm play --person``).
PERSON_STRENGTHS = ("random", "greedy", "thesis", "perfect")


class Person(Protocol):
    """Who plays against the robot."""

    def choose(self, board: str, symbol: str) -> Cell | None:
        """A free cell to draw `symbol` in (1-based), or None to give up."""

    def tell(self, message: str) -> None:
        """Show the person a message (the Tic-tac-toe GUI's text box)."""


def _masks(board: str) -> tuple[int, int]:
    b = parse_board(board)
    return b.marks("X"), b.marks("O")


class SimulatedPerson:
    """A simulated person at the board, at one of :data:`PERSON_STRENGTHS`:

    - ``random``: any free cell;
    - ``greedy`` (the default): wins when one move wins, blocks when one move loses, else random;
    - ``thesis``: the thesis' three-ply minimax (:class:`~ttt_sm.game.thesis_engine.ThesisEngine`);
    - ``perfect``: never a move that lets the robot force a win, else random
      (:class:`~ttt_sm.game.opponents.PerfectEngine`): against the strong engine, a draw.
    """

    def __init__(self, seed: int = 0, say: Callable[[str], None] | None = None, strength: str = "greedy") -> None:
        if strength not in PERSON_STRENGTHS:
            raise ValueError(f"unknown person strength {strength!r}; choose from {', '.join(PERSON_STRENGTHS)}")
        self.rng = np.random.default_rng(seed)
        self.say = say
        self.strength = strength
        self.name = f"simulated {strength}"
        self._engine: Any = None
        if strength != "greedy":
            from ..game.opponents import PerfectEngine, RandomEngine
            from ..game.thesis_engine import ThesisEngine

            self._engine = {"random": lambda: RandomEngine(seed), "thesis": ThesisEngine,
                            "perfect": lambda: PerfectEngine(seed)}[strength]()

    def choose(self, board: str, symbol: str) -> Cell | None:
        cell = self._choose(board, symbol)
        if self.say and cell is not None:  # a log shows both players' moves and the board, not the robot's alone
            i = cell_index(*cell)
            self.say(f"  [person] draws {symbol} in row {cell[0]}, column {cell[1]}:\n"
                     + board_picture(board[:i] + symbol + board[i + 1:]))
        return cell

    def _choose(self, board: str, symbol: str) -> Cell | None:
        if self._engine is not None:
            from ..game.engine import GameOver

            answer = self._engine.move(board, symbol)
            return None if isinstance(answer, GameOver) else (answer.row, answer.column)
        x, o = _masks(board)
        mine, theirs = (x, o) if symbol == "X" else (o, x)
        empty = FULL & ~(x | o)
        for mask in (win_cells(mine, theirs), win_cells(theirs, mine)):
            if mask & empty:
                return cell_of(bits(mask & empty)[0])
        free = bits(empty)
        return cell_of(int(self.rng.choice(free))) if free else None

    def tell(self, message: str) -> None:
        if self.say:
            self.say(f"  [person] {message}")


class TerminalPerson:
    """The person at the terminal: types a cell ("2 3" = row 2, column 3); q gives up."""

    name = "terminal"

    def __init__(self, stdin: Any = None, stdout: Any = None, before_write: Callable[[], None] | None = None) -> None:
        self.stdin = stdin or sys.stdin
        self.stdout = stdout or sys.stdout
        #: Called before each line is written: takes a status line off the terminal (``ttt-sm play``).
        self.before_write = before_write or (lambda: None)

    def choose(self, board: str, symbol: str) -> Cell | None:
        self.before_write()
        self.stdout.write(board_picture(board) + "\n")
        while True:
            self.stdout.write(f"Your move ({symbol}): row column, e.g. 2 3 (q to give up): ")
            self.stdout.flush()
            line = self.stdin.readline()
            if not line or line.strip().lower() in ("q", "quit"):
                return None
            parts = line.replace(",", " ").split()
            if len(parts) == 2 and all(p.isdigit() for p in parts):
                r, c = int(parts[0]), int(parts[1])
                if 1 <= r <= 5 and 1 <= c <= 5 and board[cell_index(r, c)] == ".":
                    return r, c
                self.stdout.write(f"cell ({r}, {c}) is not a free cell of the 5x5 field\n")
            else:
                self.stdout.write(f"not a cell: {line.strip()!r}\n")

    def tell(self, message: str) -> None:
        self.before_write()
        self.stdout.write(message + "\n")
        self.stdout.flush()


class RemotePerson:
    """The person at a GUI (the browser's ``/game`` page): draws by clicking cells, then clicks Play.

    Nothing here decides: the page's clicks reach the :class:`~.game.GameSession`
    (:meth:`~.game.GameSession.person_draws`, :meth:`~.game.GameSession.press_play`), whose
    flow waits for them; the simulated hand draws each clicked cell on the
    whiteboard and the camera reads the board when Play is clicked, as in
    ``ttt-sm play``.  What the game tells the person is kept for the page.
    """

    def __init__(self, keep: int = 50) -> None:
        self.messages: deque[str] = deque(maxlen=keep)
        #: Messages told so far (the page shows the newest ones).
        self.told = 0

    def choose(self, board: str, symbol: str) -> Cell | None:
        raise GameError("the person at the page plays by clicking cells; the flow does not ask them")

    def tell(self, message: str) -> None:
        self.messages.append(message)
        self.told += 1


def board_picture(board: str) -> str:
    """The 5x5 board as text: a header of column numbers, then a row number and the row's marks per line."""
    rows = ["    1 2 3 4 5"]
    for r in range(5):
        rows.append(f"  {r + 1} " + " ".join(board[5 * r:5 * r + 5]))
    return "\n".join(rows)
