"""Reading the board from a photo: which cells hold a symbol (thesis section 3.6.3).

The thesis' smart camera counts, in each of 25 fixed regions (fig. 3.33),
the share of pixels darker than a fixed grey level (80, fig. 3.32); a cell
with enough dark pixels holds a symbol.  Here the same per-cell share is
measured, but

* the **regions are not fixed**: the drawn field is located in every photo
  (:func:`ttt_sm.vision.grid.locate_grid`) and each cell is measured in the
  field rectified to a square, minus a margin along the grid lines;
* the **threshold is relative**: each pixel is compared with its local
  background (a morphological closing, which fills strokes thinner than
  :data:`BACKGROUND_PX` but follows lighting gradients and shadows), so a
  dim corner of the board does not read as ink.  A fixed level fails there:
  a board lit at 30 % is darker than 80 everywhere (see :func:`fixed_level_percentages`);
* X and O are told apart: an X's strokes cross at its centre, an O leaves
  its centre empty.

Cells are reported as the image shows them: row 1 at the top of the image,
column 1 at its left.  :mod:`ttt_sm.vision.orientation` maps them to the
board's (row, column) for a camera placement.
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np

from .camera import check_image
from .grid import Grid, locate_grid

#: Images are analysed at this width (larger ones are shrunk first), pixels.
WORK_WIDTH = 640
#: Side of the closing that estimates the clean board under the ink, pixels at the working
#: width: wider than any stroke (2-5 px), narrower than a shadow's or a lamp's gradient.
BACKGROUND_PX = 11
#: A pixel is ink when it is darker than this share of its local background, in 1/255
#: (the thesis' "value of detecting a gray colour", made relative: 225 is 12 % darker).
#: A blurred 0.8 mm robot line is only 15-30 % darker than the board; the noise of a
#: dim corner stays within a few %.  The same level finds the grid and measures the cells.
INK_LEVEL = 225
#: Side of a cell in the rectified field, pixels.
CELL_PX = 48
#: Share of a cell's side kept clear along each grid line when measuring it (0.12: 3.6 mm).
CELL_MARGIN = 0.12
#: A cell whose ink share exceeds this holds a symbol, percent (empty cells read < 1 %,
#: the robot's thin X or O 17-30 % once blurred, a person's 20-30 %).
OCCUPIED_PCT = 5.0
#: Radius of the disc around a symbol's ink centroid that tells X from O, share of a cell.
CENTRE_RADIUS = 0.1
#: An X's strokes cross at its centre: more than this share of that disc is inked.
X_CENTRE_SHARE = 0.15
#: Fixed grey level of the thesis' smart camera (fig. 3.32), for comparison only.
THESIS_GREY_LEVEL = 80

N = 5


@dataclass(frozen=True, eq=False)  # eq on arrays is ambiguous
class Detection:
    """What the camera saw on the field.

    Attributes
    ----------
    cells : str
        25 characters, row-major as the image shows the field (row 1 at
        the top, column 1 at the left): ``.`` empty, ``X`` or ``O``, ``#``
        occupied by something that is neither clearly.
    percentages : tuple[float, ...]
        25 ink shares, percent, same order (the thesis' per-cell percentages).
    centre_shares : tuple[float, ...]
        25 ink shares of the disc at each symbol's centre (0..1; 0 for an
        empty cell), what told X from O.
    grid : Grid
        The located field: homography image -> field (cells), corners.
    time_ms : float
        Wall time of :func:`detect`, milliseconds.
    """

    cells: str
    percentages: tuple[float, ...]
    centre_shares: tuple[float, ...]
    grid: Grid
    time_ms: float

    @property
    def occupied(self) -> tuple[bool, ...]:
        """25 flags: the cell holds a symbol (image order)."""
        return tuple(c != "." for c in self.cells)

    def cell(self, row: int, column: int) -> str:
        """The character of image cell (row, column), 1-based (row 1 at the top)."""
        return self.cells[(row - 1) * N + (column - 1)]

    def text(self) -> str:
        """The cells as five lines of five characters (image order)."""
        return "\n".join(self.cells[r * N:(r + 1) * N] for r in range(N))

    def to_dict(self) -> dict[str, Any]:
        """Plain data for JSON: cells, percentages, the grid's corners and homography, time."""
        return {
            "cells": self.cells,
            "rows": [self.cells[r * N:(r + 1) * N] for r in range(N)],
            "percentages": [round(p, 2) for p in self.percentages],
            "centre_shares": [round(s, 3) for s in self.centre_shares],
            "corners_px": np.round(self.grid.corners, 2).tolist(),
            "homography": self.grid.homography.tolist(),
            "rms_cells": round(self.grid.rms_cells, 4),
            "time_ms": round(self.time_ms, 3),
        }


def _grey(image: np.ndarray) -> np.ndarray:
    """The darkest channel: coloured and black markers both read dark; the white board does not."""
    if image.ndim == 2:
        return image
    b, g, r = cv2.split(image)
    return cv2.min(cv2.min(b, g), r)


def ink_image(image: np.ndarray) -> np.ndarray:
    """The photo with its lighting divided out: 255 is clean board, ink is dark.

    Parameters
    ----------
    image : np.ndarray
        BGR or grey uint8 at the working width (see :func:`detect`).

    Returns
    -------
    np.ndarray, uint8, same height and width
        ``255 * pixel / background``, the background being a closing of
        side :data:`BACKGROUND_PX` of the lightly smoothed darkest channel.
    """
    grey = cv2.GaussianBlur(_grey(image), (3, 3), 0)
    kernel = cv2.getStructuringElement(cv2.MORPH_RECT, (BACKGROUND_PX, BACKGROUND_PX))
    background = cv2.morphologyEx(grey, cv2.MORPH_CLOSE, kernel)
    return cv2.divide(grey, background, scale=255)


def working_image(image: np.ndarray) -> tuple[np.ndarray, float]:
    """The image at the working width, and the factor back to the original's pixels."""
    h, w = image.shape[:2]
    if w <= WORK_WIDTH:
        return image, 1.0
    f = WORK_WIDTH / w
    return cv2.resize(image, (WORK_WIDTH, max(1, round(h * f))), interpolation=cv2.INTER_AREA), w / WORK_WIDTH


def rectify(image: np.ndarray, grid: Grid, cell_px: int = CELL_PX, *, border: int = 255) -> np.ndarray:
    """The field warped to a square of 5 x `cell_px` pixels (image orientation kept)."""
    S = np.diag([float(cell_px), float(cell_px), 1.0]) @ grid.homography
    side = N * cell_px
    value: Any = border if image.ndim == 2 else (border,) * image.shape[2]
    return cv2.warpPerspective(image, S, (side, side), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT,
                               borderValue=value)


def cell_shares(ink: np.ndarray, cell_px: int = CELL_PX, margin: float = CELL_MARGIN) -> np.ndarray:
    """Ink share (0..1) of each cell of a rectified ink mask (bool, 5 cell_px square), shape (5, 5)."""
    m = int(round(margin * cell_px))
    cells = ink.reshape(N, cell_px, N, cell_px)[:, m:cell_px - m, :, m:cell_px - m]
    return cells.mean(axis=(1, 3))


@functools.cache
def _pixel_grid(h: int, w: int) -> tuple[np.ndarray, np.ndarray]:
    v, u = np.indices((h, w), dtype=np.float32)
    return u, v


def centre_share(cell_ink: np.ndarray, radius_px: float) -> float:
    """Share of the disc of `radius_px` around the ink's centroid that is inked (0 without ink)."""
    mom = cv2.moments(cell_ink.view(np.uint8), binaryImage=True)
    if mom["m00"] == 0:
        return 0.0
    cx, cy = mom["m10"] / mom["m00"], mom["m01"] / mom["m00"]
    u, v = _pixel_grid(*cell_ink.shape)
    disc = (u - np.float32(cx)) ** 2 + (v - np.float32(cy)) ** 2 <= np.float32(radius_px ** 2)
    n = int(np.count_nonzero(disc))
    return float(np.count_nonzero(cell_ink & disc)) / n if n else 0.0


def detect(image: Any, *, occupied_pct: float = OCCUPIED_PCT, tell_symbols: bool = True) -> Detection:
    """Locate the field in a photo and read every cell (thesis 3.6.3, without fixed regions).

    Parameters
    ----------
    image : np.ndarray
        BGR (or grey) uint8 photo, 320 x 240 to 4096 x 3072 (640 x 480
        expected); larger ones are shrunk to :data:`WORK_WIDTH` first.
    occupied_pct : float
        Ink share above which a cell holds a symbol, percent.
    tell_symbols : bool
        Tell X from O (else every occupied cell is ``#``).

    Returns
    -------
    Detection
        Cells in image order (row 1 at the top, column 1 at the left).

    Raises
    ------
    ImageError
        Not a uint8 image of a usable shape and size.
    GridNotFoundError
        The field could not be located, or part of it lies outside the picture.
    """
    t0 = time.perf_counter()
    image = check_image(image)
    work, scale = working_image(image)
    norm = ink_image(work)
    _, ink = cv2.threshold(norm, INK_LEVEL - 1, 255, cv2.THRESH_BINARY_INV)  # norm < INK_LEVEL
    grid = locate_grid(ink)
    field = rectify(norm, grid) < INK_LEVEL
    shares = cell_shares(field)
    pct = shares.ravel() * 100.0
    chars, centres = [], []
    m = int(round(CELL_MARGIN * CELL_PX))
    for k in range(N * N):
        if pct[k] <= occupied_pct:
            chars.append(".")
            centres.append(0.0)
            continue
        r, col = divmod(k, N)
        cell = field[r * CELL_PX + m:(r + 1) * CELL_PX - m, col * CELL_PX + m:(col + 1) * CELL_PX - m]
        s = centre_share(cell, CENTRE_RADIUS * CELL_PX)
        centres.append(s)
        chars.append(("X" if s > X_CENTRE_SHARE else "O") if tell_symbols else "#")
    if scale != 1.0:
        grid = grid.scaled(scale)
    return Detection("".join(chars), tuple(float(p) for p in pct), tuple(centres), grid,
                     (time.perf_counter() - t0) * 1e3)


def fixed_level_percentages(image: Any, grid: Grid, level: int = THESIS_GREY_LEVEL) -> np.ndarray:
    """The thesis' measure: per-cell share of grey pixels darker than a fixed `level`, percent, shape (25,).

    Given the (located) grid, so that only the threshold differs from
    :func:`detect`: under a lighting gradient the dim cells read full.
    """
    image = check_image(image)
    grey = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY) if image.ndim == 3 else image
    field = rectify(grey, grid, border=255) < level
    return cell_shares(field).ravel() * 100.0
