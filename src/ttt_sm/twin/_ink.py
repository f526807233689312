"""Raster kernels of the whiteboard: lay ink along a segment, wipe a swept pad.

The board raster is a ``uint8`` array ``ink[iy, ix]`` (0 = clean, otherwise
the code of the author whose ink lies there); pixel ``(iy, ix)`` has its
centre at ``(x0 + (ix + 0.5) res, y0 + (iy + 0.5) res)``, so ``iy`` grows
with the global y and ``ix`` with x.  A pixel is inked, or wiped, when its
centre lies inside the shape; both kernels touch only the pixels of that
shape's bounding rows, so a 0.1 mm step of the pen costs a few dozen pixel
tests and a step of the sponge a thin strip, not the whole pad.

``NUMBA_DISABLE_JIT=1`` runs the same code as plain Python for a debugger.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def _index_lo(v: float, lo: float, res: float, n: int) -> int:
    """First pixel index whose centre is >= v, clipped to [0, n]."""
    f = math.ceil((v - lo) / res - 0.5)
    if f < 0.0:
        return 0
    if f > n:
        return n
    return int(f)


@njit(cache=True)
def _index_hi(v: float, lo: float, res: float, n: int) -> int:
    """Last pixel index whose centre is <= v, clipped to [-1, n - 1]."""
    f = math.floor((v - lo) / res - 0.5)
    if f < -1.0:
        return -1
    if f > n - 1:
        return n - 1
    return int(f)


@njit(cache=True)
def ink_capsule(raster: np.ndarray, x0: float, y0: float, res: float,
                ax: float, ay: float, bx: float, by: float, radius: float, code: int) -> int:
    """Mark the pixels within `radius` of segment a-b with `code`.

    The marker's round felt tip of radius `radius` (m) swept from a to b: a
    capsule.  Returns how many pixels were clean before (new ink).
    """
    ny, nx = raster.shape
    i0 = _index_lo(min(ax, bx) - radius, x0, res, nx)
    i1 = _index_hi(max(ax, bx) + radius, x0, res, nx)
    j0 = _index_lo(min(ay, by) - radius, y0, res, ny)
    j1 = _index_hi(max(ay, by) + radius, y0, res, ny)
    dx = bx - ax
    dy = by - ay
    len_sq = dx * dx + dy * dy
    r_sq = radius * radius * (1.0 + 1e-9)
    new = 0
    for j in range(j0, j1 + 1):
        py = y0 + (j + 0.5) * res - ay
        for i in range(i0, i1 + 1):
            px = x0 + (i + 0.5) * res - ax
            s = 0.0
            if len_sq > 0.0:
                s = (px * dx + py * dy) / len_sq
                if s < 0.0:
                    s = 0.0
                elif s > 1.0:
                    s = 1.0
            ex = px - s * dx
            ey = py - s * dy
            if ex * ex + ey * ey <= r_sq:
                if raster[j, i] == 0:
                    new += 1
                raster[j, i] = code
    return new


@njit(cache=True)
def _cross(ox: float, oy: float, ax: float, ay: float, bx: float, by: float) -> float:
    return (ax - ox) * (by - oy) - (ay - oy) * (bx - ox)


@njit(cache=True)
def _convex_hull(px: np.ndarray, py: np.ndarray, hx: np.ndarray, hy: np.ndarray) -> int:
    """Andrew's monotone chain: hull of the points into hx, hy (CCW); returns its size."""
    n = px.shape[0]
    order = np.argsort(px * 1e6 + py)  # points are metres apart by far less than 1e6 m
    k = 0
    for idx in range(n):  # lower hull
        i = order[idx]
        while k >= 2 and _cross(hx[k - 2], hy[k - 2], hx[k - 1], hy[k - 1], px[i], py[i]) <= 0.0:
            k -= 1
        hx[k] = px[i]
        hy[k] = py[i]
        k += 1
    lower = k + 1
    for idx in range(n - 2, -1, -1):  # upper hull
        i = order[idx]
        while k >= lower and _cross(hx[k - 2], hy[k - 2], hx[k - 1], hy[k - 1], px[i], py[i]) <= 0.0:
            k -= 1
        hx[k] = px[i]
        hy[k] = py[i]
        k += 1
    return k - 1  # the last point repeats the first


@njit(cache=True)
def _row_span(hx: np.ndarray, hy: np.ndarray, m: int, y: float) -> tuple[float, float]:
    """x interval where the horizontal line at `y` crosses a convex polygon (lo > hi: misses)."""
    lo = math.inf
    hi = -math.inf
    for k in range(m):
        xa = hx[k]
        ya = hy[k]
        xb = hx[(k + 1) % m]
        yb = hy[(k + 1) % m]
        if (ya - y) * (yb - y) > 0.0:
            continue
        if ya == yb:
            lo = min(lo, xa, xb)
            hi = max(hi, xa, xb)
        else:
            x = xa + (y - ya) * (xb - xa) / (yb - ya)
            lo = min(lo, x)
            hi = max(hi, x)
    return lo, hi


@njit(cache=True)
def _square(cx: float, cy: float, c: float, s: float, half: float,
            hx: np.ndarray, hy: np.ndarray, start: int) -> None:
    """Corners (CCW) of a square of half-side `half`, axes (c, s) and (-s, c), centred at c."""
    ux, uy = c * half, s * half
    vx, vy = -s * half, c * half
    hx[start], hy[start] = cx - ux - vx, cy - uy - vy
    hx[start + 1], hy[start + 1] = cx + ux - vx, cy + uy - vy
    hx[start + 2], hy[start + 2] = cx + ux + vx, cy + uy + vy
    hx[start + 3], hy[start + 3] = cx - ux + vx, cy - uy + vy


@njit(cache=True)
def wipe_sweep(raster: np.ndarray, stamp: np.ndarray, x0: float, y0: float, res: float,
               c: float, s: float, half: float, ax: float, ay: float, bx: float, by: float,
               skip_a: bool, seq: int) -> int:
    """Wipe the pixels a square pad sweeps moving from a to b; returns the ink pixels wiped.

    The pad is a square of half-side `half` (m) whose edges run along (c, s)
    and (-s, c); the swept area is the convex hull of the pad at a and at b.
    With `skip_a` the pad at a (already wiped at the previous step, shrunk by
    one pixel against round-off and a slight turn of the pad) is left out, so
    a moving pad costs only the strip it newly covers.  Every wiped pixel
    gets `seq` in `stamp`: a stroke point laid before that is gone.
    """
    ny, nx = raster.shape
    px = np.empty(8)
    py = np.empty(8)
    _square(ax, ay, c, s, half, px, py, 0)
    _square(bx, by, c, s, half, px, py, 4)
    hx = np.empty(9)
    hy = np.empty(9)
    m = _convex_hull(px, py, hx, hy)
    sx = np.empty(4)
    sy = np.empty(4)
    inner = half - res
    if skip_a and inner > 0.0:
        _square(ax, ay, c, s, inner, sx, sy, 0)
    else:
        skip_a = False
    j0 = _index_lo(py.min(), y0, res, ny)
    j1 = _index_hi(py.max(), y0, res, ny)
    wiped = 0
    for j in range(j0, j1 + 1):
        yc = y0 + (j + 0.5) * res
        lo, hi = _row_span(hx, hy, m, yc)
        if lo > hi:
            continue
        i0 = _index_lo(lo, x0, res, nx)
        i1 = _index_hi(hi, x0, res, nx)
        k0 = nx
        k1 = -1  # skipped columns (inside the pad at a)
        if skip_a:
            slo, shi = _row_span(sx, sy, 4, yc)
            if slo <= shi:
                k0 = _index_lo(slo, x0, res, nx)
                k1 = _index_hi(shi, x0, res, nx)
        if k0 > i1 or k1 < i0:
            wiped += _wipe_run(raster, stamp, j, i0, i1, seq)
        else:
            wiped += _wipe_run(raster, stamp, j, i0, k0 - 1, seq)
            wiped += _wipe_run(raster, stamp, j, k1 + 1, i1, seq)
    return wiped


@njit(cache=True)
def _wipe_run(raster: np.ndarray, stamp: np.ndarray, j: int, i0: int, i1: int, seq: int) -> int:
    """Wipe pixels i0..i1 of row j; returns how many held ink."""
    wiped = 0
    for i in range(i0, i1 + 1):
        if raster[j, i] != 0:
            wiped += 1
            raster[j, i] = 0
        stamp[j, i] = seq
    return wiped


@njit(cache=True)
def ink_polyline(raster: np.ndarray, x0: float, y0: float, res: float,
                 xs: np.ndarray, ys: np.ndarray, radius: float, code: int) -> int:
    """:func:`ink_capsule` along every segment of a polyline (one point: a dot)."""
    n = xs.shape[0]
    if n == 1:
        return ink_capsule(raster, x0, y0, res, xs[0], ys[0], xs[0], ys[0], radius, code)
    new = 0
    for k in range(n - 1):
        new += ink_capsule(raster, x0, y0, res, xs[k], ys[k], xs[k + 1], ys[k + 1], radius, code)
    return new
