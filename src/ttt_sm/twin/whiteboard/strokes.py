"""Ink as polylines: the strokes on the board, kept true to the raster when the sponge wipes.

Every stroke point carries the update sequence number it was laid at; a
wipe stamps its pixels with its own (:mod:`.raster`).  A point whose pixel
was wiped later than the point was laid is gone, so a sponge pass removes
the points it wiped and splits a stroke it crossed.  The split is done
lazily, when someone asks for the strokes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .raster import InkRaster


@dataclass(frozen=True, eq=False)  # eq on arrays is ambiguous; compare .points with numpy
class Stroke:
    """One contiguous run of ink: a polyline on the board.

    Attributes
    ----------
    author : str
        ``"robot"`` (the pen on the arm) or ``"hand"`` (the person).
    points : np.ndarray, shape (N, 2)
        Where the real pen tip went, x and y in metres (read-only).
    times : np.ndarray, shape (N,)
        When it was at each point, seconds (read-only).
    width_m : float
        Line width of the marker, m.
    """

    author: str
    points: np.ndarray
    times: np.ndarray
    width_m: float

    @property
    def length_m(self) -> float:
        """Length of the polyline, m."""
        if len(self.points) < 2:
            return 0.0
        return float(np.hypot(*np.diff(self.points, axis=0).T).sum())


class StrokeData:
    """A stored stroke: arrays, plus the update sequence number of each point."""

    __slots__ = ("author", "width_m", "x", "y", "t", "seq", "checked")

    def __init__(self, author: str, width_m: float, x: np.ndarray, y: np.ndarray,
                 t: np.ndarray, seq: np.ndarray) -> None:
        self.author = author
        self.width_m = width_m
        self.x, self.y, self.t, self.seq = x, y, t, seq
        self.checked = 0  # wipes up to this sequence number are applied

    def snapshot(self) -> Stroke:
        points = np.column_stack((self.x, self.y))
        times = self.t.copy()
        points.flags.writeable = False
        times.flags.writeable = False
        return Stroke(self.author, points, times, self.width_m)


class StrokeLog:
    """The finished strokes on a raster, oldest first, with the wipes applied when asked."""

    def __init__(self, raster: InkRaster) -> None:
        self._raster = raster
        #: Strokes kept since the log was made (a clear does not undo the count): a view's change key.
        self.added = 0
        self.clear()

    def clear(self) -> None:
        """No strokes, no wipes."""
        self._strokes: list[StrokeData] = []
        self._cache: tuple[Stroke, ...] | None = None
        self._last_wipe_seq = 0

    def add(self, stroke: StrokeData) -> None:
        """Keep a finished stroke."""
        self._strokes.append(stroke)
        self.added += 1
        self._cache = None

    def changed(self) -> None:
        """The ink changed: build the snapshots anew when next asked."""
        self._cache = None

    def wiped(self, seq: int) -> None:
        """The sponge wiped pixels at update `seq` (their stamps say which)."""
        self._last_wipe_seq = seq
        self._cache = None

    def strokes(self, running: StrokeData | None = None) -> tuple[Stroke, ...]:
        """Every stroke left on the board, oldest first, then what is left of `running`
        (the pen's stroke still being drawn)."""
        if self._cache is None:
            self._apply_wipes()
            self._cache = tuple(s.snapshot() for s in self._strokes)
        if running is None:
            return self._cache
        return self._cache + tuple(piece.snapshot() for piece in self._split(running))

    def _apply_wipes(self) -> None:
        if all(s.checked >= self._last_wipe_seq for s in self._strokes):
            return
        kept: list[StrokeData] = []
        for s in self._strokes:
            kept.extend(self._split(s) if s.checked < self._last_wipe_seq else [s])
        self._strokes = kept

    def _split(self, s: StrokeData) -> list[StrokeData]:
        """The pieces of a stroke that no later wipe removed."""
        iy, ix = self._raster.pixels_of(s.x, s.y)
        keep = self._raster.stamp[iy, ix] < s.seq
        s.checked = self._last_wipe_seq
        if keep.all():
            return [s]
        edges = np.flatnonzero(np.diff(np.concatenate(([False], keep, [False])).astype(np.int8)))
        pieces = []
        for a, b in zip(edges[::2], edges[1::2], strict=True):
            piece = StrokeData(s.author, s.width_m, s.x[a:b].copy(), s.y[a:b].copy(),
                               s.t[a:b].copy(), s.seq[a:b].copy())
            piece.checked = self._last_wipe_seq
            pieces.append(piece)
        return pieces
