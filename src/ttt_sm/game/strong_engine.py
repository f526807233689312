"""An engine that never loses: an opening book for the first marks, an exact search after.

5x5 four-in-a-row is a draw with perfect play, so the engine can always keep
the opponent from forcing a win if it starts from a position that is not
lost.  Each move it

1. completes its own four if it can;
2. folds the position under the eight symmetries of the square, decides for
   the canonical image and maps the cell back (so symmetric positions get
   symmetric answers);
3. reads the answer from the opening book (:mod:`ttt_sm.game.book`) if it
   has it: every position up to 4 marks, and the positions up to 8 marks
   that a player following the book meets, solved exactly offline by
   :func:`choose`, because there the search costs up to seconds;
4. otherwise searches the candidates (the single cell that blocks an
   opponent's threat, else every empty cell, best first):

   a. for a forced win, within a node budget, so a move stays fast; the
      budget search has a table of its own, emptied each move, so the
      chosen move depends on the position only, not on earlier games;
   b. for the first candidate after which the opponent cannot force a win:
      an exact answer (no budget), which is what makes the engine never lose.

The answer says what the engine has proved (:class:`Analysis`): ``win``
(a forced win), ``draw`` (the opponent cannot force a win; the engine may
still win if the opponent errs) or ``loss`` (the opponent can force a win:
only from a position given to the engine already lost).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from .bitboard import FULL, INVERSE, N_CELLS, SYMMETRIES, canonical, cell_of, win_cells
from .book import Book, load_book
from .engine import GameOver, Move, prepare
from .rules import Board, Symbol, other
from .solver import Outcome, Solver, choose

WIN_BUDGET_NODES = 3000
"""Nodes the forced-win search may visit per move (about 25 ms); the no-loss search has no budget."""


@dataclass(frozen=True)
class Analysis:
    """The strong engine's move and why: what it proved and where the answer came from."""

    move: Move
    outcome: Outcome
    source: Literal["win-now", "book", "search"]
    nodes: int
    """Positions the searches visited for this move (0 for the book and an immediate win)."""


class StrongEngine:
    """The engine that never loses (see the module docstring); one instance keeps its search table.

    ``book=None`` loads the packaged opening book; pass ``Book.empty()`` to
    search every move (slow for the first few marks).
    """

    name = "strong"

    def __init__(self, book: Book | None = None, win_budget: int = WIN_BUDGET_NODES,
                 max_table_entries: int = 1_500_000) -> None:
        self.book = load_book() if book is None else book
        self.win_budget = win_budget
        self.solver = Solver(max_entries=max_table_entries)

    def move(self, board: Board | str, symbol: Symbol) -> Move | GameOver:
        """The engine's cell for ``symbol`` on ``board``, or why the game is over."""
        result = self.analyse(board, symbol)
        return result.move if isinstance(result, Analysis) else result

    def analyse(self, board: Board | str, symbol: Symbol) -> Analysis | GameOver:
        """Like :meth:`move`, with what the engine proved about the position."""
        b, me, over = prepare(board, symbol)
        if over is not None:
            return over
        mine, theirs = b.marks(me), b.marks(other(me))
        wins = win_cells(mine, theirs)
        if wins:
            return Analysis(Move(*cell_of((wins & -wins).bit_length() - 1)), "win", "win-now", 0)
        # Decide on the position's canonical image and map the cell back, so symmetric
        # positions get symmetric answers (what lets a proof check one per symmetry class).
        key, sym = canonical(mine, theirs)
        back = SYMMETRIES[INVERSE[sym]]
        entry = self.book.get(key) if (mine | theirs).bit_count() <= self.book.line_stones else None
        if entry is not None:
            cell, outcome = entry
            return Analysis(Move(*cell_of(back[cell])), outcome, "book", 0)
        cell, outcome, nodes = choose(self.solver, key & FULL, key >> N_CELLS, self.win_budget)
        return Analysis(Move(*cell_of(back[cell])), outcome, "search", nodes)

