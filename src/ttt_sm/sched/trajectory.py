"""Task-space paths sampled at the chart rate: plain setpoint sources.

Until the Control chart exists (a later issue), a path is what feeds the
loop: the tool moves along straight segments at a set speed, one increment
per chart tick, the way eq. 3.36 draws a line (``X_out = X_out_p + inc``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..params import Board


@dataclass(frozen=True)
class Waypoint:
    """A tool pose to reach: position (m), pen angle phi (rad), and whether the pen draws."""

    x: float
    y: float
    z: float
    phi: float = 0.0
    speed: float | None = None  # m/s on the segment that ends here; None: the path default


def sample_polyline(waypoints: Sequence[Waypoint], speed: float, dt: float) -> np.ndarray:
    """Sample straight segments between waypoints at constant speed.

    Parameters
    ----------
    waypoints : sequence of Waypoint
        The first is the start; each later one ends a segment.
    speed : float
        Default tool speed along a segment, m/s.
    dt : float
        Chart step, s.

    Returns
    -------
    np.ndarray, shape (n, 4)
        One row [x, y, z, phi] per chart tick; phi moves with the position,
        at most ``speed / 0.05`` rad/s so pure turns take time too.
    """
    if len(waypoints) < 1:
        raise ValueError("a path needs at least one waypoint")
    if speed <= 0 or dt <= 0:
        raise ValueError(f"speed and dt must be positive (speed={speed}, dt={dt})")
    rows = [np.array([waypoints[0].x, waypoints[0].y, waypoints[0].z, waypoints[0].phi])]
    for wp in waypoints[1:]:
        a = rows[-1]
        b = np.array([wp.x, wp.y, wp.z, wp.phi])
        v = wp.speed if wp.speed is not None else speed
        length = float(np.linalg.norm(b[:3] - a[:3]))
        turn = abs(b[3] - a[3]) * 0.05
        n = max(1, int(np.ceil(max(length, turn) / (v * dt))))
        s = np.arange(1, n + 1)[:, None] / n
        rows.extend(a + s * (b - a))
    return np.vstack(rows)


def square_path(board: Board, side: float = 0.03, lift: float = 0.02,
                press: float = 0.001) -> list[Waypoint]:
    """A square of `side` drawn around the field's centre, pen lowered and lifted.

    `press` pushes the spring-loaded pen that far into its holder while it
    draws, so small height errors do not lift it off the board.
    """
    cx, cy, z0 = board.field_center_x, board.field_center_y, board.surface_z
    h = side / 2
    corners = [(cx + h, cy + h), (cx - h, cy + h), (cx - h, cy - h), (cx + h, cy - h), (cx + h, cy + h)]
    down, up = z0 - press, z0 + lift
    path = [Waypoint(cx, cy, up + 0.03), Waypoint(corners[0][0], corners[0][1], up)]
    path.append(Waypoint(corners[0][0], corners[0][1], down))
    path.extend(Waypoint(x, y, down) for x, y in corners[1:])
    path.append(Waypoint(corners[-1][0], corners[-1][1], up))
    return path


def distance_to_path(points: np.ndarray, path: np.ndarray, chunk: int = 512) -> np.ndarray:
    """Distance from each point to the nearest point of a polyline, metres.

    Parameters
    ----------
    points : np.ndarray, shape (n, d)
        Positions to measure (e.g. the true tool path), d = 2 or 3.
    path : np.ndarray, shape (m, d)
        Vertices of the desired polyline, m >= 1.

    Returns
    -------
    np.ndarray, shape (n,)
        The geometric deviation: unlike a difference at equal times, it does
        not count a tool that is on the path but late as an error.
    """
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    poly = np.atleast_2d(np.asarray(path, dtype=float))
    if len(poly) == 1:
        return np.linalg.norm(pts - poly[0], axis=1)
    a, b = poly[:-1], poly[1:]
    ab = b - a
    denom = np.einsum("ij,ij->i", ab, ab)
    denom[denom == 0] = 1.0
    out = np.empty(len(pts))
    for i in range(0, len(pts), chunk):
        p = pts[i:i + chunk, None, :]
        s = np.clip(np.einsum("nij,ij->ni", p - a, ab) / denom, 0.0, 1.0)
        nearest = a + s[..., None] * ab
        out[i:i + chunk] = np.sqrt(np.min(np.sum((p - nearest) ** 2, axis=2), axis=1))
    return out


def simplify_polyline(points: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    """The polyline with the vertices dropped that lie within `tol` of it (Ramer-Douglas-Peucker).

    A chart-rate path has a vertex every 0.04 mm; a straight 15 cm line needs
    two.  Geometric comparisons against the simplified path are exact to `tol`.
    """
    pts = np.asarray(points, dtype=float)
    if len(pts) < 3:
        return pts
    keep = np.zeros(len(pts), dtype=bool)
    keep[0] = keep[-1] = True
    stack = [(0, len(pts) - 1)]
    while stack:
        i, j = stack.pop()
        if j <= i + 1:
            continue
        a, b = pts[i], pts[j]
        d = distance_to_path(pts[i + 1:j], np.vstack([a, b]))
        k = int(np.argmax(d))
        if d[k] > tol:
            keep[i + 1 + k] = True
            stack.extend([(i, i + 1 + k), (i + 1 + k, j)])
    return pts[keep]
