"""Wiring of the Control chart (thesis fig. 3.23) into the scheduler.

:class:`ControlStage` is a task stage: every chart step it feeds the chart
its inputs (the init charts' state, the tool pose by forward kinematics of
the encoders, the game's commands), ticks it, and hands its outputs
`X_out, Y_out, Z_out, phi` to inverse kinematics and `fr_sw` to the
setpoint filters.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import cast

import numpy as np

from ..arm import Arm
from ..charts.control import Control
from ..params import ArmParams
from ..sched.scheduler import Signals
from ..twin.kinematics import arm_chain_py
from .init_wiring import DriveInitStage
from .slots import THESIS_SLOTS, ChartSlots
from .wiring import Wiring, not_wired


def control_chart_data(params: ArmParams) -> dict[str, float]:
    """What the builder sets in the Control chart from `params`: the field, the heights."""
    b = params.board
    x_min, x_max, y_min, y_max = b.field_bounds()
    return {
        "x11": x_max, "y11": y_max, "L": b.cell_size, "cells": b.cells,
        # the pen is pressed 1.5 mm into its spring while it draws; the sponge 2.5 mm
        "z_draw": b.surface_z - 0.0015,
        "z_up": b.surface_z + 0.008,
        "z_travel": b.surface_z + b.zone_clearance,
        "z_sponge": b.surface_z + params.sponge.offset - 0.0025,
    }


def make_control_chart(params: ArmParams, listeners: Sequence[object] = (),
                       slots: ChartSlots = THESIS_SLOTS) -> Control:
    """The Control chart with the field, heights and poses of `params` (its class: `slots`' Control)."""
    chart = slots.make("Control", tick_period_s=params.control.chart_dt, listeners=list(listeners),
                       data=control_chart_data(params))
    return cast(Control, chart)  # a slotted class meets Control's contract (checked when chosen), not its type


class ControlStage:
    """Task stage: the Control chart between the game and inverse kinematics.

    The wiring table (:mod:`.wires`) says what feeds the chart and where its
    outputs go; this stage computes the tool pose the chart reads, holds the
    erase flag (the table's ``EraseFlag``), and passes the pose the chart
    commands to inverse kinematics.
    """

    def __init__(self, params: ArmParams, arm: Arm, init: DriveInitStage, chart: Control) -> None:
        self.params = params
        self.arm = arm
        self.init = init
        self.chart = chart
        #: The request to erase (the thesis' Erase_flag): set by the game or `ttt-sm play`,
        #: reset once the Control chart erases.
        self.erase_requested = False
        #: Inputs forced by a test or scenario (``Robot.set_input(..., force=True)``),
        #: applied after the wiring's own: name -> value.
        self.overrides: dict[str, object] = {}
        self._no_task = np.full(4, np.nan)
        self._inputs = vars(chart)  # plain attribute writes: this runs every chart step
        g = params.geometry
        self._geometry = (g.L1, g.L2, g.L3, g.L4, g.l_f)
        # the last forward kinematics, (q1, q2, q3, servo) -> (x, y, z): an arm that stands still (waiting
        # for the person, holding a pose) reads the same encoder angles chart step after chart step
        self._fk_in: tuple[float, float, float, float] = (math.nan,) * 4
        self._fk_out: tuple[float, float, float] = (math.nan,) * 3
        self._feed: Callable[[float, float, float], None] = not_wired
        self._outputs: Callable[[], tuple[float, float, float, float, bool, bool]] = not_wired  # type: ignore

    def blocks(self) -> dict[str, object]:
        """The objects holding the outputs of this stage's blocks (EraseFlag), by block name.

        The FK block's outputs, computed here every chart step, are the feed's arguments.
        """
        return {"EraseFlag": self}

    def wire(self, wiring: Wiring) -> None:
        """Compile this stage's part of the wiring table."""
        self._feed = wiring.feed([self.chart.chart_name], args=("FK",))
        self._outputs = wiring.collect("IK.X", "IK.Y", "IK.Z", "IK.phi", "Drives.fr_sw", "EraseFlag.erasing")

    def tick(self, signals: Signals) -> None:
        """Inputs in, chart ticked, tool pose out."""
        arm = self.arm
        q1, q2, q3 = arm.encoder_angles()
        servo = float(signals.q_set[3])
        if not math.isfinite(servo):
            # no setpoint yet (the first chart step): the pose is the angle the
            # servo was last commanded (as FK reads it everywhere: docs/safety.md)
            servo = arm.servo_setpoint
        fk_in = (q1, q2, q3, servo)
        if fk_in == self._fk_in:
            x, y, z = self._fk_out
        else:
            x, y, z, _, _, _, _, _ = arm_chain_py(q1, q2, q3, servo, *self._geometry)
            self._fk_in, self._fk_out = fk_in, (x, y, z)
        self._feed(x, y, z)
        if self.overrides:
            self._inputs.update(self.overrides)
        self.chart.tick()
        x, y, z, phi, fr_sw, erasing = self._outputs()
        if erasing:
            self.erase_requested = False  # the chart took the request
        signals.task = [x, y, z, phi] if math.isfinite(x) else self._no_task
        signals.fr_sw = bool(fr_sw)
