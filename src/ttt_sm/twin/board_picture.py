"""The whiteboard as a picture for a person: the field, its cells numbered, a scale bar, the ink.

What ``ttt-sm draw``, ``ttt-sm demo`` and ``ttt-sm play`` write for a person
to look at.  It is not the simulated camera's photograph (that one is
:meth:`~ttt_sm.twin.whiteboard.Whiteboard.render` under a camera model, and
the vision tests depend on it; this module only calls ``render``).

The picture shows the board from above with the robot at the bottom, as the
thesis' fig. 3.26 does: x to the right, y up (away from the robot), so cell
(1, 1) at ``(x11, y11)``, "the upper right corner of the playing field"
(eqs. 3.37-3.38), is at the top right; rows are counted downwards towards
the robot, columns from right to left.  Every cell carries its label
"(row, column)", so nobody has to work the numbering out.  It is cropped to
the field with a margin, grown to take in any ink beyond it (a stray mark is
never cut off), and drawn at a fixed scale (``PX_PER_MM``) with a scale bar.
docs/whiteboard.md shows one.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..files import save_figure
from .whiteboard import HAND_INK_BGR, ROBOT_INK_BGR, Region, Whiteboard

if TYPE_CHECKING:
    from matplotlib.figure import Figure

#: Board shown around the field, m.
FIELD_MARGIN_M = 0.012
#: Board shown around ink beyond the field's margin, m.
INK_MARGIN_M = 0.004
#: Image pixels per millimetre of board in the saved picture.
PX_PER_MM = 5.0
#: Length of the scale bar, mm.
SCALE_BAR_MM = 10.0
#: Figure resolution, dots per inch: with PX_PER_MM the board is drawn at one image pixel per picture pixel.
DPI = 100
#: The field's nominal lines (grey, dashed) and its outer edge (lighter, dotted), RGB.
FIELD_LINE_RGB = (0.68, 0.68, 0.68)
FIELD_EDGE_RGB = (0.8, 0.8, 0.8)
LABEL_RGB = (0.45, 0.45, 0.45)


def crop_region(board: Whiteboard, margin_m: float = FIELD_MARGIN_M) -> Region:
    """(x_min, x_max, y_min, y_max) of the board a picture shows, m.

    The field with `margin_m` around it, grown to hold every inked pixel
    (with ``INK_MARGIN_M``), within the board, and widened to whole raster
    pixels so that the picture's scale is exact.
    """
    fx0, fx1, fy0, fy1 = board.params.board.field_bounds()
    x0, x1, y0, y1 = fx0 - margin_m, fx1 + margin_m, fy0 - margin_m, fy1 + margin_m
    ink = board.pixel_centers_m(board.ink_mask())
    if len(ink):
        lo = ink.min(axis=0) - INK_MARGIN_M
        hi = ink.max(axis=0) + INK_MARGIN_M
        x0, x1, y0, y1 = min(x0, lo[0]), max(x1, hi[0]), min(y0, lo[1]), max(y1, hi[1])
    bx0, bx1, by0, by1 = board.extent
    res = board.resolution_m

    def snap(v: float, origin: float, up: bool) -> float:
        k = (v - origin) / res
        return origin + (math.ceil(k - 1e-9) if up else math.floor(k + 1e-9)) * res

    return (snap(max(x0, bx0), bx0, False), snap(min(x1, bx1), bx0, True),
            snap(max(y0, by0), by0, False), snap(min(y1, by1), by0, True))


def _rgb(bgr: tuple[int, int, int]) -> tuple[float, float, float]:
    return (bgr[2] / 255, bgr[1] / 255, bgr[0] / 255)


def _ink_over_white(bgr: np.ndarray) -> np.ndarray:
    """RGBA of a rendered board: its colours, opaque where inked, transparent where white."""
    darkest = min(*ROBOT_INK_BGR, *HAND_INK_BGR)
    alpha = np.clip((255.0 - bgr.min(axis=2)) / (255.0 - darkest), 0.0, 1.0)
    return np.dstack((bgr[:, :, ::-1] / 255.0, alpha))


def board_figure(board: Whiteboard, title: str, subtitle: str = "", grid_mm: bool = False,
                 desired: Sequence[np.ndarray] = ()) -> Figure:
    """The picture of the board as a matplotlib figure, in millimetres of the global frame.

    Parameters
    ----------
    board : Whiteboard
        The board, with whatever ink it holds.
    title : str
        What the picture is (the drawing, its cell, its speed ...).
    subtitle : str
        A second, smaller line (the seed, the run).
    grid_mm : bool
        Millimetre paper under the ink (1, 5 and 10 mm lines), as the thesis' figs. 3.19-3.20.
    desired : sequence of ndarray, shape (n, 2)
        Desired pen-down paths (x, y in m), drawn as thin black lines over the ink (the thesis' black
        lines beside the drawn red ones).

    Returns
    -------
    matplotlib.figure.Figure
        One axes: the board image with ``extent`` = :func:`crop_region` in mm,
        the field's lines, the cell labels, the scale bar (``gid="scale_bar"``)
        and a legend.
    """
    from matplotlib.artist import Artist
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    x0, x1, y0, y1 = crop_region(board)
    res = board.resolution_m
    # a quarter pixel inside the pixel-aligned crop: render takes exactly those raster pixels
    image = board.render(px_per_mm=PX_PER_MM, region=(x0 + res / 4, x1 - res / 4, y0 + res / 4, y1 - res / 4),
                         view="above", grid_mm=grid_mm)
    h_px, w_px = image.shape[:2]
    authors = {s.author for s in board.strokes}
    handles: list[Artist] = [Line2D([], [], color=FIELD_LINE_RGB, ls=(0, (4, 4)), lw=0.8,
                      label="where the field's lines go: the cell edges, 3 cm apart"),
               Line2D([], [], color=FIELD_EDGE_RGB, ls=":", lw=0.8, label="the field's outer edge (never drawn)")]
    if "robot" in authors:
        handles.append(Patch(color=_rgb(ROBOT_INK_BGR), label="the robot's ink (where the true pen tip touched)"))
    if "hand" in authors:
        handles.append(Patch(color=_rgb(HAND_INK_BGR), label="the person's ink"))
    if len(desired):
        handles.append(Line2D([], [], color="k", lw=0.6, label="the desired paths (pen down)"))
    if grid_mm:
        handles.append(Patch(facecolor="white", edgecolor="0.6", label="millimetre paper: lines every 1, 5, 10 mm"))
    # the legend's rows (two entries each) and its title below the axes: the bottom margin grows with them
    left_in, right_in, bottom_in, top_in = 0.75, 0.25, 0.8 + 0.175 * math.ceil(len(handles) / 2), 0.75
    fig = Figure(figsize=(w_px / DPI + left_in + right_in, h_px / DPI + bottom_in + top_in), dpi=DPI)
    fw, fh = fig.get_size_inches()
    ax = fig.add_axes((left_in / fw, bottom_in / fh, w_px / DPI / fw, h_px / DPI / fh))
    mm = (x0 * 1e3, x1 * 1e3, y0 * 1e3, y1 * 1e3)
    # "above": row 0 of the image is the largest y, so the image's top edge is y1.  The white
    # board is made transparent so that the field's lines, drawn on the white axes, lie under the ink.
    ax.imshow(_ink_over_white(image), extent=mm, origin="upper", interpolation="antialiased", zorder=1)
    ax.set_facecolor("white")
    ax.set_xlim(mm[0], mm[1])
    ax.set_ylim(mm[2], mm[3])
    ax.set_aspect("equal")

    b = board.params.board
    fx0, fx1, fy0, fy1 = (v * 1e3 for v in b.field_bounds())
    L = b.cell_size * 1e3
    for k in range(1, b.cells):  # the 4 + 4 lines the Control chart draws (Drawing_playing_field)
        ax.plot([fx0, fx1], [fy1 - k * L] * 2, color=FIELD_LINE_RGB, ls=(0, (4, 4)), lw=0.8, zorder=0.5)
        ax.plot([fx1 - k * L] * 2, [fy0, fy1], color=FIELD_LINE_RGB, ls=(0, (4, 4)), lw=0.8, zorder=0.5)
    ax.plot([fx0, fx1, fx1, fx0, fx0], [fy0, fy0, fy1, fy1, fy0], color=FIELD_EDGE_RGB, ls=":", lw=0.8,
            zorder=0.5)
    for row in range(1, b.cells + 1):
        for column in range(1, b.cells + 1):
            cx0, _, _, cy1 = (v * 1e3 for v in board.cell_bounds(row, column))
            ax.text(cx0 + 1.2, cy1 - 1.2, f"({row}, {column})", ha="left", va="top", fontsize=8,
                    color=LABEL_RGB, zorder=3, gid=f"cell_{row}_{column}")

    for run in desired:
        ax.plot(run[:, 0] * 1e3, run[:, 1] * 1e3, color="k", lw=0.6, zorder=3.5)

    # scale bar in the bottom left margin, on a white ground so it reads over any ink
    sx, sy = mm[0] + 3.0, mm[2] + 3.0
    ax.plot([sx, sx + SCALE_BAR_MM], [sy, sy], color="k", lw=3, solid_capstyle="butt", zorder=4, gid="scale_bar")
    ax.text(sx + SCALE_BAR_MM / 2, sy + 1.0, f"{SCALE_BAR_MM:g} mm", ha="center", va="bottom", fontsize=8,
            zorder=4, bbox={"facecolor": "white", "edgecolor": "none", "pad": 0.5})

    ax.set_xlabel("x (mm)", fontsize=9)
    ax.set_ylabel("y (mm): away from the robot", fontsize=9)
    ax.tick_params(labelsize=8)
    ax.set_title(title, fontsize=11, loc="left", pad=18 if subtitle else 6)
    if subtitle:
        ax.text(0.0, 1.01, subtitle, transform=ax.transAxes, ha="left", va="bottom", fontsize=8.5, color="0.3")

    base_mm = y0 * 1e3  # the base axis stands at y = 0 (docs/kinematics.md)
    fig.legend(handles=handles, loc="lower left", bbox_to_anchor=(left_in / fw, 0.01), ncol=2, fontsize=8,
               frameon=False,
               title=f"Seen from above, the robot at the bottom (thesis fig. 3.26); its base is {base_mm:.0f} mm "
                     "below the lower edge. Labels: (row, column), eqs. 3.37-3.38.",
               title_fontsize=8, alignment="left")
    return fig


def save_board_picture(board: Whiteboard, path: str | Path, title: str, subtitle: str = "", grid_mm: bool = False,
                       desired: Sequence[np.ndarray] = ()) -> Path:
    """Write :func:`board_figure` to a PNG file; returns the path."""
    p = Path(path)
    p.parent.mkdir(parents=True, exist_ok=True)
    return save_figure(board_figure(board, title, subtitle, grid_mm, desired), p)


__all__ = ["crop_region", "board_figure", "save_board_picture", "PX_PER_MM", "SCALE_BAR_MM"]
