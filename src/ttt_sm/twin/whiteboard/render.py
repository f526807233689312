"""Pictures of the board: the ink raster as a BGR image, optionally on millimetre paper.

The thesis shows its drawings on millimetre paper (figs. 3.19-3.20); the
views say which way the image lies on the board (docs/whiteboard.md).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from ... import files
from .errors import WhiteboardError
from .raster import InkRaster, Region

#: Ink colours (BGR) in :func:`render`, by author.
ROBOT_INK_BGR = (110, 35, 10)
HAND_INK_BGR = (25, 25, 25)
DESIRED_BGR = (40, 40, 220)
#: Millimetre paper (figs. 3.19-3.20): 1 mm, 5 mm and 10 mm lines (BGR).
GRID_BGR = ((205, 228, 250), (150, 195, 245), (95, 155, 235))

#: Image orientations of :func:`render`: view -> (flip rows, flip columns)
#: of the raster, whose row index grows with y and column index with x.
VIEWS = {
    "field": (True, True),      # row 1 at the top, column 1 at the left: x grows left, y up
    "above": (True, False),     # from above, robot at the bottom: x grows right, y up (fig. 3.26)
    "far_edge": (False, True),  # a camera beyond the far edge, facing the robot: x left, y down
}


def render(raster: InkRaster, px_per_mm: float = 4.0, grid_mm: bool = False, region: Region | None = None, *,
           view: str = "field", desired: Sequence[Any] | None = None) -> np.ndarray:
    """Draw the board as a BGR image: white board, dark blue robot ink, black hand ink.

    Parameters
    ----------
    raster : InkRaster
        The board's ink.
    px_per_mm : float
        Image pixels per millimetre of board.
    grid_mm : bool
        Millimetre paper under the ink (1, 5 and 10 mm lines), as the
        thesis' figs. 3.19-3.20.
    region : (x_min, x_max, y_min, y_max), optional
        Part of the board to draw, m (default the whole board).
    view : str
        ``"field"`` (default): row 1 of the field at the top, column 1 at
        the left, so cell (1, 1) at ``(x11, y11)`` is the top-left cell:
        x grows to the image's left and y upwards.  This is the board
        seen from below, through it (a mirror image of the view from
        above), chosen so that the image reads like the board as text.
        ``"above"``: from above with the robot at the bottom (x right,
        y up, as the thesis' fig. 3.26: cell (1, 1) top right).
        ``"far_edge"``: a camera beyond the far edge facing the robot
        (x left, y down: cell (1, 1) bottom left).
    desired : sequence of array_like (N, 2), optional
        Desired paths (m), drawn 1 px wide in red over the ink.

    Returns
    -------
    np.ndarray, uint8, shape (H, W, 3)
    """
    if view not in VIEWS:
        raise WhiteboardError(f"view must be one of {sorted(VIEWS)}, got {view!r}")
    if not 0.05 <= px_per_mm <= 50.0:
        raise WhiteboardError(f"px_per_mm must lie in [0.05, 50], got {px_per_mm!r}")
    res = raster.res
    rows, cols = raster.slices(region)
    sub = raster.ink[rows, cols]
    i0 = cols.start or 0
    j0 = rows.start or 0
    rx0, ry0 = raster.x0 + i0 * res, raster.y0 + j0 * res
    px_per_m = px_per_mm * 1e3
    W = max(1, round(sub.shape[1] * res * px_per_m))
    H = max(1, round(sub.shape[0] * res * px_per_m))
    out = np.full((H, W, 3), 255, np.uint8)  # rows along +y, columns along +x for now
    if grid_mm:
        draw_grid(out, rx0, ry0, px_per_m)
    # INTER_AREA averages properly when shrinking a lot; near 1:1 it is slow and
    # INTER_LINEAR looks the same
    interp = cv2.INTER_AREA if px_per_m * res < 1 / 1.5 else cv2.INTER_LINEAR
    if sub.any():
        # coverage by robot and by hand ink (0..255) of every image pixel, in one resize
        # (cv2.compare writes 255 where equal: one pass over the raster per author)
        by_robot = cv2.compare(sub, 1, cv2.CMP_EQ)  # type: ignore[call-overload]
        by_hand = cv2.compare(sub, 2, cv2.CMP_EQ)  # type: ignore[call-overload]
        two = cv2.merge([by_robot, by_hand])
        cover = cv2.resize(two, (W, H), interpolation=interp)
        at = cv2.findNonZero(cv2.bitwise_or(cover[:, :, 0], cover[:, :, 1]))
        if at is not None:  # blend only where there is ink: a few % of the image
            at = at.reshape(-1, 2)
            xs, ys = at[:, 0], at[:, 1]
            c = cover[ys, xs].astype(np.float32) / 255.0
            under = out[ys, xs].astype(np.float32)
            blended = (under * (1.0 - np.minimum(c.sum(axis=1, keepdims=True), 1.0))
                       + c[:, :1] * np.asarray(ROBOT_INK_BGR, np.float32)
                       + c[:, 1:] * np.asarray(HAND_INK_BGR, np.float32))
            out[ys, xs] = np.clip(blended + 0.5, 0, 255).astype(np.uint8)
    if desired is not None:
        lines = []
        for line in desired:
            p = np.asarray(line, dtype=float)
            u = (p[:, 0] - rx0) * px_per_m - 0.5
            v = (p[:, 1] - ry0) * px_per_m - 0.5
            lines.append(np.round(np.column_stack((u, v)) * 16).astype(np.int32))
        cv2.polylines(out, lines, False, DESIRED_BGR, 1, cv2.LINE_AA, shift=4)
    flip_rows, flip_cols = VIEWS[view]
    if flip_rows or flip_cols:  # cv2.flip: 0 flips rows, 1 columns, -1 both
        out = cv2.flip(out, -1 if flip_rows and flip_cols else (0 if flip_rows else 1))
    return out


def draw_grid(img: np.ndarray, rx0: float, ry0: float, px_per_m: float) -> None:
    """Millimetre paper: lines at whole millimetres of the global frame."""
    H, W = img.shape[:2]
    for every, colour in zip((1, 5, 10), GRID_BGR, strict=True):
        if every == 1 and px_per_m < 3e3:
            continue  # 1 mm lines closer than 3 px would paint the paper solid
        step = every * 1e-3
        for size, origin, axis in ((W, rx0, 1), (H, ry0, 0)):
            first = math.ceil(origin / step - 1e-9)
            last = math.floor((origin + size / px_per_m) / step + 1e-9)
            at = np.round((np.arange(first, last + 1) * step - origin) * px_per_m - 0.5)
            at = at[(at >= 0) & (at < size)].astype(int)
            if axis == 1:
                img[:, at] = colour
            else:
                img[at, :] = colour


def write_png(image: np.ndarray, path: str | Path) -> Path:
    """Write an image to a PNG file; returns the path."""
    p = Path(path)
    try:
        return files.write_png(p, image)  # whole, or not there (a full disk)
    except ValueError:
        raise WhiteboardError(f"{p}: could not encode the PNG") from None
