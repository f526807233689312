"""Contact physics: the spring-loaded pen inks, the sponge wipes (thesis sections 3.3.1 and 3.6.1).

:meth:`BoardContact.update` takes the arm's TRUE joint angles every chart
step and works out what touches the board: the pen (its slide into the
holder, the tip's drag in the holder's clearance, eqs. 3.1-3.13, and what it
inks), the sponge (what its pad wipes), and collisions with the board's
edge or stand.  It runs at every chart step of every simulated game, so it
is written for plain floats: one call of the forward kinematics chain, then
attribute arithmetic and the compiled raster kernels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ttt_sm.params import ArmParams
from ttt_sm.twin._ink import ink_capsule, wipe_sweep
from ttt_sm.twin.kinematics import arm_chain_py

from .errors import WhiteboardError
from .pen_deviation import THESIS_CLEARANCE_M, THESIS_HOLDER, pen_deviation
from .raster import InkRaster
from .strokes import StrokeData, StrokeLog

#: Line width of the robot's whiteboard marker (m).
INK_WIDTH_M = 0.8e-3
#: Largest tip deviation over the holder clearance: L_s computed by eqs. 3.1-3.13 for the thesis' holder
#: (0.35 mm) over the clearance section 3.3.1 names for it (0.4 mm); :mod:`.pen_deviation`.
TIP_DEVIATION_PER_CLEARANCE = pen_deviation(THESIS_HOLDER).deviation_m / THESIS_CLEARANCE_M
#: Beyond this tilt of the tool axis the spring cannot push the pen back along it:
#: a tip below the surface is then a jam, counted as an overpress.
PEN_MAX_TILT_RAD = math.radians(60.0)
#: The sponge's face counts as lying on the board within this angle of phi = 90 deg.
SPONGE_MAX_TILT_RAD = math.radians(20.0)

_PEN_MIN_COS = math.cos(PEN_MAX_TILT_RAD)
_SPONGE_MIN_SIN = math.cos(SPONGE_MAX_TILT_RAD)


@dataclass(frozen=True)
class Contact:
    """What touches the board after the last :meth:`BoardContact.update`.

    Attributes
    ----------
    pen_touching : bool
        The pen tip rests on the board (and inks).
    pen_colliding : bool
        The pen tip is inside the board or its stand (``zone_depth`` below
        the surface), having come in from the edge or from beneath: a
        collision, not writing.
    pen_collision_count : int
        Such collisions since the reset (rising edges).
    compression_m : float
        How far the pen is pushed into its holder along the tool axis, m.
    pen_overpress : bool
        Pushed beyond ``spring_travel`` (the holder hits the board) or jammed
        at a tilt beyond :data:`PEN_MAX_TILT_RAD`.
    pen_overpress_count : int
        Overpress events since the reset (rising edges).
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


class BoardContact:
    """The arm on the board: where the pen inks and the sponge wipes, from the true joint angles.

    Parameters
    ----------
    params : ArmParams
        Geometry (forward kinematics), ``[board]``, ``[pen]`` and ``[sponge]``.
    raster : InkRaster
        The board's pixels, inked and wiped in place.
    log : StrokeLog
        Where a stroke goes when the pen lifts, and which hears of wipes.

    Notes
    -----
    The update sequence number (``_seq``, one per :meth:`update`) and the time
    of the last update (``_t``) stamp stroke points and wipes; a person's
    stroke (the :class:`~ttt_sm.twin.whiteboard.Whiteboard`) takes the next
    number too, so the order of pen, hand and sponge is kept.
    """

    def __init__(self, params: ArmParams, raster: InkRaster, log: StrokeLog) -> None:
        g, b = params.true_geometry, params.board  # the true pen: the arm as built
        self._L1, self._L2, self._L3, self._L4, self._lf = g.L1, g.L2, g.L3, g.L4, g.l_f
        self._surface = b.surface_z
        self._raster, self._log = raster, log
        # the raster's arrays and frame as plain attributes: read at every update
        self._ink, self._stamp = raster.ink, raster.stamp
        self._res = raster.res
        self._x0, self._y0, self._x1, self._y1 = raster.x0, raster.y0, raster.x1, raster.y1
        self._travel = params.pen.spring_travel
        self._zone_depth = b.zone_depth
        self._tip_dev = params.pen.holder_clearance * TIP_DEVIATION_PER_CLEARANCE
        self._sp_off = params.sponge.offset
        self._sp_half = params.sponge.width / 2
        self._sp_comp = params.sponge.compliance
        self._radius = INK_WIDTH_M / 2
        self._min_step = self._res / 4  # stroke points closer than this are not stored
        self.reset()

    def reset(self) -> None:
        """Nothing touching, counters zero, update sequence and time back to 0 (the ink is the raster's)."""
        self._seq = 0
        self._t = 0.0
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
    def tip_deviation_m(self) -> float:
        """Largest drag of the pen tip in its holder (L_s of eq. 3.13), m."""
        return self._tip_dev

    @property
    def ink_version(self) -> tuple[int, int, int]:
        """Changes whenever the ink may have changed (a view draws it again then).

        Strokes kept so far, points of the pen's running stroke, pixels wiped
        since the reset: nothing inks or wipes without changing one of them.
        """
        return self._log.added, len(self._run_x), self.wiped_pixels

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

    def running_stroke(self) -> StrokeData | None:
        """The pen's stroke still being drawn (None while the pen is up)."""
        if not self._run_x:
            return None
        return StrokeData("robot", INK_WIDTH_M, np.array(self._run_x), np.array(self._run_y),
                          np.array(self._run_t), np.array(self._run_seq, dtype=np.int64))

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
            self._log.changed()
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
        self._log.add(StrokeData(
            "robot", INK_WIDTH_M, np.array(self._run_x), np.array(self._run_y),
            np.array(self._run_t), np.array(self._run_seq, dtype=np.int64)))
        self._run_x, self._run_y, self._run_t, self._run_seq = [], [], [], []
        self._pen_on = False
        self._compression = 0.0
        self._pen_over = False

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
            self._log.wiped(self._seq)
