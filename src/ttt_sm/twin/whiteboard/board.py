"""The whiteboard: one board that the arm's pen and sponge and a person's hand act on, and that is measured and drawn.

:class:`Whiteboard` holds the board's state (the ink raster, the strokes,
the seeded hand) and puts the ideas of its package together: the contact
physics it is built on (:mod:`.contact`), the person's hand (:mod:`.hand`),
the metrics (:mod:`.metrics`) and the pictures (:mod:`.render`).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ttt_sm.params import ArmParams
from ttt_sm.twin._ink import ink_polyline

from . import metrics, render
from .contact import BoardContact
from .errors import WhiteboardError
from .hand import HAND_INK_WIDTH_M, HAND_JITTER_M, HAND_SPEED_M_S, hand_path, symbol_paths
from .metrics import CELL_MARGIN_M, TAIL_TOL_M
from .raster import AUTHOR_CODES, InkRaster, Region
from .strokes import Stroke, StrokeData, StrokeLog


class Whiteboard(BoardContact):
    """The horizontal whiteboard: pen ink, sponge wipes and a person's strokes.

    Parameters
    ----------
    params : ArmParams
        Geometry (forward kinematics), ``[board]``, ``[pen]`` and ``[sponge]``.
    resolution_mm : float
        Side of one raster pixel, mm (0.02 to 2).
    seed : int
        Seeds the jitter of hand strokes; :meth:`reset` restarts it.

    Notes
    -----
    Call :meth:`update` with the TRUE joint angles at every chart step (the
    pen inks between consecutive calls).  The raster ``ink_mask()[iy, ix]``
    has pixel centres at ``(x_min + (ix + 0.5) res, y_min + (iy + 0.5) res)``
    with ``(x_min, x_max, y_min, y_max) = extent``.
    """

    def __init__(self, params: ArmParams, resolution_mm: float = 0.2, *, seed: int = 0) -> None:
        if not 0.02 <= resolution_mm <= 2.0:
            raise WhiteboardError(f"resolution_mm must lie in [0.02, 2] mm, got {resolution_mm!r}")
        self.params = params
        b = params.board
        x0, _, y0, _ = b.board_bounds()
        raster = InkRaster(x0, y0, b.width, b.depth, resolution_mm * 1e-3)
        self._seed = seed
        super().__init__(params, raster, StrokeLog(raster))  # calls reset()

    # ------------------------------------------------------------------ state

    def reset(self) -> None:
        """A clean board: no ink, no strokes, nothing touching, counters zero, jitter re-seeded."""
        self._raster.clear()
        self._log.clear()
        super().reset()
        self._rng = np.random.default_rng(self._seed)

    @property
    def resolution_m(self) -> float:
        """Side of one raster pixel, m."""
        return self._raster.res

    @property
    def extent(self) -> Region:
        """(x_min, x_max, y_min, y_max) the raster covers, m (the board)."""
        return self._raster.extent

    @property
    def shape(self) -> tuple[int, int]:
        """Raster shape (rows along y, columns along x)."""
        return self._raster.shape

    # ------------------------------------------------------------------ the person's hand

    def draw_stroke(self, points_m: Any, width_mm: float = HAND_INK_WIDTH_M * 1e3, *,
                    jitter_mm: float = HAND_JITTER_M * 1e3, t: float | None = None,
                    author: str = "hand") -> Stroke:
        """Draw a polyline by hand (or as `author` "robot", for synthetic tests).

        Parameters
        ----------
        points_m : array_like, shape (N, 2)
            The intended path, x and y in metres, on the board.
        width_mm : float
            Line width of the marker, mm (at least 1.5 pixels).
        jitter_mm : float
            Amplitude of a slow, seeded wobble added to the path, mm: two
            sinusoids per axis along the arc length (wavelengths 12-30 mm and
            3-7 mm), like an unsteady hand.  0 draws the path exactly.
        t : float, optional
            Start time, s (default: the time of the last :meth:`update`);
            the points are timed at :data:`HAND_SPEED_M_S`.
        author : str
            ``"hand"`` or ``"robot"``.

        Returns
        -------
        Stroke
            What was drawn (path densified to one point per half pixel, jittered).
        """
        if author not in AUTHOR_CODES:
            raise WhiteboardError(f"author must be one of {sorted(AUTHOR_CODES)}, got {author!r}")
        xs, ys, s, width_m = hand_path(points_m, self._raster, width_mm, jitter_mm, self._rng)
        self._seq += 1
        t0 = self._t if t is None else float(t)
        times = t0 + s / HAND_SPEED_M_S
        r = self._raster
        ink_polyline(r.ink, r.x0, r.y0, r.res, xs, ys, width_m / 2, AUTHOR_CODES[author])
        data = StrokeData(author, width_m, xs, ys, times, np.full(len(xs), self._seq, np.int64))
        data.checked = self._seq
        self._log.add(data)
        return data.snapshot()

    def draw_symbol(self, kind: str, row: int, column: int, *, size: float = 0.6,
                    width_mm: float = HAND_INK_WIDTH_M * 1e3,
                    jitter_mm: float = HAND_JITTER_M * 1e3, t: float | None = None) -> tuple[Stroke, ...]:
        """Draw an X (two strokes) or an O (one closed stroke) by hand inside a cell.

        Parameters
        ----------
        kind : str
            ``"X"`` or ``"O"``.
        row, column : int
            The cell, 1-based (eqs. 3.37-3.38).
        size : float
            The symbol's extent as a share of the cell side L.
        width_mm, jitter_mm, t
            As in :meth:`draw_stroke`.  With ``jitter_mm > 0`` the symbol is
            also placed a little off the cell centre (up to 2.5 x jitter),
            scaled by up to +-8 % and turned by up to +-6 deg, all seeded.

        Returns
        -------
        tuple[Stroke, ...]
        """
        kind_u = str(kind).upper()
        if kind_u not in ("X", "O"):
            raise WhiteboardError(f"kind must be 'X' or 'O', got {kind!r}")
        if not 0.0 < size <= 1.0:
            raise WhiteboardError(f"size must lie in (0, 1], got {size!r}")
        paths = symbol_paths(kind_u, self.cell_bounds(row, column), self.params.board.cell_size, size,
                             jitter_mm, self._rng)
        return tuple(self.draw_stroke(p, width_mm, jitter_mm=jitter_mm, t=t) for p in paths)

    # ------------------------------------------------------------------ cells and pixels

    def cell_bounds(self, row: int, column: int) -> Region:
        """(x_min, x_max, y_min, y_max) of a cell, m (eqs. 3.37-3.38).

        ``x11, y11`` is the field's upper right corner ``(x_max, y_max)``;
        column c spans ``x11 - c L .. x11 - (c - 1) L`` and row r spans
        ``y11 - r L .. y11 - (r - 1) L``.
        """
        b = self.params.board
        for name, v in (("row", row), ("column", column)):
            if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not 1 <= v <= b.cells:
                raise WhiteboardError(f"{name} must be an integer 1..{b.cells}, got {v!r}")
        _, x11, _, y11 = b.field_bounds()
        L = b.cell_size
        return (x11 - column * L, x11 - (column - 1) * L, y11 - row * L, y11 - (row - 1) * L)

    def pixel_centers_m(self, mask: np.ndarray) -> np.ndarray:
        """(x, y) in metres of the True pixels of a raster-shaped mask, shape (N, 2)."""
        return self._raster.pixel_centers_m(mask)

    # ------------------------------------------------------------------ queries

    @property
    def strokes(self) -> tuple[Stroke, ...]:
        """Every stroke on the board, oldest first, the pen's running one last.

        A sponge pass removes the points it wiped and splits a stroke it
        crossed, so the strokes always describe the ink that is left.
        """
        return self._log.strokes(self.running_stroke())

    def ink_mask(self) -> np.ndarray:
        """The inked pixels, bool, shape :attr:`shape` (row index along y, column along x)."""
        return self._raster.ink != 0

    def ink_area_mm2(self, region: Region | None = None) -> float:
        """Inked area, mm^2, of the board or of a region (x_min, x_max, y_min, y_max) in m."""
        return metrics.ink_area_mm2(self._raster, region)

    def ink_outside(self, polylines: Sequence[Any], tol_m: float) -> np.ndarray:
        """Ink pixels farther than `tol_m` from every desired polyline (:func:`.metrics.ink_outside`).

        Pen-lift and pen-lower tails, stray marks; :meth:`pixel_centers_m`
        turns the mask into coordinates.
        """
        return metrics.ink_outside(self._raster, polylines, tol_m)

    def longest_tail_mm(self, desired_polylines: Sequence[Any], tol_m: float = TAIL_TOL_M) -> float:
        """Length of the longest connected run of ink outside the tolerance band, mm
        (:func:`.metrics.longest_tail_mm`)."""
        return metrics.longest_tail_mm(self._raster, desired_polylines, tol_m)

    def cell_ink_fraction(self, row: int, column: int, margin_m: float = CELL_MARGIN_M) -> float:
        """Share of a cell that is inked, leaving `margin_m` clear of its grid lines."""
        return metrics.cell_ink_fraction(self._raster, self.cell_bounds(row, column), margin_m)

    # ------------------------------------------------------------------ pictures

    def render(self, px_per_mm: float = 4.0, grid_mm: bool = False, region: Region | None = None, *,
               view: str = "field", desired: Sequence[Any] | None = None) -> np.ndarray:
        """Draw the board as a BGR image: white board, dark blue robot ink, black hand ink.

        The arguments are those of :func:`.render.render` (views, millimetre
        paper, desired paths in red).
        """
        return render.render(self._raster, px_per_mm, grid_mm, region, view=view, desired=desired)

    def save_png(self, path: str | Path, **render_args: Any) -> Path:
        """Write :meth:`render` (same keyword arguments) to a PNG file; returns the path."""
        p = Path(path)
        return render.write_png(self.render(**render_args), p)
