"""The Control chart's moves (thesis section 3.6.1): ``start_stop``'s actions and the pen moves every
sub-chart makes.

Every move is a straight line at a set speed, one increment per chart tick (eq. 3.36), towards a target held
in the chart's local data `tx`, `ty`, `tz`; the pen goes down and up at `z_speed`.  Mixed into
:class:`~.control.Control`, whose data these actions read and write.
"""

from __future__ import annotations

import math

from ..runtime import ChartActions, does


class PenMoves(ChartActions):
    """``start_stop``'s actions (from the start pose to the waiting pose, waiting) and the shared pen moves."""

    # for the type checker: data an action updates from its own previous value, and the period
    tick_period_s: float
    ctr: int
    ignored_buttons: int

    @does("x_start, y_start, z_start = X_now, Y_now, Z_now; X_out, Y_out, Z_out = X_now, Y_now, Z_now;"
          " phi = 0; aim(X_now, Y_now, z_safe)", summary="X_out, Y_out, Z_out = X_now, Y_now, Z_now")
    def take_start_pose(self) -> None:
        """Remember where the arm stands once initialised: finish returns there."""
        self.x_start, self.y_start, self.z_start = self.X_now, self.Y_now, self.Z_now
        self.X_out, self.Y_out, self.Z_out, self.phi = self.X_now, self.Y_now, self.Z_now, 0.0
        self._aim(self.X_now, self.Y_now, self.z_safe)

    def during_rise(self) -> None:
        self._move(self.z_speed * 2)

    def aim_over_wait(self) -> None:
        self._aim(self.x_wait, self.y_wait, self.z_safe)

    def during_go_over(self) -> None:
        self._move(self.travel_speed)

    @does("X_out, Y_out, Z_out = x_wait, y_wait, z_wait; phi = 0; fr_sw = True")
    def on_enter_go_wait(self) -> None:
        # the thesis' wait_1: a step to the waiting pose, smoothed by slow filters
        self.X_out, self.Y_out, self.Z_out, self.phi = self.x_wait, self.y_wait, self.z_wait, 0.0
        self.fr_sw = True

    def on_exit_go_wait(self) -> None:
        self.fr_sw = False
        self._aim(self.X_out, self.Y_out, self.Z_out)

    # what others read of the chart's state: outputs, set on entry and exit (free on quiet ticks)
    def on_enter_wait_1(self) -> None:
        self.busy = False
        self.ready = bool(self.Pl_fld)

    def on_exit_wait_1(self) -> None:
        self.busy = True
        self.ready = False

    @does("ignored_buttons += 1")
    def ignore_button(self) -> None:
        self.ignored_buttons = self.ignored_buttons + 1

    def count_symbol(self) -> None:
        self.ctr = self.ctr + 1

    # ----------------------------------------------- shared pen moves

    def _aim(self, x: float, y: float, z: float) -> None:
        self.tx, self.ty, self.tz = x, y, z

    def _move(self, speed: float) -> None:
        """One increment of a straight move towards (tx, ty, tz) at `speed` (eq. 3.36)."""
        dx, dy, dz = self.tx - self.X_out_p, self.ty - self.Y_out_p, self.tz - self.Z_out_p
        dist = math.sqrt(dx * dx + dy * dy + dz * dz)
        step = speed * self.tick_period_s
        if dist <= step:
            self.X_out, self.Y_out, self.Z_out = self.tx, self.ty, self.tz
        else:
            f = step / dist
            self.X_out, self.Y_out, self.Z_out = self.X_out_p + f * dx, self.Y_out_p + f * dy, self.Z_out_p + f * dz

    def aim_down(self) -> None:
        self._aim(self.X_out, self.Y_out, self.z_draw)

    def aim_up(self) -> None:
        self._aim(self.X_out, self.Y_out, self.z_up)

    def aim_travel(self) -> None:
        self._aim(self.X_out, self.Y_out, self.z_travel)

    @does("aim(X_out, Y_out, max(Z_out, z_safe)) if not isnan(X_out) else aim(x_start, y_start, z_start)",
          summary="aim(X_out, Y_out, max(Z_out, z_safe))")
    def aim_lift(self) -> None:
        """finish: straight up from wherever the pen is, turning phi back to 0 on the way."""
        if math.isnan(self.X_out):
            # finish came before the first move: the arm still stands at its start pose
            self.take_start_pose()
            self._aim(self.x_start, self.y_start, self.z_start)
            return
        self._aim(self.X_out, self.Y_out, max(self.Z_out, self.z_safe))

    def _vertical(self) -> None:
        self._move(self.z_speed)

    # the pen goes down and up at z_speed in every sub-chart
    during_field_pen_down = during_field_pen_up = during_field_lift_off = _vertical
    during_x_pen_down = during_x_pen_up = during_x_pen_down_2 = during_x_pen_up_2 = _vertical
    during_x_lift_off = _vertical
    during_o_pen_down = during_o_pen_up = during_o_lift_off = _vertical
    during_s_pen_down = during_s_pen_up = during_s_lift_off = _vertical
