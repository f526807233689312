"""An exact solver for 5x5 four-in-a-row: can a given player force a win?

One question, asked with a fixed *attacker*: "from here, can the attacker
force four in a row whatever the defender does?"  The answer is a plain
yes/no, which makes the search small (an AND/OR tree rather than a
three-valued minimax) and its table entries one bit:

* the strong engine never loses because every move it makes leaves a
  position where the opponent, as attacker, cannot force a win;
* it wins when, as attacker itself, it finds a move after which it can.

What keeps a plain-Python search fast enough (the whole game from the empty
field is about 0.6 million nodes, a few seconds):

* bitboards: a side's cells are a 25-bit int, the 28 winning lines masks;
* threats first: a side that can complete a four does; a single threat of
  the opponent must be blocked (the only move searched); two cannot be;
* dead positions: an attacker without an open line (one the defender has not
  entered) cannot win, a full field is a draw;
* move ordering: cells on many open lines, and on lines a side already
  holds two or three of, first; the defender looks for a refutation, the
  attacker for a win, so the first good move ends the node;
* a transposition table keyed by the position, folded under the eight
  symmetries of the square while the field holds up to ``CANON_UPTO`` marks.
"""

from __future__ import annotations

from typing import Literal

from .bitboard import CELL_LINES, FULL, LINE_MASKS, LINES, N_CELLS, canonical, has_four, win_cells

Outcome = Literal["win", "draw", "loss"]
"""What a side to move can force: a win, a draw, or (against best play) a loss."""

CANON_UPTO = 12
"""Fold positions with this many marks or fewer under the symmetries (deeper, the look-up costs more than it saves)."""
_ORDER_BITS = tuple(1 << i for i in sorted(range(N_CELLS), key=lambda i: -len(CELL_LINES[i])))
_LINE_INFO = tuple(zip(LINE_MASKS, tuple(tuple(1 << i for i in line) for line in LINES), strict=True))
# Ordering weights by how many marks a line already holds: own open lines count
# three times as much as the opponent's lines a move would block.
_OWN_WEIGHT = (1, 3, 9, 27, 0)
_BLOCK_WEIGHT = (0, 1, 3, 9, 0)
_DEFENDER_TO_MOVE = 1 << (2 * N_CELLS)


class OutOfBudget(Exception):
    """A search with a node budget ran out before it had an answer."""


def ordered_moves(mover: int, other: int) -> list[int]:
    """The empty cells as single-bit masks, most promising first for ``mover``.

    A cell scores for every line through it: lines open to the mover by how
    many marks the mover has there, lines open to the other by how many it
    has (blocking them); ties keep the centre-first order.
    """
    empty = FULL & ~(mover | other)
    score: dict[int, int] = {}
    get = score.get
    for m, cells in _LINE_INFO:
        if not other & m:
            w = _OWN_WEIGHT[(mover & m).bit_count()]
        elif not mover & m:
            w = _BLOCK_WEIGHT[(other & m).bit_count()]
        else:
            continue
        for b in cells:
            if empty & b:
                score[b] = get(b, 0) + w
    base = [b for b in _ORDER_BITS if empty & b]
    return sorted(base, key=lambda b: -score.get(b, 0))


class Solver:
    """The attacker-wins search with its transposition table.

    The table only holds proven answers, so it makes searches faster but
    never changes them; it is emptied when it reaches ``max_entries``.
    ``nodes`` counts positions visited; set ``budget`` to make a search
    raise :class:`OutOfBudget` once it has visited that many.
    """

    def __init__(self, max_entries: int = 1_500_000) -> None:
        self.table: dict[int, bool] = {}
        self.max_entries = max_entries
        self.nodes = 0
        self.budget: int | None = None

    def attacker_wins(self, attacker: int, defender: int, attacker_to_move: bool) -> bool:
        """True if ``attacker`` can force four in a row from this position, whatever ``defender`` plays."""
        if has_four(attacker) or has_four(defender):  # the search below assumes nobody has won yet
            return has_four(attacker)
        if len(self.table) >= self.max_entries:
            self.table.clear()
        return self._search(attacker, defender, attacker_to_move, (attacker | defender).bit_count())

    def _search(self, a: int, d: int, a_to_move: bool, n: int) -> bool:
        self.nodes += 1
        if self.budget is not None and self.nodes > self.budget:
            raise OutOfBudget
        empty = FULL & ~(a | d)
        # One pass over the lines: both sides' threats, and whether the attacker has an open line.
        ta = td = 0
        a_open = False
        for m in LINE_MASKS:
            if not d & m:
                a_open = True
                x = a & m
                if x.bit_count() == 3:
                    ta |= x ^ m
            elif not a & m:
                y = d & m
                if y.bit_count() == 3:
                    td |= y ^ m
        if a_to_move:
            if ta:
                return True
            if not empty:
                return False
            if td:  # must block; two threats cannot both be blocked
                return False if td & (td - 1) else self._search(a | td, d, False, n + 1)
        else:
            if td:
                return False
            if not empty:
                return False
            if ta:
                return True if ta & (ta - 1) else self._search(a, d | ta, True, n + 1)
        if not a_open:
            return False
        key = canonical(a, d)[0] if n <= CANON_UPTO else a | d << N_CELLS
        if not a_to_move:
            key |= _DEFENDER_TO_MOVE
        known = self.table.get(key)
        if known is not None:
            return known
        if a_to_move:
            result = any(self._search(a | b, d, False, n + 1) for b in ordered_moves(a, d))
        else:
            result = all(self._search(a, d | b, True, n + 1) for b in ordered_moves(d, a))
        self.table[key] = result
        return result


def choose(solver: Solver, mine: int, theirs: int, win_budget: int | None) -> tuple[int, Outcome, int]:
    """The move (a bit index) for the side holding ``mine`` to move, its outcome, and the nodes searched.

    ``win_budget`` ``None`` searches for a forced win exactly (what the book
    is built with); a number caps that search, and a fresh :class:`Solver`
    does it so the answer does not depend on ``solver``'s table.
    """
    wins = win_cells(mine, theirs)
    if wins:
        return (wins & -wins).bit_length() - 1, "win", 0
    threats = win_cells(theirs, mine)
    if threats & (threats - 1):  # two cells to block: lost whatever we do; block one
        return (threats & -threats).bit_length() - 1, "loss", 0
    candidates = [threats] if threats else ordered_moves(mine, theirs)
    nodes = 0
    win_search = solver if win_budget is None else Solver()
    win_search.nodes, win_search.budget = 0, win_budget
    try:
        for b in candidates:
            if win_search.attacker_wins(mine | b, theirs, attacker_to_move=False):
                return b.bit_length() - 1, "win", win_search.nodes
    except OutOfBudget:
        pass
    nodes += win_search.nodes
    solver.nodes, solver.budget = 0, None
    for b in candidates:
        if not solver.attacker_wins(theirs, mine | b, attacker_to_move=True):
            return b.bit_length() - 1, "draw", nodes + solver.nodes
    return candidates[0].bit_length() - 1, "loss", nodes + solver.nodes
