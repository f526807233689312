"""Boards to photograph: a field and symbols drawn without running the arm.

The real field and the robot's symbols come from the Control chart driving
the twin (``ttt-sm draw field``), which takes seconds of simulation per
symbol.  For pictures, tests and the vision benchmark these helpers lay the
same ink directly, as robot strokes (its 0.8 mm pen, a slight waver), and
let the person draw with :meth:`Whiteboard.draw_symbol` (a bolder marker,
a wobbly hand, off-centre, turned).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ttt_sm.params import ArmParams
from ttt_sm.twin.whiteboard import INK_WIDTH_M, Whiteboard

#: Size of the robot's X and O, m (the Control chart's default: 3/5 of a cell).
ROBOT_SYMBOL_SIZE_M = 0.018
#: Waver of the robot's strokes (gear play, the holder's drag), mm.
ROBOT_JITTER_MM = 0.12


def draw_field(board: Whiteboard, *, jitter_mm: float = ROBOT_JITTER_MM) -> None:
    """Draw the playing field as the robot does: 4 + 4 lines across the whole 15 cm field, 3 cm apart."""
    b = board.params.board
    x_lo, x11, y_lo, y11 = b.field_bounds()
    L = b.cell_size
    for k in range(1, b.cells):
        board.draw_stroke([(x11, y11 - k * L), (x_lo, y11 - k * L)], INK_WIDTH_M * 1e3,
                          jitter_mm=jitter_mm, author="robot")
    for k in range(1, b.cells):
        board.draw_stroke([(x11 - k * L, y11), (x11 - k * L, y_lo)], INK_WIDTH_M * 1e3,
                          jitter_mm=jitter_mm, author="robot")


def draw_robot_symbol(board: Whiteboard, kind: str, row: int, column: int, *,
                      size_m: float = ROBOT_SYMBOL_SIZE_M, jitter_mm: float = ROBOT_JITTER_MM) -> None:
    """Draw the robot's X (two diagonals) or O (a circle) in a cell, as robot ink (eqs. 3.37-3.51)."""
    x_lo, x_hi, y_lo, y_hi = board.cell_bounds(row, column)
    xc, yc, h = (x_lo + x_hi) / 2, (y_lo + y_hi) / 2, size_m / 2
    if kind == "X":
        for sign in (1.0, -1.0):
            board.draw_stroke([(xc - h, yc - sign * h), (xc + h, yc + sign * h)], INK_WIDTH_M * 1e3,
                              jitter_mm=jitter_mm, author="robot")
    elif kind == "O":
        a = np.linspace(0.0, 2 * math.pi * 1.03, 120)
        board.draw_stroke(np.column_stack((xc + h * np.cos(a), yc + h * np.sin(a))), INK_WIDTH_M * 1e3,
                          jitter_mm=jitter_mm, author="robot")
    else:
        raise ValueError(f"kind must be 'X' or 'O', got {kind!r}")


@dataclass(frozen=True)
class Scene:
    """A board with a field and symbols, and what is where.

    Attributes
    ----------
    board : Whiteboard
        The inked board.
    text : str
        The truth, 25 characters row-major in board cells (row 1 first,
        column 1 first), ``.`` empty, ``X``, ``O``.
    robot_symbol : str
        ``"X"`` or ``"O"``: the robot's; the person plays the other.
    robot_cells, person_cells : tuple of (row, column)
        Who drew where, 1-based.
    """

    board: Whiteboard
    text: str
    robot_symbol: str
    robot_cells: tuple[tuple[int, int], ...]
    person_cells: tuple[tuple[int, int], ...]


def random_scene(params: ArmParams, seed: int, *, max_symbols: int = 14, resolution_mm: float = 0.2) -> Scene:
    """A field and 0..`max_symbols` symbols in random cells, the robot's and the person's alternating.

    The robot plays X or O at random; the person draws the other by hand.
    """
    rng = np.random.default_rng(seed)
    board = Whiteboard(params, resolution_mm, seed=seed)
    draw_field(board)
    n_cells = params.board.cells
    count = int(rng.integers(0, max_symbols + 1))
    cells = [divmod(int(i), n_cells) for i in rng.permutation(n_cells * n_cells)[:count]]
    robot_symbol = "X" if rng.random() < 0.5 else "O"
    person_symbol = "O" if robot_symbol == "X" else "X"
    text = ["."] * (n_cells * n_cells)
    robot_cells, person_cells = [], []
    robot_first = bool(rng.random() < 0.5)
    for k, (r, c) in enumerate(cells):
        row, column = r + 1, c + 1
        if (k % 2 == 0) == robot_first:
            draw_robot_symbol(board, robot_symbol, row, column)
            text[r * n_cells + c] = robot_symbol
            robot_cells.append((row, column))
        else:
            board.draw_symbol(person_symbol, row, column)
            text[r * n_cells + c] = person_symbol
            person_cells.append((row, column))
    return Scene(board, "".join(text), robot_symbol, tuple(robot_cells), tuple(person_cells))


def scene_from_text(params: ArmParams, text: str, robot_symbol: str = "X", seed: int = 0, *,
                    resolution_mm: float = 0.2) -> Scene:
    """The field and the symbols of a 25-character board (board order, ``.``/``X``/``O``).

    The robot's symbol is drawn as robot ink, the other by hand.  Rows may be split by '/', '|', spaces or
    new lines (as ``ttt-sm camera serve --board`` and ``ttt-sm ai move --board`` take them).
    """
    n = params.board.cells
    t = "".join(ch for ch in text if ch not in " \t\r\n/|").upper()
    if len(t) != n * n or set(t) - {".", "X", "O"}:
        raise ValueError(f"board text must be {n * n} characters of '.', 'X', 'O' (row 1 first; rows may be split"
                         f" by '/'), got {text!r}")
    if robot_symbol not in ("X", "O"):
        raise ValueError(f"robot_symbol must be 'X' or 'O', got {robot_symbol!r}")
    board = Whiteboard(params, resolution_mm, seed=seed)
    draw_field(board)
    robot_cells, person_cells = [], []
    for k, ch in enumerate(t):
        if ch == ".":
            continue
        row, column = divmod(k, n)
        cell = (row + 1, column + 1)
        if ch == robot_symbol:
            draw_robot_symbol(board, ch, *cell)
            robot_cells.append(cell)
        else:
            board.draw_symbol(ch, *cell)
            person_cells.append(cell)
    return Scene(board, t, robot_symbol, tuple(robot_cells), tuple(person_cells))
