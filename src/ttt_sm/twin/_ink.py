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


@njit(cache=True, inline="always")
def _index_lo(v: float, lo: float, res: float, n: int) -> int:
    """First pixel index whose centre is >= v, clipped to [0, n]."""
    f = math.ceil((v - lo) / res - 0.5)
    if f < 0.0:
        return 0
    if f > n:
        return n
    return int(f)


@njit(cache=True, inline="always")
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
def _bounds(hx: np.ndarray, hy: np.ndarray, m: int, bnd: np.ndarray, row: int) -> tuple[int, int]:
    """Half-planes of a convex CCW polygon as bounds on x along a row: ``x >= a + b y`` or ``x <= a + b y``.

    Edge k (from vertex k to k + 1) keeps the polygon on the side
    ``nx x + ny y <= d`` with the outward normal ``(nx, ny) = (dy, -dx)``,
    that is ``x <= a + b y`` (nx > 0) or ``x >= a + b y`` (nx < 0) with
    ``(a, b) = (d / nx, -ny / nx)``.  Lower bounds go to ``bnd[row]`` (a) and
    ``bnd[row + 1]`` (b), upper bounds to ``bnd[row + 2]`` and ``bnd[row + 3]``.
    Horizontal edges only bound y, which the caller's row range already does.
    Returns ``(n_lower, n_upper)``.
    """
    n_lo = 0
    n_hi = 0
    for k in range(m):
        xa = hx[k]
        ya = hy[k]
        xb = hx[(k + 1) % m]
        yb = hy[(k + 1) % m]
        nx = yb - ya
        ny = xa - xb
        if abs(nx) <= 1e-12 * (abs(nx) + abs(ny)):
            continue
        d = nx * xa + ny * ya
        if nx > 0.0:
            bnd[row + 2, n_hi] = d / nx
            bnd[row + 3, n_hi] = -ny / nx
            n_hi += 1
        else:
            bnd[row, n_lo] = d / nx
            bnd[row + 1, n_lo] = -ny / nx
            n_lo += 1
    return n_lo, n_hi


@njit(cache=True, inline="always")
def _span(bnd: np.ndarray, row: int, n_lo: int, n_hi: int, y: float) -> tuple[float, float]:
    """x interval of a convex polygon (given by :func:`_bounds`) along the row at `y`."""
    a = -math.inf
    for k in range(n_lo):
        a = max(a, bnd[row, k] + bnd[row + 1, k] * y)
    b = math.inf
    for k in range(n_hi):
        b = min(b, bnd[row + 2, k] + bnd[row + 3, k] * y)
    return a, b


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
def wipe_sweep(raster: np.ndarray, stamp: np.ndarray, x0: float, y0: float, res: float, half: float,
               ax: float, ay: float, ca: float, sa: float, bx: float, by: float, cb: float, sb: float,
               skip_a: bool, seq: int) -> int:
    """Wipe the pixels a square pad sweeps moving from a to b; returns the ink pixels wiped.

    The pad is a square of half-side `half` (m); at a its edges run along
    (ca, sa) and (-sa, ca), at b along (cb, sb) and (-sb, cb).  The swept
    area is taken as the convex hull of the pad at a and at b.  With
    `skip_a` the pad at a, which the previous call wiped as its pad at b, is
    left out (shrunk by 0.1 um against round-off), so a moving pad costs only
    the strip it newly covers.

    Every wiped ink pixel gets `seq` in `stamp`; a stroke point laid there
    before `seq` is gone.  Clean pixels need no stamp: a stroke point always
    lies on ink when laid (the line is wider than a pixel's half-diagonal),
    so a clean pixel's points were stamped out by the wipe that cleaned it.
    """
    ny, nx = raster.shape
    px = np.empty(8)
    py = np.empty(8)
    _square(ax, ay, ca, sa, half, px, py, 0)
    _square(bx, by, cb, sb, half, px, py, 4)
    hx = np.empty(9)
    hy = np.empty(9)
    m = _convex_hull(px, py, hx, hy)
    bnd = np.empty((8, 8))  # rows 0-3: the hull's bounds, 4-7: the pad at a's
    n_lo, n_hi = _bounds(hx, hy, m, bnd, 0)
    s_lo = s_hi = 0
    sy_min = sy_max = 0.0
    if skip_a:
        _square(ax, ay, ca, sa, half - 1e-7, hx, hy, 0)
        s_lo, s_hi = _bounds(hx, hy, 4, bnd, 4)
        sy_min, sy_max = hy[:4].min(), hy[:4].max()
    j0 = _index_lo(py.min(), y0, res, ny)
    j1 = _index_hi(py.max(), y0, res, ny)
    wiped = 0
    for j in range(j0, j1 + 1):
        yc = y0 + (j + 0.5) * res
        lo, hi = _span(bnd, 0, n_lo, n_hi, yc)
        if lo > hi:
            continue
        i0 = _index_lo(lo, x0, res, nx)
        i1 = _index_hi(hi, x0, res, nx)
        k0 = nx
        k1 = -1  # skipped columns (inside the pad at a)
        if skip_a and sy_min <= yc <= sy_max:
            slo, shi = _span(bnd, 4, s_lo, s_hi, yc)
            if slo <= shi:
                k0 = _index_lo(slo, x0, res, nx)
                k1 = _index_hi(shi, x0, res, nx)
        if k0 > i1 or k1 < i0:
            wiped += _wipe_run(raster, stamp, j, i0, i1, seq)
        else:
            wiped += _wipe_run(raster, stamp, j, i0, k0 - 1, seq)
            wiped += _wipe_run(raster, stamp, j, k1 + 1, i1, seq)
    return wiped


@njit(cache=True, inline="always")
def _wipe_run(raster: np.ndarray, stamp: np.ndarray, j: int, i0: int, i1: int, seq: int) -> int:
    """Wipe pixels i0..i1 of row j, stamping the inked ones; returns how many held ink."""
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
