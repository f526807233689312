"""DriveInit3, your version: drive 3 touches its index-and-limit switch slowly (thesis section 3.1.2).

Fill in the parts marked TODO; ``ttt-sm lab check .`` says what the chart does
and what it should.  Everything declared here is the slot's contract (docs/lab.md):
keep the names, kinds and units.
"""

from __future__ import annotations

import math

from statemachine import State

from ttt_sm.runtime import Data, TickChart


class MyDriveInit3(TickChart):
    """Drive 3: turn towards the index-and-limit switch with a shrinking increment."""

    timed = True  # the chart knows its tick period: self.tick_period_s

    inputs = (
        Data("pos_in", "rad", 0.0, "joint coordinate to pass through once initialised (IK output)"),
        Data("index", "bool", False, "index-and-limit switch level, from the Encoder block"),
        Data("index_pos", "rad", 0.0, "encoder angle latched at the switch's last edge"),
        Data("ini1", "bool", False, "drive 1 is initialised and parked"),
        Data("ini2", "bool", False, "drive 2 is initialised"),
    )
    outputs = (
        Data("pos_out", "rad", 0.0, "position setpoint sent to the drive's controller"),
        Data("offset", "rad", 0.0, "correction the Encoder block adds to the encoder angle"),
        Data("ini3", "bool", False, "drive 3 is initialised and parked"),
        Data("passing", "bool", False, "initialised: passes pos_in through"),
        Data("gave_up", "bool", False, "the search gave up"),
    )
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

    def set_home(self) -> None:
        """The switch closed: its latched encoder angle is really `index_angle`."""
        correction = self.index_angle - self.index_pos
        self.offset = self.offset + correction
        self.pos_out = self.pos_out + correction

    def during_back_off(self) -> None:
        # TODO: step pos_out towards park by at most 1 rad/s times the tick period
        self.pos_out = self.park

    def on_enter_wait_ini2(self) -> None:
        self.ini3 = True

    def on_enter_pass_pos(self) -> None:
        self.passing = True

    def during_pass_pos(self) -> None:
        self.pos_out = self.pos_in


_ = math  # math.exp may help with the shrinking increment
