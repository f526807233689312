"""The person's hand: a path with a slow seeded wobble, and an X or an O inside a cell.

Plain functions: they take the seeded generator of the board and return
paths in metres; :meth:`~ttt_sm.twin.whiteboard.Whiteboard.draw_stroke`
inks them.  The draws from the generator come in a fixed order, so a
board's seed reproduces its hand strokes.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .errors import WhiteboardError
from .raster import InkRaster, Region

#: Default line width of the person's marker (m): a hand presses a fresh marker harder.
HAND_INK_WIDTH_M = 1.5e-3
#: Amplitude of the slow wobble of a hand stroke (m), see :func:`hand_path`.
HAND_JITTER_M = 0.4e-3
#: Speed a hand stroke is timed with (m/s); only its point times depend on it.
HAND_SPEED_M_S = 0.1


def hand_path(points_m: Any, raster: InkRaster, width_mm: float, jitter_mm: float,
              rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """The path a hand draws along `points_m`, checked against the board.

    Parameters
    ----------
    points_m : array_like, shape (N, 2)
        The intended path, x and y in metres, on the board.
    raster : InkRaster
        The board (its extent and pixel size).
    width_mm : float
        Line width of the marker, mm (at least 1.5 pixels).
    jitter_mm : float
        Amplitude of the wobble, mm: two sinusoids per axis along the arc
        length (wavelengths 12-30 mm and 3-7 mm, seeded phases), like an
        unsteady hand.  0 keeps the path exact.
    rng : numpy.random.Generator
        Draws the wavelengths and phases.

    Returns
    -------
    xs, ys : np.ndarray, shape (M,)
        The path densified to one point per half pixel (so that wobble and
        wipes resolve along it), jittered, kept on the board; m.
    s : np.ndarray, shape (M,)
        Arc length of the intended path at each point, m.
    width_m : float
        The line width, m.
    """
    pts = np.asarray(points_m, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 1:
        raise WhiteboardError(f"points_m must have shape (N, 2) with N >= 1, got {pts.shape}")
    if not np.isfinite(pts).all():
        raise WhiteboardError("points_m must be finite")
    x0, x1, y0, y1 = raster.extent
    if (pts[:, 0].min() < x0 or pts[:, 0].max() > x1 or pts[:, 1].min() < y0
            or pts[:, 1].max() > y1):
        raise WhiteboardError(f"points_m must lie on the board x in [{x0:.3f}, {x1:.3f}] m, "
                              f"y in [{y0:.3f}, {y1:.3f}] m")
    res = raster.res
    width_m = width_mm * 1e-3
    if not width_m >= 1.5 * res:
        raise WhiteboardError(f"width_mm must be at least 1.5 pixels "
                              f"({1.5 * res * 1e3:.2f} mm), got {width_mm!r}")
    if not jitter_mm >= 0.0:
        raise WhiteboardError(f"jitter_mm must be >= 0, got {jitter_mm!r}")
    seg = np.hypot(*np.diff(pts, axis=0).T) if len(pts) > 1 else np.zeros(0)
    s = np.concatenate(([0.0], np.cumsum(seg)))
    n = max(1, int(math.ceil(s[-1] / (res / 2))) + 1) if s[-1] > 0 else 1
    s_new = np.linspace(0.0, s[-1], n)
    if s[-1] > 0:
        xs = np.interp(s_new, s, pts[:, 0])
        ys = np.interp(s_new, s, pts[:, 1])
    else:
        xs, ys = pts[:1, 0].copy(), pts[:1, 1].copy()
    if jitter_mm > 0.0:
        amp = jitter_mm * 1e-3
        for arr in (xs, ys):
            lam = rng.uniform((0.012, 0.003), (0.030, 0.007))
            phase = rng.uniform(0.0, 2 * math.pi, 2)
            arr += amp * (0.7 * np.sin(2 * math.pi * s_new / lam[0] + phase[0])
                          + 0.3 * np.sin(2 * math.pi * s_new / lam[1] + phase[1]))
        np.clip(xs, x0, x1, out=xs)
        np.clip(ys, y0, y1, out=ys)
    return xs, ys, s_new, width_m


def symbol_paths(kind: str, cell: Region, cell_size: float, size: float, jitter_mm: float,
                 rng: np.random.Generator) -> list[np.ndarray]:
    """The paths of an X (two lines) or an O (one closed loop) a hand draws inside a cell.

    Parameters
    ----------
    kind : str
        ``"X"`` or ``"O"`` (checked by the caller).
    cell : (x_min, x_max, y_min, y_max)
        The cell, m (eqs. 3.37-3.38).
    cell_size : float
        The cell side L, m.
    size : float
        The symbol's extent as a share of L.
    jitter_mm : float
        With ``jitter_mm > 0`` the symbol is placed a little off the cell
        centre (up to 2.5 x jitter), scaled by up to +-8 % and turned by up
        to +-6 deg, all drawn from `rng`; an O starts at a random angle.

    Returns
    -------
    list of np.ndarray, each shape (N, 2), m
    """
    x_lo, x_hi, y_lo, y_hi = cell
    xc, yc = (x_lo + x_hi) / 2, (y_lo + y_hi) / 2  # eqs. 3.45-3.46
    half = size * cell_size / 2
    turn = 0.0
    if jitter_mm > 0.0:
        k = jitter_mm / (HAND_JITTER_M * 1e3)
        off = rng.uniform(-2.5, 2.5, 2) * jitter_mm * 1e-3
        xc, yc = xc + off[0], yc + off[1]
        half *= 1.0 + 0.08 * k * rng.uniform(-1.0, 1.0)
        turn = math.radians(6.0) * k * rng.uniform(-1.0, 1.0)
    ct, st = math.cos(turn), math.sin(turn)

    def place(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        return np.column_stack((xc + ct * u - st * v, yc + st * u + ct * v))

    if kind == "X":
        d = np.array([-half, half])
        return [place(d, d), place(d, -d)]  # the 45 and 135 deg lines of fig. 3.26
    start = rng.uniform(0.0, 2 * math.pi) if jitter_mm > 0.0 else 0.0
    ang = start + np.linspace(0.0, 2 * math.pi * 1.04, 150)  # closes with a small overlap
    return [place(half * np.cos(ang), half * np.sin(ang))]
