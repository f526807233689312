"""The simulated whiteboard: ink from the spring-loaded pen, wiping by the sponge.

The board is the horizontal plane ``z = surface_z`` over the rectangle of
``[board]`` in the parameter file.  :meth:`Whiteboard.update` takes the arm's
TRUE joint angles every chart step and works out what touches the board:

* the **pen** (thesis section 3.3.1): its tip is at the end of the tool axis,
  ``fk(q)[:3]``.  Below the surface the spring lets the pen slide back into
  its holder along the tool axis until the real tip rests on the board
  (``compression``); beyond ``spring_travel`` the holder itself hits the board
  (an *overpress*; the pen still inks).  The 0.4 mm radial clearance of the
  holder lets board friction drag the tip behind the holder's motion by up to
  the thesis' 0.35 mm (eqs. 3.1-3.13): a play operator, see :meth:`update`.
* the **sponge** (section 3.6.1, Erase): on the lateral surface of the end
  effector, facing the board at phi = 90 deg; it wipes every pixel its square
  pad sweeps.
* a **person's hand** (:meth:`draw_stroke`, :meth:`draw_symbol`) for the game.

Ink lives in a raster (``resolution_mm`` per pixel, over the board) and as
stroke polylines with times and an author; the two stay consistent when the
sponge wipes.  :meth:`render` draws the board as an image (optionally on
millimetre paper like the thesis' figs. 3.19-3.20); docs/whiteboard.md
explains the model, the image orientation and the costs.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from ttt_sm.params import ArmParams
from ttt_sm.twin._ink import ink_capsule, ink_polyline, wipe_sweep
from ttt_sm.twin.kinematics import arm_chain_py

#: Line width of the robot's whiteboard marker (m).
INK_WIDTH_M = 0.8e-3
#: Default line width of the person's marker (m): a hand presses a fresh marker harder.
HAND_INK_WIDTH_M = 1.5e-3
#: Amplitude of the slow wobble of a hand stroke (m), see :meth:`Whiteboard.draw_stroke`.
HAND_JITTER_M = 0.4e-3
#: Speed a hand stroke is timed with (m/s); only its point times depend on it.
HAND_SPEED_M_S = 0.1
#: Largest tip deviation over the holder clearance: 0.35 mm for 0.4 mm (eqs. 3.11-3.13).
TIP_DEVIATION_PER_CLEARANCE = 0.35 / 0.4
#: Beyond this tilt of the tool axis the spring cannot push the pen back along it:
#: a tip below the surface is then a jam, counted as an overpress.
PEN_MAX_TILT_RAD = math.radians(60.0)
#: The sponge's face counts as lying on the board within this angle of phi = 90 deg.
SPONGE_MAX_TILT_RAD = math.radians(20.0)
#: Margin kept clear of the grid lines when measuring a cell's ink (m).
CELL_MARGIN_M = 3e-3
#: Default tolerance band around a desired path for :meth:`Whiteboard.longest_tail_mm` (m).
TAIL_TOL_M = 1e-3
#: Ink colours (BGR) in :meth:`Whiteboard.render`, by author.
ROBOT_INK_BGR = (110, 35, 10)
HAND_INK_BGR = (25, 25, 25)
DESIRED_BGR = (40, 40, 220)
#: Millimetre paper (figs. 3.19-3.20): 1 mm, 5 mm and 10 mm lines (BGR).
GRID_BGR = ((205, 228, 250), (150, 195, 245), (95, 155, 235))

#: Image orientations of :meth:`Whiteboard.render`: view -> (flip rows, flip columns)
#: of the raster, whose row index grows with y and column index with x.
VIEWS = {
    "field": (True, True),      # row 1 at the top, column 1 at the left: x grows left, y up
    "above": (True, False),     # from above, robot at the bottom: x grows right, y up (fig. 3.26)
    "far_edge": (False, True),  # a camera beyond the far edge, facing the robot: x left, y down
}

_AUTHOR_CODES = {"robot": 1, "hand": 2}
_CODE_AUTHORS = {code: name for name, code in _AUTHOR_CODES.items()}
_PEN_MIN_COS = math.cos(PEN_MAX_TILT_RAD)
_SPONGE_MIN_SIN = math.cos(SPONGE_MAX_TILT_RAD)

Region = tuple[float, float, float, float]


def _load_kernels(ink: np.dtype, stamp: np.dtype) -> None:
    """Load the compiled ink and wipe kernels now (numba's disk cache), not when the pen first
    touches: on a scratch raster, with the argument types the board passes."""
    raster, stamps = np.zeros((2, 2), ink), np.zeros((2, 2), stamp)
    ink_capsule(raster, 0.0, 0.0, 1.0, 0.5, 0.5, 0.5, 0.5, 0.1, 1)
    wipe_sweep(raster, stamps, 0.0, 0.0, 1.0, 0.1, 0.5, 0.5, 1.0, 0.0, 0.5, 0.5, 1.0, 0.0, False, 1)


class WhiteboardError(ValueError):
    """A whiteboard call got a value it cannot use (cell, region, stroke, file)."""


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


@dataclass(frozen=True)
class Contact:
    """What touches the board after the last :meth:`Whiteboard.update`.

    Attributes
    ----------
    pen_touching : bool
        The pen tip rests on the board (and inks).
    pen_colliding : bool
        The pen tip is inside the board or its stand (``zone_depth`` below
        the surface), having come in from the edge or from beneath: a
        collision, not writing.
    pen_collision_count : int
        Such collisions since :meth:`Whiteboard.reset` (rising edges).
    compression_m : float
        How far the pen is pushed into its holder along the tool axis, m.
    pen_overpress : bool
        Pushed beyond ``spring_travel`` (the holder hits the board) or jammed
        at a tilt beyond :data:`PEN_MAX_TILT_RAD`.
    pen_overpress_count : int
        Overpress events since :meth:`Whiteboard.reset` (rising edges).
    tip_m : tuple[float, float] | None
        The real tip (x, y) on the board while touching, m.
    drag_m : float
        Distance of the real tip from where forward kinematics puts it, m.
    max_drag_m : float
        Largest ``drag_m`` since the reset, m.
    sponge_touching : bool
        The sponge pad lies on the board (and wipes).
    sponge_press_m : float
        How far the pad is pressed in, m.
    sponge_overpress : bool
        Pressed beyond the sponge's ``compliance``.
    sponge_overpress_count : int
        Sponge overpress events since the reset.
    """

    pen_touching: bool
    pen_colliding: bool
    pen_collision_count: int
    compression_m: float
    pen_overpress: bool
    pen_overpress_count: int
    tip_m: tuple[float, float] | None
    drag_m: float
    max_drag_m: float
    sponge_touching: bool
    sponge_press_m: float
    sponge_overpress: bool
    sponge_overpress_count: int


class _StrokeData:
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


class Whiteboard:
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
        g, b = params.geometry, params.board
        self._L1, self._L2, self._L3, self._L4, self._lf = g.L1, g.L2, g.L3, g.L4, g.l_f
        self._surface = b.surface_z
        self._res = resolution_mm * 1e-3
        x0, _, y0, _ = b.board_bounds()
        nx, ny = int(round(b.width / self._res)), int(round(b.depth / self._res))
        self._x0, self._y0 = x0, y0
        self._x1, self._y1 = x0 + nx * self._res, y0 + ny * self._res
        self._ink = np.zeros((ny, nx), np.uint8)
        self._stamp = np.zeros((ny, nx), np.int32)  # sequence number of each pixel's last wipe
        _load_kernels(self._ink.dtype, self._stamp.dtype)
        self._travel = params.pen.spring_travel
        self._zone_depth = b.zone_depth
        self._tip_dev = params.pen.holder_clearance * TIP_DEVIATION_PER_CLEARANCE
        self._sp_off = params.sponge.offset
        self._sp_half = params.sponge.width / 2
        self._sp_comp = params.sponge.compliance
        self._radius = INK_WIDTH_M / 2
        self._min_step = self._res / 4  # stroke points closer than this are not stored
        self._seed = seed
        self.reset()

    # ------------------------------------------------------------------ state

    def reset(self) -> None:
        """A clean board: no ink, no strokes, nothing touching, counters zero, jitter re-seeded."""
        self._ink[:] = 0
        self._stamp[:] = 0
        self._seq = 0
        self._t = 0.0
        self._strokes: list[_StrokeData] = []
        self._cache: tuple[Stroke, ...] | None = None
        self._last_wipe_seq = 0
        self._rng = np.random.default_rng(self._seed)
        # pen
        self._pen_on = False
        self._tip_x = self._tip_y = 0.0  # real tip
        self._cx = self._cy = 0.0  # where forward kinematics puts it
        self._ink_x = self._ink_y = 0.0  # the real tip when ink was last laid
        self._run_x: list[float] = []
        self._run_y: list[float] = []
        self._run_t: list[float] = []
        self._run_seq: list[int] = []
        self._compression = 0.0
        self._pen_over = False
        self._pen_over_count = 0
        self._max_drag = 0.0
        self._pen_above = True  # the tip was last above the surface (or no update yet)
        self._pen_colliding = False
        self._collision_count = 0
        # sponge
        self._sp_on = False
        self._sp_x = self._sp_y = 0.0  # pad centre when it last wiped
        self._sp_c, self._sp_s = 1.0, 0.0  # and the pad's edge direction then (the base azimuth)
        self._sp_above = True  # the pad face was last above the surface
        self._sp_press = 0.0
        self._sp_over = False
        self._sp_over_count = 0
        self.wiped_pixels = 0

    @property
    def resolution_m(self) -> float:
        """Side of one raster pixel, m."""
        return self._res

    @property
    def extent(self) -> Region:
        """(x_min, x_max, y_min, y_max) the raster covers, m (the board)."""
        return (self._x0, self._x1, self._y0, self._y1)

    @property
    def shape(self) -> tuple[int, int]:
        """Raster shape (rows along y, columns along x)."""
        ny, nx = self._ink.shape
        return (ny, nx)

    @property
    def tip_deviation_m(self) -> float:
        """Largest drag of the pen tip in its holder (L_s of eq. 3.13), m."""
        return self._tip_dev

    @property
    def contact(self) -> Contact:
        """What touches the board now, and the overpress counters."""
        drag = math.hypot(self._cx - self._tip_x, self._cy - self._tip_y) if self._pen_on else 0.0
        return Contact(
            pen_touching=self._pen_on,
            pen_colliding=self._pen_colliding,
            pen_collision_count=self._collision_count,
            compression_m=self._compression,
            pen_overpress=self._pen_over,
            pen_overpress_count=self._pen_over_count,
            tip_m=(self._tip_x, self._tip_y) if self._pen_on else None,
            drag_m=drag,
            max_drag_m=self._max_drag,
            sponge_touching=self._sp_on,
            sponge_press_m=self._sp_press,
            sponge_overpress=self._sp_over,
            sponge_overpress_count=self._sp_over_count,
        )

    # ------------------------------------------------------------------ the arm

    def update(self, t: float, q: Any) -> None:
        """Advance the board to time `t` with the arm at TRUE joint angles `q`.

        Parameters
        ----------
        t : float
            Time, s (stamps stroke points).
        q : array_like, shape (4,)
            True joint angles q1..q4, rad.

        Notes
        -----
        Pen (section 3.3): with the nominal tip ``p = fk(q)[:3]`` at depth
        ``d = surface_z - p_z >= 0`` and tool axis ``u`` (frame 1:
        ``(0, sin phi, -cos phi)``), the pen slides back into its holder by
        ``c = d / cos phi`` so that its tip ``p - c u`` rests on the surface.
        The real tip then follows that contact point like a play operator of
        radius ``L_s`` (``holder_clearance`` x 0.35/0.4, eq. 3.13): board
        friction holds it until the holder has moved ``L_s`` away, then drags
        it along ``L_s`` behind.  Lifting re-centres the pen.  Ink is laid
        along the segment between the real tip's last two positions.

        Sponge (section 3.6.1): pad centre ``p + offset n``, frame 1
        ``n = (0, -cos phi, -sin phi)`` (straight down at phi = 90 deg); it
        touches when that face is at or below the surface (phi within
        :data:`SPONGE_MAX_TILT_RAD` of 90 deg), and wipes the square it sweeps.

        Both touch only after coming down onto the surface from above: a tip
        that reaches the board's plane from beside the board or from beneath
        it (the power-on pose hangs below the plane) is inside the board or
        its stand, a collision (:attr:`Contact.pen_collision_count`), and
        does not write.
        """
        if type(q) is tuple:  # the robot's board stage passes a tuple
            q1, q2, q3, q4 = q
        elif type(q) is np.ndarray:
            q1, q2, q3, q4 = q.tolist()
        else:
            q1, q2, q3, q4 = (float(v) for v in q)
        x, y, z, _, s1, c1, sa, ca = arm_chain_py(q1, q2, q3, q4, self._L1, self._L2, self._L3, self._L4,
                                                  self._lf)
        if not (z == z and q1 == q1):
            raise WhiteboardError(f"joint angles must be finite, got {[q1, q2, q3, q4]}")
        self._t = t
        self._seq += 1
        depth = self._surface - z
        if depth >= 0.0:
            self._pen_contact(t, x, y, s1, c1, sa, ca, depth)
        else:
            if self._pen_on:
                self._pen_lift()
            self._pen_above = True
            self._pen_colliding = False
        press = self._surface - (z - self._sp_off * sa)
        if press >= 0.0:
            if sa >= _SPONGE_MIN_SIN and (self._sp_on or self._sp_above):
                self._sponge_contact(x, y, s1, c1, ca, press)
                return
            self._sp_above = False
        else:
            self._sp_above = True
        if self._sp_on:
            self._sp_on = False
            self._sp_press = 0.0
            self._sp_over = False

    def _pen_contact(self, t: float, x: float, y: float, s1: float, c1: float, sa: float, ca: float,
                     depth: float) -> None:
        if ca >= _PEN_MIN_COS:
            comp = depth / ca
            cx = x + comp * s1 * sa  # p - comp * u, u = (-s1 sa, c1 sa, -ca)
            cy = y - comp * c1 * sa
            over = comp > self._travel
        else:  # the pen lies too flat to slide back: a jam
            comp, cx, cy, over = depth, x, y, True
        if not (self._x0 <= cx <= self._x1 and self._y0 <= cy <= self._y1):
            if self._pen_on:  # beyond the board's edge there is nothing to touch
                self._pen_lift()
            self._pen_above = self._pen_colliding = False  # below the board's plane, beside it
            return
        if not (self._pen_on or self._pen_above):
            # The tip came into the board from its edge or from beneath: a
            # collision with the board or its stand (zone_depth thick), not writing.
            colliding = depth <= self._zone_depth
            if colliding and not self._pen_colliding:
                self._collision_count += 1
            self._pen_colliding = colliding
            return
        if over and not self._pen_over:
            self._pen_over_count += 1
        self._pen_over = over
        self._compression = comp
        self._cx, self._cy = cx, cy
        if not self._pen_on:
            self._pen_on = True
            self._tip_x = self._ink_x = cx
            self._tip_y = self._ink_y = cy
            ink_capsule(self._ink, self._x0, self._y0, self._res, cx, cy, cx, cy, self._radius, 1)
            self._run_x.append(cx)
            self._run_y.append(cy)
            self._run_t.append(t)
            self._run_seq.append(self._seq)
            self._cache = None
            return
        dx = cx - self._tip_x
        dy = cy - self._tip_y
        dist = math.hypot(dx, dy)
        if dist > self._tip_dev:  # the holder drags the tip along, L_s behind
            k = self._tip_dev / dist
            self._tip_x = cx - dx * k
            self._tip_y = cy - dy * k
            dist = self._tip_dev
        if dist > self._max_drag:
            self._max_drag = dist
        tx, ty = self._tip_x, self._tip_y
        step = math.hypot(tx - self._ink_x, ty - self._ink_y)
        if step >= self._min_step:
            ink_capsule(self._ink, self._x0, self._y0, self._res, self._ink_x, self._ink_y, tx, ty,
                        self._radius, 1)
            self._ink_x, self._ink_y = tx, ty
            self._append(tx, ty, t, step)

    def _append(self, x: float, y: float, t: float, step: float) -> None:
        """Add a point to the running stroke, with intermediate points every pixel."""
        n = int(step / self._res)
        if n >= 1:  # keep points at most one pixel apart: a wipe then splits the stroke exactly
            x_last, y_last, t_last = self._run_x[-1], self._run_y[-1], self._run_t[-1]
            for k in range(1, n + 1):
                f = k / (n + 1)
                self._run_x.append(x_last + f * (x - x_last))
                self._run_y.append(y_last + f * (y - y_last))
                self._run_t.append(t_last + f * (t - t_last))
                self._run_seq.append(self._seq)
        self._run_x.append(x)
        self._run_y.append(y)
        self._run_t.append(t)
        self._run_seq.append(self._seq)

    def _pen_lift(self) -> None:
        if (self._tip_x, self._tip_y) != (self._run_x[-1], self._run_y[-1]):
            # the tip crept less than the point spacing since the last point: finish there
            step = math.hypot(self._tip_x - self._ink_x, self._tip_y - self._ink_y)
            ink_capsule(self._ink, self._x0, self._y0, self._res, self._ink_x, self._ink_y,
                        self._tip_x, self._tip_y, self._radius, 1)
            self._append(self._tip_x, self._tip_y, self._t, step)
        self._strokes.append(_StrokeData(
            "robot", INK_WIDTH_M, np.array(self._run_x), np.array(self._run_y),
            np.array(self._run_t), np.array(self._run_seq, dtype=np.int64)))
        self._run_x, self._run_y, self._run_t, self._run_seq = [], [], [], []
        self._pen_on = False
        self._compression = 0.0
        self._pen_over = False
        self._cache = None

    def _sponge_contact(self, x: float, y: float, s1: float, c1: float, ca: float, press: float) -> None:
        fx = x + self._sp_off * s1 * ca  # p + offset n, n = (s1 ca, -c1 ca, -sa)
        fy = y - self._sp_off * c1 * ca
        h = self._sp_half
        if not (self._x0 - h <= fx <= self._x1 + h and self._y0 - h <= fy <= self._y1 + h):
            self._sp_on, self._sp_press, self._sp_over = False, 0.0, False  # beyond the board
            return
        over = press > self._sp_comp
        if over and not self._sp_over:
            self._sp_over_count += 1
        self._sp_over = over
        self._sp_press = press
        if self._sp_on:
            if abs(fx - self._sp_x) + abs(fy - self._sp_y) < self._min_step:
                return  # not moved: nothing new under the pad
            wiped = wipe_sweep(self._ink, self._stamp, self._x0, self._y0, self._res, h,
                               self._sp_x, self._sp_y, self._sp_c, self._sp_s, fx, fy, c1, s1,
                               True, self._seq)
        else:
            self._sp_on = True
            wiped = wipe_sweep(self._ink, self._stamp, self._x0, self._y0, self._res, h,
                               fx, fy, c1, s1, fx, fy, c1, s1, False, self._seq)
        self._sp_x, self._sp_y, self._sp_c, self._sp_s = fx, fy, c1, s1
        if wiped:
            self.wiped_pixels += wiped
            self._last_wipe_seq = self._seq
            self._cache = None

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
        if author not in _AUTHOR_CODES:
            raise WhiteboardError(f"author must be one of {sorted(_AUTHOR_CODES)}, got {author!r}")
        pts = np.asarray(points_m, dtype=float)
        if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 1:
            raise WhiteboardError(f"points_m must have shape (N, 2) with N >= 1, got {pts.shape}")
        if not np.isfinite(pts).all():
            raise WhiteboardError("points_m must be finite")
        x0, x1, y0, y1 = self.extent
        if (pts[:, 0].min() < x0 or pts[:, 0].max() > x1 or pts[:, 1].min() < y0
                or pts[:, 1].max() > y1):
            raise WhiteboardError(f"points_m must lie on the board x in [{x0:.3f}, {x1:.3f}] m, "
                                  f"y in [{y0:.3f}, {y1:.3f}] m")
        width_m = width_mm * 1e-3
        if not width_m >= 1.5 * self._res:
            raise WhiteboardError(f"width_mm must be at least 1.5 pixels "
                                  f"({1.5 * self._res * 1e3:.2f} mm), got {width_mm!r}")
        if not jitter_mm >= 0.0:
            raise WhiteboardError(f"jitter_mm must be >= 0, got {jitter_mm!r}")
        # densify to half a pixel, so that wobble and wipes resolve along the path
        seg = np.hypot(*np.diff(pts, axis=0).T) if len(pts) > 1 else np.zeros(0)
        s = np.concatenate(([0.0], np.cumsum(seg)))
        n = max(1, int(math.ceil(s[-1] / (self._res / 2))) + 1) if s[-1] > 0 else 1
        s_new = np.linspace(0.0, s[-1], n)
        if s[-1] > 0:
            xs = np.interp(s_new, s, pts[:, 0])
            ys = np.interp(s_new, s, pts[:, 1])
        else:
            xs, ys = pts[:1, 0].copy(), pts[:1, 1].copy()
        if jitter_mm > 0.0:
            amp = jitter_mm * 1e-3
            for arr in (xs, ys):
                lam = self._rng.uniform((0.012, 0.003), (0.030, 0.007))
                phase = self._rng.uniform(0.0, 2 * math.pi, 2)
                arr += amp * (0.7 * np.sin(2 * math.pi * s_new / lam[0] + phase[0])
                              + 0.3 * np.sin(2 * math.pi * s_new / lam[1] + phase[1]))
            np.clip(xs, x0, x1, out=xs)
            np.clip(ys, y0, y1, out=ys)
        self._seq += 1
        t0 = self._t if t is None else float(t)
        times = t0 + s_new / HAND_SPEED_M_S
        ink_polyline(self._ink, self._x0, self._y0, self._res, xs, ys, width_m / 2,
                     _AUTHOR_CODES[author])
        data = _StrokeData(author, width_m, xs, ys, times, np.full(len(xs), self._seq, np.int64))
        data.checked = self._seq
        self._strokes.append(data)
        self._cache = None
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
        x_lo, x_hi, y_lo, y_hi = self.cell_bounds(row, column)
        xc, yc = (x_lo + x_hi) / 2, (y_lo + y_hi) / 2  # eqs. 3.45-3.46
        half = size * self.params.board.cell_size / 2
        turn = 0.0
        if jitter_mm > 0.0:
            k = jitter_mm / (HAND_JITTER_M * 1e3)
            off = self._rng.uniform(-2.5, 2.5, 2) * jitter_mm * 1e-3
            xc, yc = xc + off[0], yc + off[1]
            half *= 1.0 + 0.08 * k * self._rng.uniform(-1.0, 1.0)
            turn = math.radians(6.0) * k * self._rng.uniform(-1.0, 1.0)
        ct, st = math.cos(turn), math.sin(turn)

        def place(u: np.ndarray, v: np.ndarray) -> np.ndarray:
            return np.column_stack((xc + ct * u - st * v, yc + st * u + ct * v))

        if kind_u == "X":
            d = np.array([-half, half])
            paths = [place(d, d), place(d, -d)]  # the 45 and 135 deg lines of fig. 3.26
        else:
            start = self._rng.uniform(0.0, 2 * math.pi) if jitter_mm > 0.0 else 0.0
            ang = start + np.linspace(0.0, 2 * math.pi * 1.04, 150)  # closes with a small overlap
            paths = [place(half * np.cos(ang), half * np.sin(ang))]
        return tuple(self.draw_stroke(p, width_mm, jitter_mm=jitter_mm, t=t) for p in paths)

    # ------------------------------------------------------------------ cells and regions

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

    def _slices(self, region: Region | None) -> tuple[slice, slice]:
        """Raster rows and columns whose pixel centres lie in `region` (default: all)."""
        if region is None:
            return slice(None), slice(None)
        x_lo, x_hi, y_lo, y_hi = (float(v) for v in region)
        if not (x_lo < x_hi and y_lo < y_hi):
            raise WhiteboardError(f"region must be (x_min, x_max, y_min, y_max) with min < max, "
                                  f"got {region!r}")
        ny, nx = self._ink.shape
        i0 = max(0, math.ceil((x_lo - self._x0) / self._res - 0.5))
        i1 = min(nx - 1, math.floor((x_hi - self._x0) / self._res - 0.5))
        j0 = max(0, math.ceil((y_lo - self._y0) / self._res - 0.5))
        j1 = min(ny - 1, math.floor((y_hi - self._y0) / self._res - 0.5))
        if i0 > i1 or j0 > j1:
            raise WhiteboardError(f"region {region!r} does not overlap the board {self.extent!r}")
        return slice(j0, j1 + 1), slice(i0, i1 + 1)

    def pixel_centers_m(self, mask: np.ndarray) -> np.ndarray:
        """(x, y) in metres of the True pixels of a raster-shaped mask, shape (N, 2)."""
        iy, ix = np.nonzero(mask)
        return np.column_stack((self._x0 + (ix + 0.5) * self._res, self._y0 + (iy + 0.5) * self._res))

    # ------------------------------------------------------------------ queries

    @property
    def strokes(self) -> tuple[Stroke, ...]:
        """Every stroke on the board, oldest first, the pen's running one last.

        A sponge pass removes the points it wiped and splits a stroke it
        crossed, so the strokes always describe the ink that is left.
        """
        if self._cache is None:
            self._apply_wipes()
            self._cache = tuple(s.snapshot() for s in self._strokes)
        if not self._run_x:
            return self._cache
        run = _StrokeData("robot", INK_WIDTH_M, np.array(self._run_x), np.array(self._run_y),
                          np.array(self._run_t), np.array(self._run_seq, dtype=np.int64))
        return self._cache + tuple(piece.snapshot() for piece in self._split(run))

    def _apply_wipes(self) -> None:
        if all(s.checked >= self._last_wipe_seq for s in self._strokes):
            return
        kept: list[_StrokeData] = []
        for s in self._strokes:
            kept.extend(self._split(s) if s.checked < self._last_wipe_seq else [s])
        self._strokes = kept

    def _split(self, s: _StrokeData) -> list[_StrokeData]:
        """The pieces of a stroke that no later wipe removed."""
        ny, nx = self._ink.shape
        ix = np.clip(((s.x - self._x0) / self._res).astype(np.int64), 0, nx - 1)
        iy = np.clip(((s.y - self._y0) / self._res).astype(np.int64), 0, ny - 1)
        keep = self._stamp[iy, ix] < s.seq
        s.checked = self._last_wipe_seq
        if keep.all():
            return [s]
        edges = np.flatnonzero(np.diff(np.concatenate(([False], keep, [False])).astype(np.int8)))
        pieces = []
        for a, b in zip(edges[::2], edges[1::2], strict=True):
            piece = _StrokeData(s.author, s.width_m, s.x[a:b].copy(), s.y[a:b].copy(),
                                s.t[a:b].copy(), s.seq[a:b].copy())
            piece.checked = self._last_wipe_seq
            pieces.append(piece)
        return pieces

    def ink_mask(self) -> np.ndarray:
        """The inked pixels, bool, shape :attr:`shape` (row index along y, column along x)."""
        return self._ink != 0

    def ink_area_mm2(self, region: Region | None = None) -> float:
        """Inked area, mm^2, of the board or of a region (x_min, x_max, y_min, y_max) in m."""
        rows, cols = self._slices(region)
        return float(np.count_nonzero(self._ink[rows, cols])) * (self._res * 1e3) ** 2

    def ink_outside(self, polylines: Sequence[Any], tol_m: float) -> np.ndarray:
        """Ink pixels farther than `tol_m` from every desired polyline.

        Parameters
        ----------
        polylines : sequence of array_like, each shape (N, 2)
            Desired paths, metres.
        tol_m : float
            Half-width of the tolerance band around them, m.

        Returns
        -------
        np.ndarray, bool, shape :attr:`shape`
            Pen-lift and pen-lower tails, stray marks; :meth:`pixel_centers_m`
            turns it into coordinates.
        """
        if not tol_m >= 0.0:
            raise WhiteboardError(f"tol_m must be >= 0, got {tol_m!r}")
        band = np.zeros_like(self._ink)
        for line in polylines:
            p = np.asarray(line, dtype=float)
            if p.ndim != 2 or p.shape[1] != 2 or len(p) < 1:
                raise WhiteboardError(f"each polyline must have shape (N, 2), got {p.shape}")
            ink_polyline(band, self._x0, self._y0, self._res, np.ascontiguousarray(p[:, 0]),
                         np.ascontiguousarray(p[:, 1]), float(tol_m), 1)
        return (self._ink != 0) & (band == 0)

    def longest_tail_mm(self, desired_polylines: Sequence[Any], tol_m: float = TAIL_TOL_M) -> float:
        """Length of the longest connected run of ink outside the tolerance band, mm.

        The length of a run is its Feret diameter (largest distance between
        two of its pixel centres); only the part beyond `tol_m` from the
        desired path counts.  0.0 when all ink lies within the band.
        """
        outside = self.ink_outside(desired_polylines, tol_m).astype(np.uint8)
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
        return best * self._res * 1e3

    def cell_ink_fraction(self, row: int, column: int, margin_m: float = CELL_MARGIN_M) -> float:
        """Share of a cell that is inked, leaving `margin_m` clear of its grid lines."""
        x_lo, x_hi, y_lo, y_hi = self.cell_bounds(row, column)
        if not 0.0 <= margin_m < (x_hi - x_lo) / 2:
            raise WhiteboardError(f"margin_m must lie in [0, half a cell), got {margin_m!r}")
        rows, cols = self._slices((x_lo + margin_m, x_hi - margin_m, y_lo + margin_m, y_hi - margin_m))
        part = self._ink[rows, cols]
        return float(np.count_nonzero(part)) / part.size

    # ------------------------------------------------------------------ pictures

    def render(self, px_per_mm: float = 4.0, grid_mm: bool = False, region: Region | None = None, *,
               view: str = "field", desired: Sequence[Any] | None = None) -> np.ndarray:
        """Draw the board as a BGR image: white board, dark blue robot ink, black hand ink.

        Parameters
        ----------
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
        rows, cols = self._slices(region)
        sub = self._ink[rows, cols]
        i0 = cols.start or 0
        j0 = rows.start or 0
        rx0, ry0 = self._x0 + i0 * self._res, self._y0 + j0 * self._res
        px_per_m = px_per_mm * 1e3
        W = max(1, round(sub.shape[1] * self._res * px_per_m))
        H = max(1, round(sub.shape[0] * self._res * px_per_m))
        out = np.full((H, W, 3), 255, np.uint8)  # rows along +y, columns along +x for now
        if grid_mm:
            self._draw_grid(out, rx0, ry0, px_per_m)
        # INTER_AREA averages properly when shrinking a lot; near 1:1 it is slow and
        # INTER_LINEAR looks the same
        interp = cv2.INTER_AREA if px_per_m * self._res < 1 / 1.5 else cv2.INTER_LINEAR
        if sub.any():
            # coverage by robot and by hand ink (0..255) of every image pixel, in one resize
            full = np.uint8(255)
            two = cv2.merge([(sub == 1).view(np.uint8) * full, (sub == 2).view(np.uint8) * full])
            cover = cv2.resize(two, (W, H), interpolation=interp)
            at = cv2.findNonZero(cv2.bitwise_or(cover[:, :, 0], cover[:, :, 1]))
            if at is not None:  # blend only where there is ink: a few % of the image
                at = at.reshape(-1, 2)
                cols, rows = at[:, 0], at[:, 1]
                c = cover[rows, cols].astype(np.float32) / 255.0
                under = out[rows, cols].astype(np.float32)
                blended = (under * (1.0 - np.minimum(c.sum(axis=1, keepdims=True), 1.0))
                           + c[:, :1] * np.asarray(ROBOT_INK_BGR, np.float32)
                           + c[:, 1:] * np.asarray(HAND_INK_BGR, np.float32))
                out[rows, cols] = np.clip(blended + 0.5, 0, 255).astype(np.uint8)
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

    @staticmethod
    def _draw_grid(img: np.ndarray, rx0: float, ry0: float, px_per_m: float) -> None:
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

    def save_png(self, path: str | Path, **render_args: Any) -> Path:
        """Write :meth:`render` (same keyword arguments) to a PNG file; returns the path."""
        p = Path(path)
        image = self.render(**render_args)
        if not cv2.imwrite(str(p), image):
            raise WhiteboardError(f"{p}: could not write the PNG (does the folder exist?)")
        return p
