"""Bitboards of the 5x5 field: a set of cells is a 25-bit int, bit ``5*(row-1) + (column-1)``.

Both engines and the rules count winning lines with these masks; the strong
engine also folds positions under the eight symmetries of the square.
"""

from __future__ import annotations

SIZE = 5
"""Cells per side of the field (thesis 3.6.2: a 5 by 5 field)."""
K = 4
"""Marks in a row that win (thesis 3.6.2: four consecutive symbols)."""
N_CELLS = SIZE * SIZE
FULL = (1 << N_CELLS) - 1


def cell_index(row: int, column: int) -> int:
    """Bit index of the 1-based cell ``(row, column)``."""
    return SIZE * (row - 1) + (column - 1)


def cell_of(index: int) -> tuple[int, int]:
    """The 1-based ``(row, column)`` of a bit index."""
    return index // SIZE + 1, index % SIZE + 1


def _lines() -> tuple[tuple[int, ...], ...]:
    """Every run of K cells in a row, a column or a diagonal, as 0-based cell indices."""
    runs = []
    for dr, dc in ((0, 1), (1, 0), (1, 1), (1, -1)):
        for r in range(SIZE):
            for c in range(SIZE):
                end_r, end_c = r + dr * (K - 1), c + dc * (K - 1)
                if 0 <= end_r < SIZE and 0 <= end_c < SIZE:
                    runs.append(tuple((r + dr * i) * SIZE + c + dc * i for i in range(K)))
    return tuple(runs)


LINES: tuple[tuple[int, ...], ...] = _lines()
"""The 28 winning lines: 10 in rows, 10 in columns, 4 on each diagonal direction."""
LINE_MASKS: tuple[int, ...] = tuple(sum(1 << i for i in line) for line in LINES)
CELL_LINES: tuple[tuple[int, ...], ...] = tuple(
    tuple(m for m in LINE_MASKS if m >> i & 1) for i in range(N_CELLS))
"""For each cell, the masks of the lines through it (3 at a corner, 8 at the centre)."""


def has_four(stones: int) -> bool:
    """True if ``stones`` hold a whole winning line."""
    return any(stones & m == m for m in LINE_MASKS)


def win_cells(mine: int, theirs: int) -> int:
    """Empty cells where ``mine`` would complete four in a row (lines with three of ``mine``, none of ``theirs``)."""
    cells = 0
    for m in LINE_MASKS:
        if not theirs & m:
            x = mine & m
            if x.bit_count() == K - 1:
                cells |= x ^ m
    return cells


def bits(mask: int) -> list[int]:
    """Indices of the set bits of ``mask``, lowest first."""
    out = []
    while mask:
        low = mask & -mask
        out.append(low.bit_length() - 1)
        mask ^= low
    return out


# The eight symmetries of the square as cell permutations: (r, c) -> f(r, c).
def _symmetries() -> tuple[tuple[int, ...], ...]:
    n = SIZE - 1
    maps = (lambda r, c: (r, c), lambda r, c: (c, n - r), lambda r, c: (n - r, n - c),
            lambda r, c: (n - c, r), lambda r, c: (r, n - c), lambda r, c: (n - r, c),
            lambda r, c: (c, r), lambda r, c: (n - c, n - r))
    perms = []
    for f in maps:
        perm = [0] * N_CELLS
        for i in range(N_CELLS):
            r2, c2 = f(i // SIZE, i % SIZE)
            perm[i] = r2 * SIZE + c2
        perms.append(tuple(perm))
    return tuple(perms)


SYMMETRIES: tuple[tuple[int, ...], ...] = _symmetries()
"""Cell permutations: ``SYMMETRIES[s][i]`` is where symmetry ``s`` sends cell ``i``; 0 is the identity."""
INVERSE: tuple[int, ...] = tuple(
    next(t for t in range(8) if all(SYMMETRIES[t][SYMMETRIES[s][i]] == i for i in range(N_CELLS)))
    for s in range(8))

# Row tables: the image of the 5 bits of one row of each side, combined as a 10-bit value,
# so a position (two masks) transforms with 5 look-ups per symmetry.
_ROW_TABLES: tuple[tuple[tuple[int, ...], ...], ...] = tuple(
    tuple(tuple(sum(1 << perm[r * SIZE + c] for c in range(SIZE) if v >> c & 1)
                | sum(1 << (perm[r * SIZE + c] + N_CELLS) for c in range(SIZE) if v >> (c + SIZE) & 1)
                for v in range(1 << (2 * SIZE)))
          for r in range(SIZE))
    for perm in SYMMETRIES)


def pack(a: int, b: int) -> int:
    """One int for a position: ``a`` in the low 25 bits, ``b`` above."""
    return a | b << N_CELLS


def transform(a: int, b: int, s: int) -> int:
    """The packed image of the position ``(a, b)`` under symmetry ``s``."""
    t = _ROW_TABLES[s]
    return (t[0][(a & 31) | (b & 31) << 5] | t[1][(a >> 5 & 31) | (b >> 5 & 31) << 5]
            | t[2][(a >> 10 & 31) | (b >> 10 & 31) << 5] | t[3][(a >> 15 & 31) | (b >> 15 & 31) << 5]
            | t[4][(a >> 20 & 31) | (b >> 20 & 31) << 5])


def canonical(a: int, b: int) -> tuple[int, int]:
    """The smallest packed image of ``(a, b)`` under the eight symmetries, and that symmetry."""
    best, best_s = pack(a, b), 0
    for s in range(1, 8):
        k = transform(a, b, s)
        if k < best:
            best, best_s = k, s
    return best, best_s
