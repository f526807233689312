"""DriveInit3, your version: drive 3 touches its index-and-limit switch slowly (thesis section 3.1.2).

Fill in the parts marked TODO; ``ttt-sm lab check .`` says what the chart does
and what it should.  The inputs and outputs are the slot's contract (docs/lab.md), the
thesis chart's own; ``HomeAndPass`` gives what every DriveInit chart does alike:
``set_home`` (the switch's edge corrects ``offset``) and ``pass_pos``.
"""

from __future__ import annotations

import math

from statemachine import State

from ttt_sm.charts.drive_init import DriveInit3, HomeAndPass
from ttt_sm.runtime import Data


class MyDriveInit3(HomeAndPass):
    """Drive 3: turn towards the index-and-limit switch with a shrinking increment."""

    timed = True  # the chart knows its tick period: self.tick_period_s

    # the slot's contract, as the thesis chart declares it: what the robot feeds and reads
    inputs = DriveInit3.inputs
    outputs = DriveInit3.outputs
    local = (
        Data("index_angle", "rad", 0.0, "true angle of the switch (set from the parameter file)"),
        Data("park", "rad", 0.0, "angle to wait at once initialised (set from the parameter file)"),
        Data("inc", "rad", 0.0, "current step per chart tick"),
    )

    wait_ini1 = State(initial=True)
    approach = State()
    back_off = State()
    wait_ini2 = State()
    pass_pos = State()

    wait_ini1.to(approach, cond="ini1", on="start_search")
    approach.to(back_off, cond="index", on="set_home")
    back_off.to(wait_ini2, cond="pos_out == park")
    wait_ini2.to(pass_pos, cond="ini2")

    def start_search(self) -> None:
        # TODO: the first step per tick: 1 rad/s times the tick period
        self.inc = 0.0

    def during_approach(self) -> None:
        # TODO: move pos_out on by inc (pos_out_p is pos_out one tick ago), then shrink inc,
        # but never below 0.2 rad/s times the tick period
        pass

    def during_back_off(self) -> None:
        # TODO: step pos_out towards park by at most 1 rad/s times the tick period
        self.pos_out = self.park

    def on_enter_wait_ini2(self) -> None:
        self.ini3 = True


_ = math  # math.exp may help with the shrinking increment
