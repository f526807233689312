"""DriveInit2, your version: turn a set angle one way; if the index did not pass, turn back (section 3.1.2).

Fill in the parts marked TODO; ``ttt-sm lab check .`` says what the chart does.
"""

from __future__ import annotations

from statemachine import State

from ttt_sm.charts.drive_init import DriveInit2
from ttt_sm.runtime import Data, TickChart


class MyDriveInit2(TickChart):
    """Drive 2: wait for drive 1, search the index, wait for drive 3, park, pass pos_in."""

    timed = True

    # the slot's contract, as the thesis chart declares it: what the robot feeds and reads
    inputs = DriveInit2.inputs
    outputs = DriveInit2.outputs
    local = (
        Data("index_angle", "rad", 0.0, "true angle of the index switch (parameter file)"),
        Data("park", "rad", 0.0, "angle to hold once initialised (parameter file)"),
    )

    wait_ini1 = State(initial=True)
    turn_one_way = State()
    wait_ini3 = State()
    pass_pos = State()

    wait_ini1.to(turn_one_way, cond="ini1")
    # TODO: or 0.6 rad turned without the index passing: turn back
    turn_one_way.to(wait_ini3, cond="index_passed", on="set_home")
    wait_ini3.to(pass_pos, cond="ini3")

    def index_passed(self) -> bool:
        # TODO: the index switch changed since the search began
        return False

    def set_home(self) -> None:
        # TODO: the latched encoder angle index_pos is really index_angle: correct offset and pos_out
        pass

    def during_turn_one_way(self) -> None:
        self.pos_out = self.pos_out_p + 0.75 * self.tick_period_s

    def on_enter_wait_ini3(self) -> None:
        self.ini2 = True

    def on_enter_pass_pos(self) -> None:
        self.passing = True

    def during_pass_pos(self) -> None:
        self.pos_out = self.pos_in
