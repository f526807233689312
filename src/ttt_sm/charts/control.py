"""The Control chart of thesis section 3.6.1 (figs. 3.23-3.27): what the pen does.

It turns the game's commands into tool poses, one per chart tick: `X_out`,
`Y_out`, `Z_out` (metres) and `phi` (rad), plus `fr_sw`, which slows the
setpoint filters.  Its sub-charts are compound states, as in fig. 3.24:

- ``start_stop``: waits for the drives to be initialised, rises from the
  start pose and moves above the board without touching it, then ``go_wait``
  steps to the waiting pose beside the board with the slow filters (the
  thesis' ``wait_1`` "step" with a lowered cut-off) and ``wait_1`` waits.
- ``Drawing_playing_field``: 4 lines parallel to X and 4 parallel to Y, each
  drawn by incrementing one coordinate per tick (eq. 3.36); the pen is lowered
  and lifted by Z between lines; sets the field flag `Pl_fld`.
- ``Drawing_X`` (eqs. 3.37-3.44) and ``Drawing_O`` (four arcs, each a bit
  over a quarter so the circle closes, eqs. 3.45-3.51) in cell (row, column),
  on the ``button`` event.
- ``Drawing_sine``: the sine wave of section 3.5.3, on the ``draw_sine`` event.
- ``Erase``: phi to 90 deg, sponge down, passes along Y 3 cm apart over the
  field, flag and counter reset, phi back to 0; then the field is redrawn.
- ``finishing``: `finish` at any moment (also mid-stroke) lifts the pen and
  returns the arm to its start pose.

A ``button`` that arrives while the arm is busy (anything but ``wait_1``, or
``wait_1`` with the field or an erase still to do) is ignored and counted in
`ignored_buttons`: a drawing is never started twice, the field and erasing
come first, and the person presses again once the arm waits (the GUI shows
when).  (One that arrives in the very wake-up that leaves ``wait_1`` to erase
or to draw the field is not counted: that transition takes the wake-up.)
A ``draw_sine`` then is dropped.  ``finish`` before the first move
ends at once: the arm still stands at its start pose.

Every move is a straight line at a set speed, one increment per tick, towards
a target held in the local data `tx`, `ty`, `tz`; a state's exit guard is
"target reached".  The field's, the cells' and the symbols' geometry are pure
functions in :mod:`ttt_sm.charts.geometry`; their inputs (the field's corner,
the cell side, heights, the waiting pose) are local data the application sets
from the parameter file.
"""

from __future__ import annotations

import math

from statemachine import State

from ..runtime import Data, TickChart, action_on, does
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
    pass_ends,
    pass_x,
    x_line_1,
    x_line_2,
    x_start,
)


class Control(TickChart):
    """The Control block: start/stop, the field, X, O, a sine wave, erasing, finishing."""

    timed = True  # speeds are per second: a step per tick is speed * tick_period_s
    # for type checkers: data that actions update from their own previous value, and the period
    tick_period_s: float
    ctr: int
    ignored_buttons: int

    inputs = (
        Data("row", "1", 1, "row of the cell to draw in, 1..5 (eq. 3.38)", limits=(1, 5)),
        Data("column", "1", 1, "column of the cell to draw in, 1..5 (eq. 3.37)", limits=(1, 5)),
        Data("symbol", "1", 1, "symbol the button draws: 1 = X, 0 = O"),
        Data("finish", "bool", False, "1: finish the application, return to the start pose"),
        Data("erase", "bool", False, "erasing flag: erase the board at the next wait"),
        Data("initialised", "bool", False, "every drive passes its position through (init charts)"),
        Data("X_now", "m", 0.0, "tool x by forward kinematics of the encoders"),
        Data("Y_now", "m", 0.0, "tool y by forward kinematics of the encoders"),
        Data("Z_now", "m", 0.0, "tool z by forward kinematics of the encoders"),
        Data("speed", "m/s", 0.02, "drawing speed (the Operational GUI's speed)"),
        Data("size", "m", 0.018, "symbol size: the X's side, the O's diameter (GUI magnitude)"),
        Data("sine_amplitude", "m", 0.02, "amplitude of the sine wave (section 3.5.3)"),
    )
    outputs = (
        Data("X_out", "m", math.nan, "tool x; NaN until initialised (no command)"),
        Data("Y_out", "m", math.nan, "tool y"),
        Data("Z_out", "m", math.nan, "tool z (pen tip)"),
        Data("phi", "rad", 0.0, "tool angle about the global X axis (0: pen down, pi/2: sponge down)"),
        Data("fr_sw", "bool", False, "slow setpoint filters (the step to wait_1)"),
        Data("Pl_fld", "bool", False, "playing field flag: the field has been drawn"),
        Data("ctr", "1", 0, "symbols drawn by the manipulator"),
        Data("ready", "bool", False, "waits in wait_1 with the field drawn: a button draws now"),
        Data("busy", "bool", True, "anything but waiting in wait_1: initialising, moving, drawing, erasing"),
        Data("erasing", "bool", False, "in the Erase sub-chart"),
        Data("at_start", "bool", False, "finish is done: the arm is back at its start pose (finished)"),
    )
    local = (
        Data("x11", "m", 0.075, "x of the field's upper right corner (eqs. 3.37, 3.45)"),
        Data("y11", "m", 0.325, "y of the field's upper right corner (eqs. 3.38, 3.46)"),
        Data("L", "m", 0.03, "side of one cell"),
        Data("cells", "1", 5, "cells per row and column"),
        Data("z_draw", "m", -0.0015, "pen tip height while drawing: presses the spring-loaded pen"),
        Data("z_up", "m", 0.008, "pen tip height between strokes"),
        Data("z_travel", "m", 0.04, "height for moves to and from the waiting pose"),
        Data("z_safe", "m", 0.08, "height for moves from and to the start pose"),
        Data("z_sponge", "m", 0.0175, "tool height with the sponge pressed on the board (phi = 90 deg)"),
        Data("x_wait", "m", 0.16, "waiting pose beside the board, out of the camera's way"),
        Data("y_wait", "m", 0.12, "waiting pose y"),
        Data("z_wait", "m", 0.06, "waiting pose z"),
        Data("wait_tol", "m", 0.002, "the arm is at the waiting pose within this distance"),
        Data("travel_speed", "m/s", 0.06, "speed of pen-up moves"),
        Data("z_speed", "m/s", 0.02, "speed of lowering and lifting the pen"),
        Data("phi_rate", "rad/s", 1.0, "how fast phi turns for the sponge"),
        Data("wipe_speed", "m/s", 0.04, "speed of the sponge passes"),
        Data("arc_overlap", "rad", 0.035, "each quarter arc of the O is this much longer (closes it)"),
        Data("sine_length", "m", 0.12, "length of the sine wave along X"),
        Data("sine_periods", "1", 2.0, "periods of the sine wave"),
        Data("x_start", "m", 0.0, "start pose x (where the arm stood once initialised)"),
        Data("y_start", "m", 0.0, "start pose y"),
        Data("z_start", "m", 0.0, "start pose z"),
        Data("tx", "m", 0.0, "target x of the current move"),
        Data("ty", "m", 0.0, "target y of the current move"),
        Data("tz", "m", 0.0, "target z of the current move"),
        Data("k", "1", 0, "index of the current line, pass or arc"),
        Data("x_ini", "m", 0.0, "start of the X's first line (eq. 3.37)"),
        Data("y_ini", "m", 0.0, "start of the X's first line (eq. 3.38)"),
        Data("h1", "m", 0.0, "intersection of the X's first line with the Y axis (eq. 3.39)"),
        Data("h2", "m", 0.0, "intersection of the X's second line with the Y axis (eq. 3.42)"),
        Data("Y_end", "m", 0.0, "y of the end of the X's first line"),
        Data("x0", "m", 0.0, "centre of the O (eq. 3.45)"),
        Data("y0", "m", 0.0, "centre of the O (eq. 3.46)"),
        Data("R", "m", 0.0, "radius of the O (eq. 3.47)"),
        Data("arc_end", "rad", 0.0, "angle where the current arc ends"),
        Data("ignored_buttons", "1", 0, "button events that came while the arm was busy"),
    )

    class start_stop(State.Compound):
        wait_ini = State(initial=True)
        rise = State()
        go_over = State()
        go_wait = State()
        wait_1 = State()

        wait_ini.to(rise, cond="initialised", on="take_start_pose")
        rise.to(go_over, cond="at_target", on="aim_over_wait")
        go_over.to(go_wait, cond="at_target")
        go_wait.to(wait_1, cond="arrived")

    class Drawing_playing_field(State.Compound):
        to_line = State(initial=True)
        field_pen_down = State()
        line = State()
        field_pen_up = State()
        field_lift_off = State()

        to_line.to(field_pen_down, cond="at_target", on="aim_down")
        field_pen_down.to(line, cond="at_target", on="aim_line_end")
        line.to(field_pen_up, cond="at_target", on="aim_up")
        field_pen_up.to(to_line, cond="more_lines and at_target", on="next_line")
        field_pen_up.to(field_lift_off, cond="at_target", on="field_done")

    class Drawing_X(State.Compound):
        x_to_start = State(initial=True)
        x_pen_down = State()
        line_1 = State()
        x_pen_up = State()
        to_line_2 = State()
        x_pen_down_2 = State()
        line_2 = State()
        x_pen_up_2 = State()
        x_lift_off = State()

        x_to_start.to(x_pen_down, cond="at_target", on="aim_down")
        x_pen_down.to(line_1, cond="at_target")
        line_1.to(x_pen_up, cond="x_line_done", on="end_line_1")
        x_pen_up.to(to_line_2, cond="at_target", on="aim_line_2")
        to_line_2.to(x_pen_down_2, cond="at_target", on="aim_down")
        x_pen_down_2.to(line_2, cond="at_target")
        line_2.to(x_pen_up_2, cond="x_line_done", on="aim_up")
        x_pen_up_2.to(x_lift_off, cond="at_target", on="aim_travel")

    class Drawing_O(State.Compound):
        o_to_start = State(initial=True)
        o_pen_down = State()
        arc_1 = State()
        arc_2 = State()
        arc_3 = State()
        arc_4 = State()
        o_pen_up = State()
        o_lift_off = State()

        o_to_start.to(o_pen_down, cond="at_target", on="aim_down")
        o_pen_down.to(arc_1, cond="at_target", on="start_arc_1")
        arc_1.to(arc_2, cond="arc_done", on="next_arc")
        arc_2.to(arc_3, cond="arc_done", on="next_arc")
        arc_3.to(arc_4, cond="arc_done", on="next_arc")
        arc_4.to(o_pen_up, cond="arc_done", on="aim_up")
        o_pen_up.to(o_lift_off, cond="at_target", on="aim_travel")

    class Drawing_sine(State.Compound):
        s_to_start = State(initial=True)
        s_pen_down = State()
        wave = State()
        s_pen_up = State()
        s_lift_off = State()

        s_to_start.to(s_pen_down, cond="at_target", on="aim_down")
        s_pen_down.to(wave, cond="at_target", on="aim_wave_end")
        wave.to(s_pen_up, cond="sine_done", on="aim_up")
        s_pen_up.to(s_lift_off, cond="at_target", on="aim_travel")

    class Erase(State.Compound):
        erase_lift = State(initial=True)
        turn_sponge = State()
        to_pass = State()
        sponge_down = State()
        wipe = State()
        sponge_up = State()
        turn_pen = State()

        erase_lift.to(turn_sponge, cond="at_target")
        turn_sponge.to(to_pass, cond="phi >= pi_2", on="aim_pass_start")
        to_pass.to(sponge_down, cond="at_target", on="aim_sponge_down")
        sponge_down.to(wipe, cond="at_target", on="aim_pass_end")
        wipe.to(sponge_up, cond="at_target", on="aim_sponge_up")
        sponge_up.to(to_pass, cond="more_passes and at_target", on="next_pass")
        sponge_up.to(turn_pen, cond="at_target", on="erased")

    class finishing(State.Compound):
        home_lift = State(initial=True)
        go_home_over = State()
        go_home = State()
        finished = State()

        home_lift.to(go_home_over, cond="at_target and phi <= 0", on="aim_home_over")
        go_home_over.to(go_home, cond="at_target", on="aim_home")
        go_home.to(finished, cond="at_target")

    # -- from the waiting pose: erase first, then the field, then what the person asks.
    # Stateflow tries wait_1's transitions in the order written, at every wake-up, the
    # person's events included: a button draws only once the arm is idle.  A button that
    # no transition takes (the arm busy anywhere, or wait_1 not idle) is ignored and
    # counted: the `on button` action of every state it can arrive in, which runs in the
    # state's during phase, i.e. only when none of its transitions was taken.
    start_stop.wait_1.to(Erase, cond="erase")
    start_stop.wait_1.to(Drawing_playing_field, cond="not Pl_fld")
    button = (start_stop.wait_1.to(Drawing_X, cond="symbol == 1 and idle", on="count_symbol")
              | start_stop.wait_1.to(Drawing_O, cond="symbol == 0 and idle", on="count_symbol")
              | action_on((start_stop.wait_ini, start_stop.rise, start_stop.go_over, start_stop.go_wait,
                           start_stop.wait_1, Drawing_playing_field, Drawing_X, Drawing_O, Drawing_sine, Erase,
                           finishing), "ignore_button"))
    draw_sine = start_stop.wait_1.to(Drawing_sine, cond="idle")

    # -- back to the waiting pose once a sub-chart is done (lifted to z_travel)
    start_stop.go_wait.from_(Drawing_playing_field.field_lift_off, Drawing_X.x_lift_off, Drawing_O.o_lift_off,
                             Drawing_sine.s_lift_off, cond="at_target")
    Erase.turn_pen.to(start_stop.go_wait, cond="phi <= 0 and at_target")

    # -- finish, at any moment (a sub-chart's outer transition: tried before anything inside it)
    start_stop.to(finishing, cond="finish and initialised", on="aim_lift")
    finishing.from_(Drawing_playing_field, Drawing_X, Drawing_O, Drawing_sine, Erase, cond="finish", on="aim_lift")

    pi_2 = math.pi / 2

    #: What the action texts on the diagrams name besides the chart's data (docs/runtime.md, "What an action does").
    action_helpers = {
        "aim(x, y, z)": "the next move's target: tx, ty, tz = x, y, z (x, y may be given as one point)",
        "move(v)": "one step of the straight move to (tx, ty, tz) at speed v: each of X_out, Y_out, Z_out its"
                   " value at the previous tick plus its share of a step v*dt long, the target reached exactly"
                   " (eq. 3.36)",
        "inc": "the drawing step per tick along the coordinate the state increments: speed*dt/sqrt(2) for the X"
               " and the O (45-degree lines), speed*dt/2 for the sine",
        "field_start(k)": "(x, y) where line k of the field starts: lines 0-3 parallel to X, 4-7 parallel to Y",
        "field_end(k)": "(x, y) where line k of the field ends",
        "circle(a)": "the O's point at angle a: (x0 + R*cos(a), y0 + R*sin(a))",
        "pass_x(k)": "x of the sponge's pass k over the field",
        "pass_start(k)": "y where the sponge's pass k starts (5 mm beyond the field)",
        "pass_end(k)": "y where the sponge's pass k ends",
    }

    # ---------------------------------------------------------------- guards

    def at_target(self) -> bool:
        """The output has reached the current move's target."""
        return self.X_out == self.tx and self.Y_out == self.ty and self.Z_out == self.tz

    def idle(self) -> bool:
        """Nothing of the arm's own is pending: the field is drawn and no erase is asked for."""
        return bool(self.Pl_fld and not self.erase)

    def arrived(self) -> bool:
        """The arm itself (forward kinematics of the encoders) is at the waiting pose."""
        return (abs(self.X_now - self.x_wait) < self.wait_tol and abs(self.Y_now - self.y_wait) < self.wait_tol
                and abs(self.Z_now - self.z_wait) < self.wait_tol)

    def more_lines(self) -> bool:
        """Another of the 4 + 4 field lines is left."""
        return self.k < 2 * (self.cells - 1) - 1

    def x_line_done(self) -> bool:
        """The X's current line reached its end (x decreased by the symbol size)."""
        return self.X_out <= self.x_ini - self.size

    def arc_done(self) -> bool:
        """The current arc reached its end angle."""
        return self.X_out == self.tx and self.Y_out == self.ty

    def sine_done(self) -> bool:
        """The sine wave reached its end."""
        return self.X_out <= self.tx

    def more_passes(self) -> bool:
        """Another sponge pass is left."""
        return self.k < self.cells - 1

    # ------------------------------------------------------- start_stop

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

    # ------------------------------------------- Drawing_playing_field

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

    # ------------------------------------------------------- Drawing_X

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

    # ------------------------------------------------------- Drawing_O

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

    # ------------------------------------------------------- Drawing_sine

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

    # ----------------------------------------------------------- Erase

    def on_enter_Erase(self) -> None:
        self.erasing = True
        self._aim(self.X_out, self.Y_out, max(self.Z_out, self.z_travel))

    def on_exit_Erase(self) -> None:
        self.erasing = False

    def during_erase_lift(self) -> None:
        self._move(self.z_speed * 2)

    @does("phi = min(phi + phi_rate*dt, pi/2)")
    def during_turn_sponge(self) -> None:
        self.phi = min(self.phi + self.phi_rate * self.tick_period_s, self.pi_2)

    def _pass_x(self, k: int) -> float:
        return pass_x(self.x11, self.L, self.cells, k)

    def _pass_ends(self, k: int) -> tuple[float, float]:
        """Passes along Y over the whole field (and 5 mm beyond), alternately one way and back."""
        return pass_ends(self.y11, self.L, self.cells, k)

    @does("k = 0; aim(pass_x(0), pass_start(0), z_travel)")
    def aim_pass_start(self) -> None:
        self.k = 0
        self._aim(self._pass_x(0), self._pass_ends(0)[0], self.z_travel)

    def during_to_pass(self) -> None:
        self._move(self.travel_speed)

    def aim_sponge_down(self) -> None:
        self._aim(self.X_out, self.Y_out, self.z_sponge)

    def during_sponge_down(self) -> None:
        self._move(self.z_speed)

    @does("aim(X_out, pass_end(k), z_sponge)")
    def aim_pass_end(self) -> None:
        self._aim(self.X_out, self._pass_ends(self.k)[1], self.z_sponge)

    def during_wipe(self) -> None:
        self._move(self.wipe_speed)

    def aim_sponge_up(self) -> None:
        self._aim(self.X_out, self.Y_out, self.z_sponge + 0.01)

    def during_sponge_up(self) -> None:
        self._move(self.z_speed)

    @does("k = k + 1; aim(pass_x(k), pass_start(k), z_sponge + 0.01)")
    def next_pass(self) -> None:
        self.k = self.k + 1
        self._aim(self._pass_x(self.k), self._pass_ends(self.k)[0], self.z_sponge + 0.01)

    def erased(self) -> None:
        self.Pl_fld = False
        self.ctr = 0
        self._aim(self.X_out, self.Y_out, self.z_travel)

    def during_turn_pen(self) -> None:
        self._move(self.z_speed * 2)
        self.phi = max(self.phi - self.phi_rate * self.tick_period_s, 0.0)

    # ------------------------------------------------------- finishing

    def during_finishing(self) -> None:
        self.fr_sw = False
        self.phi = max(self.phi - self.phi_rate * self.tick_period_s, 0.0)

    def during_home_lift(self) -> None:
        self._move(self.z_speed * 2)

    def aim_home_over(self) -> None:
        self._aim(self.x_start, self.y_start, self.Z_out)

    def during_go_home_over(self) -> None:
        self._move(self.travel_speed)

    def aim_home(self) -> None:
        self._aim(self.x_start, self.y_start, self.z_start)

    def during_go_home(self) -> None:
        self._move(self.z_speed * 2)

    def on_enter_finished(self) -> None:
        self.at_start = True
