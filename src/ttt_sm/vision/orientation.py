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

A photo turned or mirrored would be read as a turned or mirrored board,
every symbol in the wrong cell.  Two things tell the orientation:

* the **perspective** (:func:`check_orientation`): a camera beyond the far
  edge, looking down at a slant, sees the field's near side wider than its
  far side (1.16-1.22 times on the simulated camera, whatever its jitter),
  at the bottom of the picture.  A photo turned by 90 or 180 deg puts that
  side elsewhere.  A mirror keeps it at the bottom, and a camera straight
  above sees no perspective;
* the **robot's own marks** (:func:`check_robot_marks`, and
  :func:`~ttt_sm.vision.percent.percent_process` in a game): the robot knows
  where it drew; if the photo shows its marks where a turn or a mirror
  would put them, the photo is turned or mirrored.

A single photo cannot tell more: the drawn field is symmetric under every
turn and mirror of the square, and so are an X and an O.  A camera beyond
the far edge stands on the field's axis, so a left-right mirror keeps its
perspective; only robot marks that a mirror moves tell it.
:func:`establish_orientation` puts the two together: of the eight ways a
photo may have been turned or mirrored, it keeps those that the perspective
and the robot's marks allow, and reads the photo only if that leaves the
photo as it is, or leaves ways that all read the same board.  Anything else
is refused with the reason (docs/vision.md, "What a single photo can tell").
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from .errors import OrientationError, VisionError

N = 5
VIEW_NAMES = ("far_edge", "above", "field")
#: Where the side of the field nearest the camera lies in the picture, per view; None: the
#: camera looks straight down (or the view is a drawing convention), no side is nearer.
NEAR_SIDE: dict[str, str | None] = {"far_edge": "bottom", "above": None, "field": None}
#: In a view with perspective, the near side is at least this many times as wide as the far side
#: (the simulated camera: 1.16-1.22); less, and which way the photo is turned cannot be told.
MIN_PERSPECTIVE = 1.08
_OPPOSITE = {"top": "bottom", "bottom": "top", "left": "right", "right": "left"}
#: What to do when the near side is on another side than the view says (the view's side: bottom).
_TURN_BACK = {"left": "turn it 90 deg counter-clockwise", "right": "turn it 90 deg clockwise",
              "top": "turn it 180 deg"}


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


def perspective(corners: Iterable[Iterable[float]]) -> tuple[str, float]:
    """The side of the field that looks widest (``top``, ``bottom``, ``left``, ``right``) and how many
    times as wide as the side opposite; `corners` as :attr:`~ttt_sm.vision.grid.Grid.corners`
    (top left, top right, bottom right, bottom left, pixels)."""
    (x0, y0), (x1, y1), (x2, y2), (x3, y3) = ((float(x), float(y)) for x, y in corners)

    def length(ax: float, ay: float, bx: float, by: float) -> float:
        return float(((ax - bx) ** 2 + (ay - by) ** 2) ** 0.5)

    sides = {"top": length(x0, y0, x1, y1), "right": length(x1, y1, x2, y2),
             "bottom": length(x2, y2, x3, y3), "left": length(x3, y3, x0, y0)}
    widest = max(sides, key=lambda k: sides[k] / max(sides[_OPPOSITE[k]], 1e-9))
    return widest, sides[widest] / max(sides[_OPPOSITE[widest]], 1e-9)


def _near_side(grid: object, view: str, what: str) -> tuple[str, float]:
    """The side of the field nearest the camera and how much wider it is than the far side; an
    :class:`OrientationError` when the perspective is too weak to tell (a camera looking straight down)."""
    side, ratio = perspective(grid.corners)  # type: ignore[attr-defined]
    if ratio < MIN_PERSPECTIVE:
        raise OrientationError(
            f"{what}: cannot tell which way the photo is turned: the field's sides differ by only"
            f" {100 * (ratio - 1):.0f} %, where a camera {_WHERE[view]} sees its near side at least"
            f" {100 * (MIN_PERSPECTIVE - 1):.0f} % wider; if the camera looks straight down, give --view above")
    return side, ratio


def check_orientation(grid: object, view: str, what: str = "photo") -> str:
    """Check by its perspective that a photo is not turned against `view`; a note of what was checked.

    Parameters
    ----------
    grid : Grid
        The located field (``Detection.grid``); only its ``corners`` are read.
    view : str
        Where the camera stands (:data:`VIEW_NAMES`).
    what : str
        How to name the photo in the message (its file name).

    Returns
    -------
    str
        ``orientation checked: ...`` or, for a view without perspective,
        ``orientation not checked: ...`` saying why and what would check it.

    Raises
    ------
    OrientationError
        The field's near side is not where `view` puts it (the photo is
        turned), or the perspective is too weak to tell.
    """
    _check(view)
    near = NEAR_SIDE[view]
    if near is None:
        return (f"orientation not checked: in view {view!r} no side of the field is nearer the camera, so a"
                f" turned or mirrored photo looks the same; the robot's marks check it (--robot-marks)")
    side, ratio = _near_side(grid, view, what)
    if side != near:
        raise OrientationError(
            f"{what}: the photo is turned: the field's near side (the widest, {ratio:.2f} times its far side)"
            f" is at the {side} of the picture, where a camera {_WHERE[view]} sees it at the {near};"
            f" {_TURN_BACK[side]}, or give the --view of the camera")
    return f"orientation checked: the field's near side is at the {side}, {ratio:.2f} times as wide as its far side"


_WHERE = {"far_edge": "beyond the far edge"}

#: What may have happened to a photo, and how to undo it on a 5 x 5 grid of image cells
#: (0-based row, column of the photo as it should be -> where that cell is in the photo given).
CHANGES: dict[str, Callable[[int, int], tuple[int, int]]] = {
    "mirrored left-right": lambda r, c: (r, N - 1 - c),
    "mirrored top-bottom": lambda r, c: (N - 1 - r, c),
    "turned 90 deg clockwise": lambda r, c: (c, N - 1 - r),
    "turned 90 deg counter-clockwise": lambda r, c: (N - 1 - c, r),
    "turned 180 deg": lambda r, c: (N - 1 - r, N - 1 - c),
    "mirrored across its diagonal": lambda r, c: (c, r),
    "mirrored across its other diagonal": lambda r, c: (N - 1 - c, N - 1 - r),
}


def _undo(cells: str, change: Callable[[int, int], tuple[int, int]]) -> str:
    out = []
    for r in range(N):
        for c in range(N):
            rr, cc = change(r, c)
            out.append(cells[rr * N + cc])
    return "".join(out)


def _shows(board: str, marks: str) -> list[tuple[int, int]]:
    """The board cells of `marks` (``X``/``O``) that `board` does not show (``#`` shows either)."""
    return [divmod(k, N) for k, m in enumerate(marks) if m != EMPTY and board[k] not in (m, "#")]


EMPTY = "."


def check_robot_marks(cells: str, view: str, robot_marks: str, what: str = "photo") -> None:
    """Check that the robot's own marks are where it drew them in a detection.

    Parameters
    ----------
    cells : str
        ``Detection.cells``: 25 characters in image order.
    view : str
        Where the camera stands (:data:`VIEW_NAMES`).
    robot_marks : str
        25 characters in board order: the robot's ``X`` or ``O`` where it
        drew, ``.`` elsewhere.
    what : str
        How to name the photo in the message.

    Raises
    ------
    OrientationError
        The marks are seen where a turn or a mirror of the photo would put
        them (the message names which).
    VisionError
        Some marks are not seen, and no turn or mirror explains it.
    """
    _check(view)
    if len(cells) != N * N or len(robot_marks) != N * N or set(robot_marks) - {"X", "O", EMPTY}:
        raise VisionError(f"{what}: expected 25 detected cells and 25 robot marks ('X', 'O' or '.')")
    missing = _shows(board_text(cells, view), robot_marks)
    if not missing:
        return
    explains = [name for name, change in CHANGES.items()
                if not _shows(board_text(_undo(cells, change), view), robot_marks)]
    if explains:
        raise OrientationError(
            f"{what}: the robot's marks show the photo {' or '.join(explains)}: they are where that would put"
            f" them, not where the robot drew them; fix the camera (a mirror setting?) or the photo")
    shown = ", ".join(f"({r + 1}, {c + 1})" for r, c in missing)
    raise VisionError(f"{what}: the robot's marks are not all seen: board cell(s) {shown} should hold"
                      f" {robot_marks[missing[0][0] * N + missing[0][1]]} and no turn or mirror of the photo"
                      f" explains it")


AS_IS = "as it is"
#: The eight ways a photo of the square field may have been changed: as it is and :data:`CHANGES`.
WAYS: dict[str, Callable[[int, int], tuple[int, int]]] = {AS_IS: lambda r, c: (r, c), **CHANGES}


def ways_perspective_allows(view: str) -> list[str]:
    """The ways (:data:`WAYS`) a photo in `view` may have been changed that its perspective cannot tell
    from the photo as it is: two (as it is and the mirror along the camera's axis) in a view with
    perspective, all eight in one without."""
    _check(view)
    near = NEAR_SIDE[view]
    return [n for n, ch in WAYS.items() if near is None or _side_after(ch, near) == near]


def undo_way(board: str, way: str, view: str) -> str:
    """25 board-order characters as read from a photo `way` changed: the board the photo shows once the
    change is undone (``way`` a name of :data:`WAYS`)."""
    return board_text(_undo(image_text(board, view), WAYS[way]), view)


def _side_after(change: Callable[[int, int], tuple[int, int]], side: str) -> str:
    """Where the `side` of the photo as it should be lies in a photo changed by `change`."""
    cells = {"top": [(0, c) for c in range(N)], "bottom": [(N - 1, c) for c in range(N)],
             "left": [(r, 0) for r in range(N)], "right": [(r, N - 1) for r in range(N)]}[side]
    moved = [change(r, c) for r, c in cells]
    for name, where in (("top", lambda rc: rc[0] == 0), ("bottom", lambda rc: rc[0] == N - 1),
                        ("left", lambda rc: rc[1] == 0), ("right", lambda rc: rc[1] == N - 1)):
        if all(where(rc) for rc in moved):
            return name
    raise AssertionError(f"{side} side not moved to a side")  # every change of the square moves sides to sides


def _cell_list(marks: str) -> str:
    return ", ".join(f"({k // N + 1}, {k % N + 1})" for k, m in enumerate(marks) if m != EMPTY) or "none"


def establish_orientation(grid: object, cells: str, view: str, robot_marks: str | None = None,
                          what: str = "photo") -> str:
    """Read a photo only if which way it is turned and its handedness are established; a note of how.

    Of the eight ways a photo of a square field may have been turned or
    mirrored (:data:`CHANGES` and the photo as it is), the perspective keeps
    those that put the field's near side where `view` has it (a view with
    perspective: two, the photo as it is and its mirror along the camera's
    axis), and the robot's marks keep those that show them where the robot
    drew them.  The photo is read if the photo as it is remains and every
    other remaining way reads the same board (a board symmetric like the
    marks: nothing is read wrong); else it is refused.

    Parameters
    ----------
    grid : Grid
        The located field (``Detection.grid``); only its ``corners`` are read.
    cells : str
        ``Detection.cells``: 25 characters in image order.
    view : str
        Where the camera stands (:data:`VIEW_NAMES`).
    robot_marks : str, optional
        25 characters in board order: the robot's ``X`` or ``O`` where it
        drew, ``.`` elsewhere; None if not known.
    what : str
        How to name the photo in messages (its file name).

    Returns
    -------
    str
        ``orientation checked: ...``, naming the evidence.

    Raises
    ------
    OrientationError
        The photo is turned or mirrored, or whether it is cannot be told and
        the board would read differently if it were.
    VisionError
        The robot's marks are not all seen and no allowed turn or mirror explains it.
    """
    _check(view)
    if len(cells) != N * N:
        raise VisionError(f"{what}: expected 25 detected cells, got {len(cells)}")
    if robot_marks is not None and (len(robot_marks) != N * N or set(robot_marks) - {"X", "O", EMPTY}):
        raise VisionError(f"{what}: expected 25 robot marks ('X', 'O' or '.')")
    ways = dict(WAYS)
    near = NEAR_SIDE[view]
    evidence = []
    if near is not None:
        side, ratio = _near_side(grid, view, what)
        ways = {n: ch for n, ch in ways.items() if _side_after(ch, near) == side}
        evidence.append(f"the field's near side is at the {side}, {ratio:.2f} times as wide as its far side")
        no_help = "its perspective cannot tell them apart (the camera stands on the field's axis)"
    else:
        no_help = f"in view {view!r} no side of the field is nearer the camera"
    if robot_marks is not None:
        kept = {n: ch for n, ch in ways.items() if not _shows(board_text(_undo(cells, ch), view), robot_marks)}
        if not kept:
            missing = _shows(board_text(cells, view), robot_marks)
            shown = ", ".join(f"({r + 1}, {c + 1})" for r, c in missing)
            raise VisionError(
                f"{what}: the robot's marks are not all seen: board cell(s) {shown} should hold"
                f" {robot_marks[missing[0][0] * N + missing[0][1]]} and no turn or mirror of the photo"
                f" {'that its perspective allows ' if near is not None else ''}explains it")
        ways = kept
        evidence.append(f"the robot's marks ({_cell_list(robot_marks)}) are where it drew them")
    others = [n for n in ways if n != AS_IS]
    if AS_IS not in ways:
        if near is not None and robot_marks is None:
            side = _side_after(ways[others[0]], near)
            turn = " or ".join(others)
            raise OrientationError(
                f"{what}: the photo is turned: the field's near side (the widest, {ratio:.2f} times its far"
                f" side) is at the {side} of the picture, where a camera {_WHERE[view]} sees it at the {near}"
                f" (the photo is {turn}); {_TURN_BACK[side]}, or give the --view of the camera")
        raise OrientationError(
            f"{what}: the robot's marks show the photo {' or '.join(others)}: read as it is, every symbol would be"
            f" in the wrong cell; fix the camera (a mirror setting?) or the photo")
    as_read = board_text(cells, view)
    differ = [n for n in others if board_text(_undo(cells, ways[n]), view) != as_read]
    if differ:
        marks = ("no robot marks were given (--robot-marks)" if robot_marks is None else
                 f"the robot's marks ({_cell_list(robot_marks)}) look the same")
        raise OrientationError(
            f"{what}: cannot tell whether the photo is {' or '.join(differ)}: {no_help}, and {marks}"
            f" that way; read one way or the other it shows a different board; give the robot's marks"
            f" with one that such a mirror or turn would move")
    if others:
        evidence.append(f"{' or '.join(others)}, it would read the same board")
    return "orientation checked: " + "; ".join(evidence)
