"""From cells as the image shows them to the board's (row, column).

:func:`~ttt_sm.vision.detection.detect` numbers cells as the picture shows
them: row 1 at the top, column 1 at the left.  The board numbers them as
the thesis does (eqs. 3.37-3.38): cell (1, 1) at ``(x11, y11)``, the field's
corner farthest from the robot on the +x side; rows grow towards the robot
(-y), columns towards -x.  Which image cell is which board cell depends on
where the camera stands; the views are those of
:data:`ttt_sm.twin.whiteboard.VIEWS`:

============  ===========  ==========  ============  ================================
view          image right  image up    board (1, 1)  image (r, c) is board
============  ===========  ==========  ============  ================================
``far_edge``  -x           -y          bottom left   (6 - r, c)
``above``     +x           +y          top right     (r, 6 - c)
``field``     -x           +y          top left      (r, c)
============  ===========  ==========  ============  ================================

The simulated camera stands beyond the board's far edge and looks back at
the robot (:meth:`~ttt_sm.vision.simulated.CameraPose.beyond_far_edge`):
view ``"far_edge"``.  A real camera on a stand over the board is
``"above"`` if the robot is at the bottom of its picture, ``"far_edge"`` if
at the top.
"""

from __future__ import annotations

from .errors import VisionError

N = 5
VIEW_NAMES = ("far_edge", "above", "field")


def _check(view: str) -> None:
    if view not in VIEW_NAMES:
        raise VisionError(f"view must be one of {', '.join(VIEW_NAMES)}, got {view!r}")


def board_cell(row: int, column: int, view: str = "far_edge") -> tuple[int, int]:
    """The board's (row, column) of image cell (row, column), both 1-based (see the module table)."""
    _check(view)
    if not (1 <= row <= N and 1 <= column <= N):
        raise VisionError(f"cell ({row}, {column}) is off the {N}x{N} field")
    if view == "far_edge":
        return N + 1 - row, column
    if view == "above":
        return row, N + 1 - column
    return row, column


def image_cell(row: int, column: int, view: str = "far_edge") -> tuple[int, int]:
    """The image cell showing board cell (row, column): the inverse of :func:`board_cell`."""
    return board_cell(row, column, view)  # each mapping is its own inverse


def board_text(cells: str, view: str = "far_edge") -> str:
    """Reorder 25 image-order characters (``Detection.cells``) into board order (row 1, column 1 first)."""
    _check(view)
    if len(cells) != N * N:
        raise VisionError(f"expected 25 cell characters, got {len(cells)}")
    out = [""] * (N * N)
    for r in range(1, N + 1):
        for c in range(1, N + 1):
            br, bc = board_cell(r, c, view)
            out[(br - 1) * N + (bc - 1)] = cells[(r - 1) * N + (c - 1)]
    return "".join(out)


def board_values(values: list[float] | tuple[float, ...], view: str = "far_edge") -> tuple[float, ...]:
    """Reorder 25 image-order numbers (``Detection.percentages``) into board order."""
    _check(view)
    if len(values) != N * N:
        raise VisionError(f"expected 25 values, got {len(values)}")
    out = [0.0] * (N * N)
    for r in range(1, N + 1):
        for c in range(1, N + 1):
            br, bc = board_cell(r, c, view)
            out[(br - 1) * N + (bc - 1)] = float(values[(r - 1) * N + (c - 1)])
    return tuple(out)


def image_text(board: str, view: str = "far_edge") -> str:
    """Reorder 25 board-order characters into image order (the inverse of :func:`board_text`)."""
    return board_text(board, view)  # every view's mapping is an involution
