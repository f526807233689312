"""DriveInit1, your version: find the index, or a hard stop and then the index (thesis section 3.1.2).

Fill in the parts marked TODO; ``ttt-sm lab check .`` says what the chart does.
Everything declared here is the slot's contract (docs/lab.md).
"""

from __future__ import annotations

from statemachine import State

from ttt_sm.runtime import Data, TickChart


class MyDriveInit1(TickChart):
    """Drive 1: turn until the index passes (or a stall: turn back), park, wait for 2 and 3, pass pos_in."""

    timed = True

    inputs = (
        Data("pos_in", "rad", 0.0, "joint coordinate to pass through once initialised"),
        Data("stop", "bool", False, "a non-zero value stops the drive where it is"),
        Data("index", "bool", False, "index switch level"),
        Data("pos_Encoder", "rad", 0.0, "drive angle from the encoder"),
        Data("index_pos", "rad", 0.0, "encoder angle latched at the index switch's last edge"),
        Data("ini2", "bool", False, "drive 2 is initialised"),
        Data("ini3", "bool", False, "drive 3 is initialised"),
    )
    outputs = (
        Data("pos_out", "rad", 0.0, "position setpoint"),
        Data("offset", "rad", 0.0, "correction the Encoder block adds to the encoder angle"),
        Data("ini_23", "bool", False, "drive 1 initialised and parked: drives 2 and 3 may start"),
        Data("passing", "bool", False, "initialised: passes pos_in through"),
        Data("gave_up", "bool", False, "the search gave up"),
    )
    local = (
        Data("index_angle", "rad", 0.0, "true angle of the index switch (parameter file)"),
        Data("park", "rad", 0.0, "angle to wait at while drives 2 and 3 initialise (parameter file)"),
        Data("index_start", "bool", False, "index level when the search began"),
    )

    turn_fwd = State(initial=True)
    go_park = State()
    wait_23 = State()
    pass_pos = State()

    turn_fwd.to(go_park, cond="index_passed", on="set_home")
    # TODO: a stall (the encoder stands still while pos_out moves on) means a hard stop: turn back
    go_park.to(wait_23, cond="pos_out == park")
    wait_23.to(pass_pos, cond="ini2 and ini3")

    def index_passed(self) -> bool:
        return self.index != self.index_start

    def on_enter_turn_fwd(self) -> None:
        self.index_start = self.index
        self.pos_out = self.pos_Encoder

    def during_turn_fwd(self) -> None:
        self.pos_out = self.pos_out_p + 1.0 * self.tick_period_s

    def set_home(self) -> None:
        correction = self.index_angle - self.index_pos
        self.offset = self.offset + correction
        self.pos_out = self.pos_out + correction

    def during_go_park(self) -> None:
        # TODO: step towards park at 1 rad/s; jumping there swings the arm through the board zone
        self.pos_out = self.park

    def on_enter_wait_23(self) -> None:
        self.ini_23 = True

    def on_enter_pass_pos(self) -> None:
        self.passing = True

    def during_pass_pos(self) -> None:
        self.pos_out = self.pos_in
