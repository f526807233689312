"""The three drive-initialisation charts of thesis section 3.1.2 (figs. 3.2-3.4).

The encoders are relative: at power-on they count from zero wherever the arm
happens to be.  Each chart moves its drive until the drive's index switch
changes, which tells the Encoder block where the drive really is (the
`offset` output), and only then passes the position commanded from above
(`pos_in`, the IK output) through to its controller (`pos_out`).

- DriveInit1 (base yaw) turns one way until its index passes, or until a
  stall shows it hit a hard stop (the setpoint runs ahead of the encoder:
  "If the output position of the encoder is not changing, while the output
  position of the initialization block still is ..."), then turns back until
  the index passes; it parks where drives 2 and 3 can initialise away from the
  board, tells them (`ini_23`), and waits for them.
- DriveInit2 (shoulder) hangs near zero at power-on, so it turns by a set
  angle one way and, if the index did not pass, turns back until it does.
- DriveInit3 (elbow): its index switch is also its limit switch, so it turns
  towards it with an increment that starts big and shrinks, to touch it
  slowly.

Every angle here is in the drive's encoder coordinates, which become the true
joint angle once `offset` is applied.  Speeds are per-second data; a chart
turns them into its step per tick with the tick period the scheduler gives it
(`tick_period_s`), so the drives search equally fast at any chart rate.
The charts import only the runtime; `ttt_sm.app.init_wiring` connects them
to the twin.
"""

from __future__ import annotations

import math

from statemachine import HistoryState, State

from ..runtime import Data, TickChart, does

#: Data every DriveInit chart declares alike (thesis fig. 3.2-3.4: pos_in in, pos_out and the offset out).
_POS_IN = Data("pos_in", "rad", 0.0, "joint coordinate to pass through once initialised (IK output)")
_INDEX = Data("index", "bool", False, "index switch level, from the Encoder block")
_INDEX_POS = Data("index_pos", "rad", 0.0, "encoder angle latched at the index switch's last edge")
_POS_OUT = Data("pos_out", "rad", 0.0, "position setpoint sent to the drive's controller")
_OFFSET = Data("offset", "rad", 0.0, "correction the Encoder block adds to the encoder angle")
_INDEX_ANGLE = Data("index_angle", "rad", 0.0, "true angle of the index switch")
#: Local data drives 1 and 2 declare alike: the search's step and where it began.
_SEARCH_INC = Data("inc", "rad", 0.0, "search step per chart tick: search_speed times the tick period")
_INDEX_START = Data("index_start", "bool", False, "index level when the current search began")
#: Outputs every DriveInit chart declares: what the application reads of its state.
_STATUS = (
    Data("passing", "bool", False, "initialised: passes pos_in through (pass_pos)"),
    Data("gave_up", "bool", False, "the search gave up: a switch was not found (failed)"),
)


def _step_towards(value: float, target: float, inc: float) -> float:
    """`value` moved towards `target` by at most `inc`."""
    return value + max(-inc, min(inc, target - value))


class HomeAndPass(TickChart):
    """What every DriveInit chart does alike: take the index as home, then pass pos_in.

    An abstract chart (no states, no data): each DriveInit chart declares its own
    states and data, and the runtime finds these methods on it by name as it finds
    the chart's own (``on="set_home"``, ``during_pass_pos``).
    """

    #: What the action texts on the diagrams name besides the chart's data (docs/runtime.md, "What an action does").
    action_helpers = {
        "step_towards(v, target, inc)": "v moved towards target by at most inc",
        "watch_encoder()": "moving = True once the encoder turned still_speed*dt in a tick; enc_prev = pos_Encoder",
    }

    # for type checkers: data every DriveInit chart declares, and its period (it is timed)
    tick_period_s: float
    pos_in: float
    pos_out: float
    offset: float
    index_pos: float
    index_angle: float
    passing: bool
    gave_up: bool

    @does("offset = offset + index_angle - index_pos; pos_out = pos_out + index_angle - index_pos")
    def set_home(self) -> None:
        """The index switch changed: its latched encoder angle is `index_angle` really."""
        correction = self.index_angle - self.index_pos
        self.offset = self.offset + correction
        self.pos_out = self.pos_out + correction

    def during_pass_pos(self) -> None:
        self.pos_out = self.pos_in

    # what the application reads of the chart's state: outputs, set on entry and exit
    def on_enter_pass_pos(self) -> None:
        self.passing = True

    def on_exit_pass_pos(self) -> None:
        self.passing = False

    def on_enter_failed(self) -> None:
        self.gave_up = True


class _IndexSearch(HomeAndPass):
    """A DriveInit chart that waits for an edge of its index switch (drives 1 and 2).

    Drive 3's switch is also its limit switch: its guards read the level itself.
    """

    index: bool
    index_start: bool

    def index_passed(self) -> bool:
        """The index switch changed since the search began."""
        return self.index != self.index_start


class DriveInit1(_IndexSearch):
    """Drive 1: find the index (or a hard stop, then the index), park, wait, pass pos_in."""

    timed = True

    inputs = (
        _POS_IN,
        Data("stop", "bool", False, "a non-zero value stops the drive where it is"),
        _INDEX,
        Data("pos_Encoder", "rad", 0.0, "drive angle from the encoder (relative until initialised)"),
        _INDEX_POS,
        Data("ini2", "bool", False, "drive 2 is initialised"),
        Data("ini3", "bool", False, "drive 3 is initialised"),
    )
    outputs = (
        _POS_OUT,
        _OFFSET,
        Data("ini_23", "bool", False, "drive 1 initialised and parked: drives 2 and 3 may start"),
        *_STATUS,
    )
    local = (
        Data("search_speed", "rad/s", 1.0, "how fast the setpoint turns while searching and parking"),
        _SEARCH_INC,
        _INDEX_ANGLE,
        Data("park", "rad", 0.0, "angle to wait at while drives 2 and 3 initialise"),
        Data("still_speed", "rad/s", 0.25, "encoder slower than this (a quarter of search_speed): stalled"),
        Data("stall_lag", "rad", 0.06, "setpoint this far ahead of a still encoder: stalled (a start at a stop)"),
        Data("direction", "1", 1.0, "+1 while turning forward, -1 while turning back"),
        Data("moving", "bool", False, "the encoder has moved since the current turn began"),
        Data("park_tol", "rad", 0.002, "how close the encoder must be to the parking angle"),
        Data("enc_prev", "rad", 0.0, "encoder angle one chart tick earlier"),
        _INDEX_START,
    )

    class run(State.Compound):
        class initialise(State.Compound):
            power_on = State(initial=True)
            turn_fwd = State()
            turn_back = State()
            go_park = State()
            wait_23 = State()

            power_on.to(turn_fwd)  # on the first tick, once the inputs are read
            turn_fwd.to(go_park, cond="index_passed", on="set_home")
            turn_fwd.to(turn_back, cond="stalled", on="reverse")
            turn_back.to(go_park, cond="index_passed", on="set_home")
            go_park.to(wait_23, cond="parked")

        pass_pos = State()
        h = HistoryState(type="deep")  # back into the very state `stop` interrupted
        initialise.wait_23.to(pass_pos, cond="ini2 and ini3")

    stopped = State()
    failed = State()

    run.to(stopped, cond="stop")
    stopped.to(run.h, cond="not stop")
    run.initialise.turn_back.to(failed, cond="stalled")

    # -- guards: pure functions of inputs and data -----------------------------
    # (index_passed, set_home and during_pass_pos: see _IndexSearch)

    def stalled(self) -> bool:
        """The encoder stands still while the setpoint moves on: a hard stop.

        Either the drive was moving and its encoder stopped, or (a start
        right at a stop, where it never moved) the setpoint ran `stall_lag`
        ahead of it.  Before the drive gets under way the setpoint filter
        delays it, which is why a still encoder alone does not count.
        """
        if (self.pos_out - self.pos_Encoder) * self.direction > self.stall_lag:
            return True
        return self.moving and abs(self.pos_Encoder - self.enc_prev) < self.still_speed * self.tick_period_s

    def parked(self) -> bool:
        """Setpoint at the parking angle and the drive there too."""
        return self.pos_out == self.park and abs(self.pos_Encoder - self.park) < self.park_tol

    # -- actions ------------------------------------------------------------------

    @does("pos_out = enc_prev = pos_Encoder; inc = search_speed*dt; index_start = index; direction = 1;"
          " moving = False", summary="pos_out = enc_prev = pos_Encoder; inc = search_speed*dt")
    def on_enter_turn_fwd(self) -> None:
        self.inc = self.search_speed * self.tick_period_s
        self.index_start = self.index
        self.pos_out = self.pos_Encoder
        self.enc_prev = self.pos_Encoder
        self.direction = 1.0
        self.moving = False

    def during_turn_fwd(self) -> None:
        self.pos_out = self.pos_out_p + self.inc
        self._watch_encoder()

    def _watch_encoder(self) -> None:
        """Remember this tick's encoder angle, and whether the drive got under way."""
        if abs(self.pos_Encoder - self.enc_prev) >= self.still_speed * self.tick_period_s:
            self.moving = True
        self.enc_prev = self.pos_Encoder

    @does("pos_out = enc_prev = pos_Encoder; index_start = index; direction = -1; moving = False")
    def reverse(self) -> None:
        """Turn back from where the drive stands, not from where the setpoint ran to."""
        self.pos_out = self.pos_Encoder
        self.index_start = self.index
        self.enc_prev = self.pos_Encoder
        self.direction = -1.0
        self.moving = False

    def during_turn_back(self) -> None:
        self.pos_out = self.pos_out_p - self.inc
        self._watch_encoder()

    def during_go_park(self) -> None:
        self.pos_out = _step_towards(self.pos_out_p, self.park, self.inc)

    def on_enter_wait_23(self) -> None:
        self.ini_23 = True

    def on_enter_stopped(self) -> None:
        self.pos_out = self.pos_Encoder

    def on_enter_failed(self) -> None:
        self.gave_up = True
        self.pos_out = self.pos_Encoder


class DriveInit2(_IndexSearch):
    """Drive 2: wait for drive 1, turn a set angle, turn back if the index did not pass, wait, park."""

    timed = True

    inputs = (
        _POS_IN,
        _INDEX,
        _INDEX_POS,
        Data("ini1", "bool", False, "drive 1 is initialised and parked (its ini_23)"),
        Data("ini3", "bool", False, "drive 3 is initialised"),
    )
    outputs = (
        _POS_OUT,
        _OFFSET,
        Data("ini2", "bool", False, "drive 2 is initialised"),
        *_STATUS,
    )
    local = (
        Data("search_speed", "rad/s", 0.75, "how fast the setpoint turns while searching and parking"),
        _SEARCH_INC,
        _INDEX_ANGLE,
        Data("turn_angle", "rad", 0.6, "how far to turn one way before turning back"),
        Data("max_back", "rad", 2.0, "how far to turn back before giving up"),
        Data("travel", "rad", 0.0, "turned so far in the current direction"),
        _INDEX_START,
        Data("park", "rad", 0.0, "angle to hold once initialised, until the Control chart takes over"),
    )

    wait_ini1 = State(initial=True)
    turn_one_way = State()
    turn_back = State()
    wait_ini3 = State()
    go_park = State()
    pass_pos = State()
    failed = State()

    wait_ini1.to(turn_one_way, cond="ini1", on="start_search")
    turn_one_way.to(wait_ini3, cond="index_passed", on="set_home")
    turn_one_way.to(turn_back, cond="travel >= turn_angle", on="start_search")
    turn_back.to(wait_ini3, cond="index_passed", on="set_home")
    turn_back.to(failed, cond="travel >= max_back")
    wait_ini3.to(go_park, cond="ini3")
    go_park.to(pass_pos, cond="pos_out == park")

    # (index_passed, set_home and during_pass_pos: see _IndexSearch)

    def start_search(self) -> None:
        self.inc = self.search_speed * self.tick_period_s
        self.index_start = self.index
        self.travel = 0.0

    def during_turn_one_way(self) -> None:
        self.pos_out = self.pos_out_p + self.inc
        self.travel = self.travel + self.inc

    def during_turn_back(self) -> None:
        self.pos_out = self.pos_out_p - self.inc
        self.travel = self.travel + self.inc

    def on_enter_wait_ini3(self) -> None:
        self.ini2 = True

    def during_go_park(self) -> None:
        self.pos_out = _step_towards(self.pos_out_p, self.park, self.inc)


class DriveInit3(HomeAndPass):
    """Drive 3: turn towards the index-and-limit switch with a shrinking increment."""

    timed = True

    inputs = (
        _POS_IN,
        Data("index", "bool", False, "index-and-limit switch level, from the Encoder block"),
        Data("index_pos", "rad", 0.0, "encoder angle latched at the switch's last edge"),
        Data("ini1", "bool", False, "drive 1 is initialised and parked (its ini_23)"),
        Data("ini2", "bool", False, "drive 2 is initialised"),
    )
    outputs = (
        _POS_OUT,
        _OFFSET,
        Data("ini3", "bool", False, "drive 3 is initialised and parked"),
        *_STATUS,
    )
    local = (
        Data("inc", "rad", 0.0, "current step per chart tick"),
        Data("speed_max", "rad/s", 1.0, "first speed towards the switch, and the speed of backing off"),
        Data("speed_min", "rad/s", 0.2, "slowest speed: how fast the switch is touched"),
        Data("slow_down_s", "s", 0.666, "the speed falls by a factor e every this many seconds"),
        Data("shrink", "1", 1.0, "the step is multiplied by this every tick: exp(-tick period / slow_down_s)"),
        Data("index_angle", "rad", 0.0, "true angle of the index-and-limit switch"),
        Data("park", "rad", 0.0, "angle to wait at once initialised"),
        Data("max_travel", "rad", 3.5, "how far to turn before giving up"),
        Data("travel", "rad", 0.0, "turned so far"),
    )

    wait_ini1 = State(initial=True)
    leave_switch = State()
    approach = State()
    back_off = State()
    wait_ini2 = State()
    pass_pos = State()
    failed = State()

    wait_ini1.to(leave_switch, cond="ini1 and index", on="start_search")
    wait_ini1.to(approach, cond="ini1", on="start_search")
    leave_switch.to(back_off, cond="not index", on="set_home")
    approach.to(back_off, cond="index", on="set_home")
    approach.to(failed, cond="travel >= max_travel")
    leave_switch.to(failed, cond="travel >= max_travel")
    back_off.to(wait_ini2, cond="pos_out == park")
    wait_ini2.to(pass_pos, cond="ini2")

    # (set_home and during_pass_pos: see HomeAndPass)

    def start_search(self) -> None:
        self.inc = self.speed_max * self.tick_period_s
        self.shrink = math.exp(-self.tick_period_s / self.slow_down_s)
        self.travel = 0.0

    def during_approach(self) -> None:
        self.pos_out = self.pos_out_p + self.inc
        self.travel = self.travel + self.inc
        self.inc = max(self.speed_min * self.tick_period_s, self.inc * self.shrink)

    @does("pos_out = pos_out_p - speed_min*dt; travel = travel + speed_min*dt")
    def during_leave_switch(self) -> None:
        step = self.speed_min * self.tick_period_s
        self.pos_out = self.pos_out_p - step
        self.travel = self.travel + step

    @does("pos_out = step_towards(pos_out_p, park, speed_max*dt)")
    def during_back_off(self) -> None:
        self.pos_out = _step_towards(self.pos_out_p, self.park, self.speed_max * self.tick_period_s)

    def on_enter_wait_ini2(self) -> None:
        self.ini3 = True


INIT_CHARTS = (DriveInit1, DriveInit2, DriveInit3)
