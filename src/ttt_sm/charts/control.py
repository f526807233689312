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

This module holds the chart: its data, states, transitions and guards.  The
actions are by sub-chart: :mod:`.control_moves` (``start_stop`` and the pen
moves), :mod:`.control_drawing` (the field, the X, the O, the sine wave) and
:mod:`.control_erase` (``Erase``, ``finishing``).
"""

from __future__ import annotations

import math

from statemachine import State

from ..runtime import Data, TickChart, action_on
from .control_drawing import FieldDrawing, ODrawing, SineDrawing, XDrawing
from .control_erase import Erasing, Finishing
from .control_moves import PenMoves


class Control(PenMoves, FieldDrawing, XDrawing, ODrawing, SineDrawing, Erasing, Finishing,
              TickChart):
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
