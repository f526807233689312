"""The thesis' tic-tac-toe algorithm (thesis 3.6.2): minimax over three plies with f = n1 - n2.

The Matlab block of Fig. 3.29 takes the coordinates of the opponent's marks
(``o_pos``) and of the arm's own (``x_pos``) and outputs the arm's next cell
(``play_ps``).  Its steps, as :func:`thesis_algorithm` follows them:

1. combine both lists into one field;
2. if the opponent already has four in a row, stop and output a coordinate
   that is out of range (:data:`OUT_OF_RANGE`);
3-4. expand every empty cell with the arm's mark; a win scores +inf and is
   not expanded further;
5-6. expand each of those with every reply of the opponent; an opponent win
   scores -inf;
7-8. expand each of those with every second move of the arm; a win scores
   +inf;
9. score every other third-ply state with the static evaluation
   ``f = n1 - n2`` (eq. 3.52);
10-12. back the scores up: the opponent picks the lowest, the arm the highest;
13. output the cell of the best first move.

How we read what the thesis leaves open (docs/game.md says the same):

* ``n1`` ("number of possibilities to win") is the number of the 28 winning
  lines holding no opponent mark, ``n2`` ("possibilities to lose") those
  holding no mark of the arm; an empty line counts in both, so it cancels.
* A state with no empty cell left before the third ply is scored with ``f``.
* Cells are tried row by row, column by column, and among equal scores the
  first one wins (what Matlab's ``max`` returns).
* The thesis does not print the out-of-range coordinate; we use ``(6, 6)``,
  one past the last row and column.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

from .bitboard import CELL_LINES, FULL, LINE_MASKS, bits, cell_index, cell_of, has_four
from .engine import GameOver, Move, prepare
from .rules import Board, BoardError, MoveError, Symbol, check_cell, other

OUT_OF_RANGE: tuple[int, int] = (6, 6)
"""What step 2 outputs when the opponent has already won: a cell off the 5x5 field."""
INF = math.inf


def static_evaluation(mine: int, theirs: int) -> int:
    """Eq. 3.52, ``f = n1 - n2``: winning lines still open to the arm minus those open to the opponent."""
    n1 = sum(1 for m in LINE_MASKS if not theirs & m)
    n2 = sum(1 for m in LINE_MASKS if not mine & m)
    return n1 - n2


def _completes_four(stones: int, cell: int) -> bool:
    """True if adding ``cell`` (a bit index) to ``stones`` makes four in a row."""
    s = stones | 1 << cell
    return any(s & m == m for m in CELL_LINES[cell])


def _third_ply(mine: int, theirs: int) -> float:
    """Steps 7-10: the best score of the arm's second move on the state ``(mine, theirs)``.

    Placing the arm's mark on a cell leaves ``n1`` as it is and closes, for
    the opponent, the lines through that cell the arm had not entered yet, so
    each leaf's ``f`` is the parent's ``f`` plus that count; this is
    ``max(static_evaluation(mine | cell, theirs))`` without recounting 28
    lines per leaf (a test checks the two agree).
    """
    empty = FULL & ~(mine | theirs)
    if not empty:
        return static_evaluation(mine, theirs)
    base = static_evaluation(mine, theirs)
    best = -INF
    for cell in bits(empty):
        if _completes_four(mine, cell):
            return INF  # step 8: nothing beats a win
        gain = sum(1 for m in CELL_LINES[cell] if not mine & m)
        best = max(best, base + gain)
    return best


def _second_ply(mine: int, theirs: int) -> float:
    """Steps 5-6 and 11: the lowest score the opponent can leave after the arm's first move."""
    empty = FULL & ~(mine | theirs)
    if not empty:
        return static_evaluation(mine, theirs)
    worst = INF
    for cell in bits(empty):
        if _completes_four(theirs, cell):
            return -INF  # step 6: the opponent wins
        worst = min(worst, _third_ply(mine, theirs | 1 << cell))
    return worst


def first_ply_scores(mine: int, theirs: int) -> dict[int, float]:
    """Steps 3-4 and 12: the backed-up score of each of the arm's moves, by bit index."""
    scores: dict[int, float] = {}
    for cell in bits(FULL & ~(mine | theirs)):
        scores[cell] = INF if _completes_four(mine, cell) else _second_ply(mine | 1 << cell, theirs)
    return scores


def _mask(cells: Iterable[tuple[int, int]], what: str) -> int:
    mask = 0
    for row, column in cells:
        try:
            check_cell(row, column)
        except MoveError as exc:
            raise BoardError(f"{what}: {exc}") from None
        bit = 1 << cell_index(row, column)
        if mask & bit:
            raise BoardError(f"{what}: cell ({row}, {column}) is listed twice")
        mask |= bit
    return mask


def thesis_algorithm(o_pos: Iterable[tuple[int, int]], x_pos: Iterable[tuple[int, int]]) -> tuple[int, int]:
    """The Matlab block of Fig. 3.29: the arm's next cell ``play_ps`` from both players' cells.

    ``o_pos`` are the opponent's cells (from the camera), ``x_pos`` the arm's
    own, 1-based ``(row, column)`` pairs, whatever symbols they draw.
    Returns :data:`OUT_OF_RANGE` if the opponent already has four in a row
    (step 2); raises :class:`~ttt_sm.game.rules.MoveError` if no cell is
    empty (the thesis does not say what happens then).
    """
    theirs = _mask(o_pos, "o_pos")
    mine = _mask(x_pos, "x_pos")
    if mine & theirs:
        raise BoardError("o_pos and x_pos share a cell")
    if has_four(theirs):  # step 2
        return OUT_OF_RANGE
    scores = first_ply_scores(mine, theirs)
    if not scores:
        raise MoveError("no empty cell is left: the field is full")
    best = max(scores.values())
    return cell_of(next(c for c, s in scores.items() if s == best))


class ThesisEngine:
    """The thesis' three-ply minimax as an :class:`~ttt_sm.game.engine.Engine`.

    A finished game is a :class:`~ttt_sm.game.engine.GameOver`; when the
    opponent has won it carries the thesis' out-of-range output.
    """

    name = "thesis"

    def move(self, board: Board | str, symbol: Symbol) -> Move | GameOver:
        """The thesis algorithm's cell for ``symbol`` on ``board``."""
        b, me, over = prepare(board, symbol)
        if over is not None:
            if over.winner == other(me):
                return GameOver(over.winner, over.reason, thesis_output=OUT_OF_RANGE)
            return over
        mine, theirs = b.marks(me), b.marks(other(me))
        row, column = thesis_algorithm([cell_of(i) for i in bits(theirs)], [cell_of(i) for i in bits(mine)])
        return Move(row, column)
