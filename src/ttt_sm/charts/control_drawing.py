"""The Control chart's drawings (thesis section 3.6.1, figs. 3.25-3.27): the playing field, the X, the
four-arc O and the sine wave, with eqs. 3.36-3.51.

One class per sub-chart, mixed into :class:`~.control.Control`, whose data these actions read and write; the
geometry (the field's lines, the X's and the O's points) is :mod:`.geometry`'s.
"""

from __future__ import annotations

import math

from ..runtime import ChartActions, does
from .geometry import (
    O_START,
    arc_end,
    circle_point,
    circle_x,
    circle_y,
    field_line,
    o_centre,
    o_radius,
    on_x_line_1,
    on_x_line_2,
    x_line_1,
    x_line_2,
    x_start,
)


class FieldDrawing(ChartActions):
    """``Drawing_playing_field``: 4 lines parallel to X and 4 parallel to Y (eq. 3.36)."""

    def _field_line(self, k: int) -> tuple[float, float, float, float]:
        """Start and end (x, y) of field line k: 0-3 parallel to X, 4-7 parallel to Y."""
        return field_line(self.x11, self.y11, self.L, self.cells, k)

    @does("k = 0; aim(field_start(0), z_up)")
    def on_enter_Drawing_playing_field(self) -> None:
        self.k = 0
        x, y, _, _ = self._field_line(0)
        self._aim(x, y, self.z_up)

    def during_to_line(self) -> None:
        self._move(self.travel_speed)

    @does("aim(field_end(k), z_draw)")
    def aim_line_end(self) -> None:
        _, _, x, y = self._field_line(self.k)
        self._aim(x, y, self.z_draw)

    @does("move(speed) (eq. 3.36)")
    def during_line(self) -> None:
        # eq. 3.36: one coordinate changes by inc per tick, the other stays
        self._move(self.speed)

    @does("k = k + 1; aim(field_start(k), z_up)")
    def next_line(self) -> None:
        self.k = self.k + 1
        x, y, _, _ = self._field_line(self.k)
        self._aim(x, y, self.z_up)

    @does("Pl_fld = True; aim(X_out, Y_out, z_travel)")
    def field_done(self) -> None:
        self.Pl_fld = True
        self.aim_travel()


class XDrawing(ChartActions):
    """``Drawing_X`` in cell (row, column): two lines at 45 degrees (eqs. 3.37-3.44)."""

    @does("x_ini = x11 - (column-1)*L - (L-size)/2 (eq. 3.37); y_ini = y11 - (row-1)*L - (L-size)/2 (eq. 3.38);"
          " h1 = y_ini - x_ini (eq. 3.39); aim(x_ini, y_ini, z_up)")
    def on_enter_Drawing_X(self) -> None:
        # eqs. 3.37-3.38, with the symbol size as a parameter: L/5 margins for size 3L/5
        self.x_ini, self.y_ini = x_start(self.x11, self.y11, self.L, self.row, self.column, self.size)
        self.h1 = x_line_1(self.x_ini, self.y_ini)  # eq. 3.39
        self._aim(self.x_ini, self.y_ini, self.z_up)

    def _travel(self) -> None:
        self._move(self.travel_speed)

    during_x_to_start = during_o_to_start = during_s_to_start = _travel

    @does("X_out = max(X_out_p - inc, x_ini - size) (eq. 3.40); Y_out = X_out + h1 (eq. 3.41)")
    def during_line_1(self) -> None:
        # eqs. 3.40-3.41: X decreases, Y follows the 45-degree line Y = X + h1
        self.X_out = max(self.X_out_p - self.speed * self.tick_period_s / math.sqrt(2), self.x_ini - self.size)
        self.Y_out = on_x_line_1(self.X_out, self.h1)

    @does("Y_end = Y_out; aim(X_out, Y_out, z_up)")
    def end_line_1(self) -> None:
        self.Y_end = self.Y_out
        self.aim_up()

    @does("h2 = Y_end + x_ini (eq. 3.42); aim(x_ini, Y_end, z_up)")
    def aim_line_2(self) -> None:
        # eq. 3.42: the second line starts at (x_ini, Y_end)
        self.h2 = x_line_2(self.Y_end, self.x_ini)
        self._aim(self.x_ini, self.Y_end, self.z_up)

    def during_to_line_2(self) -> None:
        self._move(self.travel_speed)

    @does("X_out = max(X_out_p - inc, x_ini - size) (eq. 3.43); Y_out = -X_out + h2 (eq. 3.44)")
    def during_line_2(self) -> None:
        # eqs. 3.43-3.44: Y = -X + h2; X decreases (the printed '+' would leave the cell)
        self.X_out = max(self.X_out_p - self.speed * self.tick_period_s / math.sqrt(2), self.x_ini - self.size)
        self.Y_out = on_x_line_2(self.X_out, self.h2)


class ODrawing(ChartActions):
    """``Drawing_O`` in cell (row, column): four arcs, each a bit over a quarter (eqs. 3.45-3.51)."""

    @does("x0 = x11 - (column-1)*L - L/2 (eq. 3.45); y0 = y11 - (row-1)*L - L/2 (eq. 3.46);"
          " R = size/2 (eq. 3.47); aim(circle(-pi/4), z_up)")
    def on_enter_Drawing_O(self) -> None:
        # eqs. 3.45-3.47; R = size/2 (the printed R = L/4 is the size L/2)
        self.x0, self.y0 = o_centre(self.x11, self.y11, self.L, self.row, self.column)
        self.R = o_radius(self.size)
        # part 1 starts at the lower right: eq. 3.48 decreases X along the lower half (eq. 3.49)
        self._aim(*circle_point(self.x0, self.y0, self.R, O_START), self.z_up)

    @does("k = 0; arc_end = -pi/4 - (k+1)*(pi/2 + arc_overlap); aim(circle(arc_end), z_draw)")
    def start_arc_1(self) -> None:
        self.k = 0
        self._aim_arc()

    @does("k = k + 1; arc_end = -pi/4 - (k+1)*(pi/2 + arc_overlap); aim(circle(arc_end), z_draw)")
    def next_arc(self) -> None:
        self.k = self.k + 1
        self._aim_arc()

    def _aim_arc(self) -> None:
        """End point of arc k: a quarter plus the overlap, clockwise from -45 deg (eqs. 3.48-3.51)."""
        self.arc_end = arc_end(self.k, self.arc_overlap)
        self._aim(*circle_point(self.x0, self.y0, self.R, self.arc_end), self.z_draw)

    def _arc_step(self) -> float:
        return self.speed * self.tick_period_s * math.sqrt(0.5)

    @does("X_out = max(X_out_p - inc, tx) (eq. 3.48); Y_out = -sqrt(R^2 - (X_out - x0)^2) + y0 (eq. 3.49)")
    def during_arc_1(self) -> None:
        # eqs. 3.48-3.49: X decreases along the lower half, Y from the circle (the negative root)
        self.X_out = max(self.X_out_p - self._arc_step(), self.tx)
        self.Y_out = circle_y(self.X_out, self.x0, self.y0, self.R, -1.0)
        if self.X_out == self.tx:
            self.Y_out = self.ty

    @does("Y_out = min(Y_out_p + inc, ty) (eq. 3.50); X_out = -sqrt(R^2 - (Y_out - y0)^2) + x0 (eq. 3.51)")
    def during_arc_2(self) -> None:
        # eqs. 3.50-3.51: Y increases along the left half, X from the circle (the negative root)
        self.Y_out = min(self.Y_out_p + self._arc_step(), self.ty)
        self.X_out = circle_x(self.Y_out, self.x0, self.y0, self.R, -1.0)
        if self.Y_out == self.ty:
            self.X_out = self.tx

    @does("X_out = min(X_out_p + inc, tx); Y_out = sqrt(R^2 - (X_out - x0)^2) + y0")
    def during_arc_3(self) -> None:
        # like part 1, "X_out is incremented" and the root positive: the upper half
        self.X_out = min(self.X_out_p + self._arc_step(), self.tx)
        self.Y_out = circle_y(self.X_out, self.x0, self.y0, self.R, 1.0)
        if self.X_out == self.tx:
            self.Y_out = self.ty

    @does("Y_out = max(Y_out_p - inc, ty); X_out = sqrt(R^2 - (Y_out - y0)^2) + x0")
    def during_arc_4(self) -> None:
        # like part 2, "Y_out is decreased" and the root positive: the right half
        self.Y_out = max(self.Y_out_p - self._arc_step(), self.ty)
        self.X_out = circle_x(self.Y_out, self.x0, self.y0, self.R, 1.0)
        if self.Y_out == self.ty:
            self.X_out = self.tx


class SineDrawing(ChartActions):
    """``Drawing_sine``: the sine wave of section 3.5.3 along the field's middle row."""

    @does("x0 = x11 - (cells*L - sine_length)/2; y0 = y11 - cells*L/2; aim(x0, y0, z_up)")
    def on_enter_Drawing_sine(self) -> None:
        # along the middle row of the field, from its right edge (section 3.5.3)
        self.x0 = self.x11 - (self.cells * self.L - self.sine_length) / 2
        self.y0 = self.y11 - self.cells * self.L / 2
        self._aim(self.x0, self.y0, self.z_up)

    def aim_wave_end(self) -> None:
        self.tx = self.x0 - self.sine_length

    @does("X_out = max(X_out_p - inc, tx); Y_out = y0 + sine_amplitude*sin(2*pi*sine_periods*(x0 - X_out)/sine_length)",
          summary="X_out = max(X_out_p - inc, tx); Y_out = y0 + sine_amplitude*sin(...)")
    def during_wave(self) -> None:
        # X decreases by a set increment; Y follows the sine
        self.X_out = max(self.X_out_p - self.speed * self.tick_period_s * 0.5, self.tx)
        s = (self.x0 - self.X_out) / self.sine_length
        self.Y_out = self.y0 + self.sine_amplitude * math.sin(2 * math.pi * self.sine_periods * s)
