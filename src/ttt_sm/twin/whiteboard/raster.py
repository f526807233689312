"""The ink raster: which pixel of the board holds ink, whose, and when it was last wiped.

The raster covers the board (``[board]`` of the parameter file) in square
pixels of ``res`` metres.  ``ink[iy, ix]`` is 0 (clean) or the author's code
(:data:`AUTHOR_CODES`); ``stamp[iy, ix]`` is the update sequence number of
the pixel's last wipe, which is how a stroke learns which of its points a
later sponge pass removed (:mod:`.strokes`).  Pixel centres lie at
``(x0 + (ix + 0.5) res, y0 + (iy + 0.5) res)``.  The compiled kernels that
paint and wipe it are in :mod:`ttt_sm.twin._ink`.
"""

from __future__ import annotations

import math

import numpy as np

from ttt_sm.twin._ink import ink_capsule, wipe_sweep

from .errors import WhiteboardError

#: (x_min, x_max, y_min, y_max), m: a rectangle on the board.
Region = tuple[float, float, float, float]

#: Raster value of each author's ink.
AUTHOR_CODES = {"robot": 1, "hand": 2}


def _load_kernels(ink: np.dtype, stamp: np.dtype) -> None:
    """Load the compiled ink and wipe kernels now (numba's disk cache), not when the pen first
    touches: on a scratch raster, with the argument types the board passes."""
    raster, stamps = np.zeros((2, 2), ink), np.zeros((2, 2), stamp)
    ink_capsule(raster, 0.0, 0.0, 1.0, 0.5, 0.5, 0.5, 0.5, 0.1, 1)
    wipe_sweep(raster, stamps, 0.0, 0.0, 1.0, 0.1, 0.5, 0.5, 1.0, 0.0, 0.5, 0.5, 1.0, 0.0, False, 1)


class InkRaster:
    """The board as pixels: ink by author, and the sequence number of each pixel's last wipe.

    Parameters
    ----------
    x0, y0 : float
        The board's corner with the smallest x and y, m.
    width, depth : float
        The board's size along x and y, m.
    res : float
        Side of one pixel, m.
    """

    def __init__(self, x0: float, y0: float, width: float, depth: float, res: float) -> None:
        nx, ny = int(round(width / res)), int(round(depth / res))
        self.res = res
        self.x0, self.y0 = x0, y0
        self.x1, self.y1 = x0 + nx * res, y0 + ny * res
        self.ink = np.zeros((ny, nx), np.uint8)
        self.stamp = np.zeros((ny, nx), np.int32)  # sequence number of each pixel's last wipe
        _load_kernels(self.ink.dtype, self.stamp.dtype)

    def clear(self) -> None:
        """No ink, no wipes (in place: the contact physics holds the same arrays)."""
        self.ink[:] = 0
        self.stamp[:] = 0

    @property
    def extent(self) -> Region:
        """(x_min, x_max, y_min, y_max) the raster covers, m."""
        return (self.x0, self.x1, self.y0, self.y1)

    @property
    def shape(self) -> tuple[int, int]:
        """Raster shape (rows along y, columns along x)."""
        ny, nx = self.ink.shape
        return (ny, nx)

    def slices(self, region: Region | None) -> tuple[slice, slice]:
        """Raster rows and columns whose pixel centres lie in `region` (default: all)."""
        if region is None:
            return slice(None), slice(None)
        x_lo, x_hi, y_lo, y_hi = (float(v) for v in region)
        if not (x_lo < x_hi and y_lo < y_hi):
            raise WhiteboardError(f"region must be (x_min, x_max, y_min, y_max) with min < max, "
                                  f"got {region!r}")
        ny, nx = self.ink.shape
        i0 = max(0, math.ceil((x_lo - self.x0) / self.res - 0.5))
        i1 = min(nx - 1, math.floor((x_hi - self.x0) / self.res - 0.5))
        j0 = max(0, math.ceil((y_lo - self.y0) / self.res - 0.5))
        j1 = min(ny - 1, math.floor((y_hi - self.y0) / self.res - 0.5))
        if i0 > i1 or j0 > j1:
            raise WhiteboardError(f"region {region!r} does not overlap the board {self.extent!r}")
        return slice(j0, j1 + 1), slice(i0, i1 + 1)

    def pixel_centers_m(self, mask: np.ndarray) -> np.ndarray:
        """(x, y) in metres of the True pixels of a raster-shaped mask, shape (N, 2)."""
        iy, ix = np.nonzero(mask)
        return np.column_stack((self.x0 + (ix + 0.5) * self.res, self.y0 + (iy + 0.5) * self.res))

    def pixels_of(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Row and column indices of the pixels holding points (x, y), m (clipped to the raster)."""
        ny, nx = self.ink.shape
        ix = np.clip(((x - self.x0) / self.res).astype(np.int64), 0, nx - 1)
        iy = np.clip(((y - self.y0) / self.res).astype(np.int64), 0, ny - 1)
        return iy, ix
