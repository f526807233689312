"""Percent-process (thesis 3.6.3): from the camera's per-cell percentages to the person's moves.

The thesis' Matlab function takes the 25 percentages and the robot's moves,
marks every cell whose percentage exceeds a set value, and removes the
robot's cells: what is left are the person's.  Here it also keeps the
person's earlier moves and refuses what is not one legal move, with a
message the game can show the person:

* two or more new symbols at once -> :class:`~ttt_sm.vision.errors.TooManyMovesError`;
* new ink in a cell the robot occupies (its percentage rose well above what
  the robot's own symbol read, or the cell reads the person's symbol) ->
  :class:`~ttt_sm.vision.errors.RobotCellMarkedError`;
* a symbol (the robot's or the person's) that is no longer seen ->
  :class:`~ttt_sm.vision.errors.SymbolVanishedError`, unless every symbol
  is seen where a turned or mirrored picture would put it ->
  :class:`~ttt_sm.vision.errors.PictureTurnedError` (the camera is wrong,
  not the person).

Everything is in board order (row 1, column 1 first): map a detection with
:func:`read_moves` or :mod:`ttt_sm.vision.orientation`.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

from .detection import OCCUPIED_PCT, Detection
from .errors import PictureTurnedError, RobotCellMarkedError, SymbolVanishedError, TooManyMovesError, VisionError
from .orientation import CHANGES, board_text, board_values

Cell = tuple[int, int]
N = 5
#: A robot cell whose percentage rose by more than this over the reading of the robot's
#: own symbol has been drawn on, percent points (the robot's symbol reads about 8-13 %,
#: a person's adds 15-20 %; frame-to-frame noise is below 1).
OVERDRAW_PCT = 5.0


@dataclass(frozen=True)
class PersonMoves:
    """The person's moves seen on the board.

    Attributes
    ----------
    cells : tuple of (row, column)
        Every cell the person occupies, in board order (row-major), 1-based.
    new : (row, column) or None
        The move made since the last call (None: the person has not moved yet).
    """

    cells: tuple[Cell, ...]
    new: Cell | None


def _cells(cells: Iterable[Cell], what: str) -> set[Cell]:
    out = set()
    for cell in cells:
        r, c = cell
        if not (1 <= r <= N and 1 <= c <= N):
            raise VisionError(f"{what}: cell {cell!r} is off the {N}x{N} field")
        out.add((int(r), int(c)))
    return out


def percent_process(percentages: Sequence[float], robot_cells: Iterable[Cell],
                    person_cells: Iterable[Cell] = (), *, robot_ink: Mapping[Cell, float] | None = None,
                    symbols: str | None = None, robot_symbol: str | None = None,
                    occupied_pct: float = OCCUPIED_PCT, overdraw_pct: float = OVERDRAW_PCT) -> PersonMoves:
    """The person's moves from the 25 per-cell percentages (board order) and the robot's moves.

    Parameters
    ----------
    percentages : sequence of 25 floats
        Ink share per cell, percent, board order (row 1, column 1 first).
    robot_cells : iterable of (row, column)
        Cells the robot has drawn its symbol in.
    person_cells : iterable of (row, column)
        The person's moves accepted so far.
    robot_ink : mapping (row, column) -> percent, optional
        What each robot cell read just after the robot drew there; a rise
        of more than `overdraw_pct` means the person drew on it.
    symbols, robot_symbol : str, optional
        The detection's 25 characters in board order and the robot's
        symbol (``"X"``/``"O"``): a robot cell that reads the other symbol
        has been drawn on.
    occupied_pct : float
        A cell above this percentage holds a symbol.
    overdraw_pct : float
        See `robot_ink`.

    Returns
    -------
    PersonMoves

    Raises
    ------
    SymbolVanishedError, RobotCellMarkedError, TooManyMovesError
        (checked in that order) with ``cells`` and ``message_for_person``.
    """
    if len(percentages) != N * N:
        raise VisionError(f"percent-process: expected 25 percentages, got {len(percentages)}")
    robot = _cells(robot_cells, "robot_cells")
    person = _cells(person_cells, "person_cells")
    if robot & person:
        raise VisionError(f"percent-process: cells {sorted(robot & person)} are both the robot's and the person's")
    occupied = {divmod(k, N) for k in range(N * N) if float(percentages[k]) > occupied_pct}
    occupied = {(r + 1, c + 1) for r, c in occupied}
    gone = sorted((robot | person) - occupied)
    if gone and len(robot | person) >= 2 and _turned(robot | person, occupied):
        raise PictureTurnedError(sorted(robot | person))
    if gone:
        raise SymbolVanishedError(gone)
    marked = set()
    if robot_ink is not None:
        for cell, before in robot_ink.items():
            if cell in robot and float(percentages[(cell[0] - 1) * N + cell[1] - 1]) > before + overdraw_pct:
                marked.add(cell)
    if symbols is not None and robot_symbol is not None:
        if len(symbols) != N * N:
            raise VisionError(f"percent-process: expected 25 symbols, got {len(symbols)}")
        other = "O" if robot_symbol == "X" else "X"
        marked |= {cell for cell in robot if symbols[(cell[0] - 1) * N + cell[1] - 1] == other}
    if marked:
        raise RobotCellMarkedError(sorted(marked))
    new = sorted(occupied - robot - person)
    if len(new) > 1:
        raise TooManyMovesError(new)
    cells = tuple(sorted(person | set(new)))
    return PersonMoves(cells, new[0] if new else None)


def check_own_marks(percentages: Sequence[float], robot_cells: Iterable[Cell],
                    occupied_pct: float = OCCUPIED_PCT) -> None:
    """Check a photo taken right after the robot drew: every robot mark is seen where the robot drew it.

    The robot's marks are the only cells whose truth a game knows (the
    person's are what the camera read).  A photo that shows them where a turn
    or a mirror of the picture would put them is :class:`PictureTurnedError`;
    one that misses them otherwise, :class:`SymbolVanishedError`.
    """
    robot = _cells(robot_cells, "robot_cells")
    occupied = {(k // N + 1, k % N + 1) for k in range(N * N) if float(percentages[k]) > occupied_pct}
    if robot <= occupied:
        return
    if _turned(robot, occupied):
        raise PictureTurnedError(sorted(robot))
    raise SymbolVanishedError(sorted(robot - occupied))


def _turned(marks: set[Cell], occupied: set[Cell]) -> bool:
    """Whether a turn or a mirror of the picture (not none) would show every mark on an occupied cell."""
    for change in CHANGES.values():
        if all(tuple(v + 1 for v in change(r - 1, c - 1)) in occupied for r, c in marks):
            return True
    return False


def read_moves(detection: Detection, robot_cells: Iterable[Cell], person_cells: Iterable[Cell] = (), *,
               view: str = "far_edge", robot_ink: Mapping[Cell, float] | None = None,
               robot_symbol: str | None = None) -> PersonMoves:
    """:func:`percent_process` on a detection, mapped from the image to the board by `view`."""
    return percent_process(board_values(detection.percentages, view), robot_cells, person_cells,
                           robot_ink=robot_ink, symbols=board_text(detection.cells, view),
                           robot_symbol=robot_symbol)


def robot_ink_after_move(detection: Detection, cell: Cell, view: str = "far_edge") -> float:
    """The percentage of board `cell` in a detection: record it as ``robot_ink[cell]`` after the robot drew there."""
    r, c = _cells([cell], "cell").pop()
    return board_values(detection.percentages, view)[(r - 1) * N + c - 1]
