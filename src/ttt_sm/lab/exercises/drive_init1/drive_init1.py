"""DriveInit1, your version: find the index, or a hard stop and then the index (thesis section 3.1.2).

Fill in the parts marked TODO; ``ttt-sm lab check .`` says what the chart does.
The inputs and outputs are the slot's contract (docs/lab.md), the thesis chart's own;
``HomeAndPass`` gives what every DriveInit chart does alike: ``set_home`` and ``pass_pos``.
"""

from __future__ import annotations

from statemachine import State

from ttt_sm.charts.drive_init import DriveInit1, HomeAndPass
from ttt_sm.runtime import Data


class MyDriveInit1(HomeAndPass):
    """Drive 1: turn until the index passes (or a stall: turn back), park, wait for 2 and 3, pass pos_in."""

    timed = True

    # the slot's contract, as the thesis chart declares it: what the robot feeds and reads
    inputs = DriveInit1.inputs
    outputs = DriveInit1.outputs
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

    def during_go_park(self) -> None:
        # TODO: step towards park at 1 rad/s; jumping there swings the arm through the board zone
        self.pos_out = self.park

    def on_enter_wait_23(self) -> None:
        self.ini_23 = True
