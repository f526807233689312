"""What the ink measures: inked area, ink outside a desired path, the longest tail, a cell's share.

Plain functions of an :class:`~.raster.InkRaster`; the
:class:`~ttt_sm.twin.whiteboard.Whiteboard` offers each as a method.  The
precision figures of the drawing (docs/drawing.md) and the tests of the
charts' drawings are made of them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import cv2
import numpy as np

from ttt_sm.twin._ink import ink_polyline

from .errors import WhiteboardError
from .raster import InkRaster, Region

#: Margin kept clear of the grid lines when measuring a cell's ink (m).
CELL_MARGIN_M = 3e-3
#: Default tolerance band around a desired path for :func:`longest_tail_mm` (m).
TAIL_TOL_M = 1e-3


def ink_area_mm2(raster: InkRaster, region: Region | None = None) -> float:
    """Inked area, mm^2, of the board or of a region (x_min, x_max, y_min, y_max) in m."""
    rows, cols = raster.slices(region)
    return float(np.count_nonzero(raster.ink[rows, cols])) * (raster.res * 1e3) ** 2


def ink_outside(raster: InkRaster, polylines: Sequence[Any], tol_m: float) -> np.ndarray:
    """Ink pixels farther than `tol_m` from every desired polyline.

    Parameters
    ----------
    raster : InkRaster
        The board.
    polylines : sequence of array_like, each shape (N, 2)
        Desired paths, metres.
    tol_m : float
        Half-width of the tolerance band around them, m.

    Returns
    -------
    np.ndarray, bool, shape of the raster
        Pen-lift and pen-lower tails, stray marks;
        :meth:`InkRaster.pixel_centers_m` turns it into coordinates.
    """
    if not tol_m >= 0.0:
        raise WhiteboardError(f"tol_m must be >= 0, got {tol_m!r}")
    band = np.zeros_like(raster.ink)
    for line in polylines:
        p = np.asarray(line, dtype=float)
        if p.ndim != 2 or p.shape[1] != 2 or len(p) < 1:
            raise WhiteboardError(f"each polyline must have shape (N, 2), got {p.shape}")
        ink_polyline(band, raster.x0, raster.y0, raster.res, np.ascontiguousarray(p[:, 0]),
                     np.ascontiguousarray(p[:, 1]), float(tol_m), 1)
    return (raster.ink != 0) & (band == 0)


def longest_tail_mm(raster: InkRaster, desired_polylines: Sequence[Any], tol_m: float = TAIL_TOL_M) -> float:
    """Length of the longest connected run of ink outside the tolerance band, mm.

    The length of a run is its Feret diameter (largest distance between
    two of its pixel centres); only the part beyond `tol_m` from the
    desired path counts.  0.0 when all ink lies within the band.
    """
    outside = ink_outside(raster, desired_polylines, tol_m).astype(np.uint8)
    n, labels, stats, _ = cv2.connectedComponentsWithStats(outside, connectivity=8)
    if n <= 1:
        return 0.0
    iy, ix = np.nonzero(labels)
    lab = labels[iy, ix]
    order = np.argsort(lab, kind="stable")
    bounds = np.searchsorted(lab[order], np.arange(1, n + 1))
    best = 0.0
    for k in np.argsort(-np.hypot(stats[1:, cv2.CC_STAT_WIDTH], stats[1:, cv2.CC_STAT_HEIGHT])) + 1:
        if math.hypot(stats[k, cv2.CC_STAT_WIDTH], stats[k, cv2.CC_STAT_HEIGHT]) <= best:
            break  # no smaller bounding box can hold a longer run
        sel = order[bounds[k - 1]:bounds[k]]
        pts = np.column_stack((ix[sel], iy[sel])).astype(np.int32)
        hull = cv2.convexHull(pts).reshape(-1, 2).astype(float)
        d = np.hypot(hull[:, None, 0] - hull[None, :, 0], hull[:, None, 1] - hull[None, :, 1])
        best = max(best, float(d.max()))
    return best * raster.res * 1e3


def cell_ink_fraction(raster: InkRaster, cell: Region, margin_m: float = CELL_MARGIN_M) -> float:
    """Share of a cell (x_min, x_max, y_min, y_max, m) that is inked, leaving `margin_m` clear of its grid lines."""
    x_lo, x_hi, y_lo, y_hi = cell
    if not 0.0 <= margin_m < (x_hi - x_lo) / 2:
        raise WhiteboardError(f"margin_m must lie in [0, half a cell), got {margin_m!r}")
    rows, cols = raster.slices((x_lo + margin_m, x_hi - margin_m, y_lo + margin_m, y_hi - margin_m))
    part = raster.ink[rows, cols]
    return float(np.count_nonzero(part)) / part.size
