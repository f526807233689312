"""Wiring of the Control chart (thesis fig. 3.23) into the scheduler.

:class:`ControlStage` is a task stage: every chart step it feeds the chart
its inputs (the init charts' state, the tool pose by forward kinematics of
the encoders, the game's commands), ticks it, and hands its outputs
`X_out, Y_out, Z_out, phi` to inverse kinematics and `fr_sw` to the
setpoint filters.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..arm import Arm
from ..charts.control import Control
from ..params import ArmParams
from ..sched.scheduler import Signals
from ..twin.kinematics import fk_floats
from .init_wiring import DriveInitStage

# The compiled forward kinematics' Python original: a numba call with nine
# float arguments costs ~10 us in dispatch, the plain function ~2 us.
_fk_python = fk_floats.py_func


def make_control_chart(params: ArmParams, listeners: Sequence[object] = ()) -> Control:
    """The Control chart with the field, heights and poses of `params`."""
    b = params.board
    x_min, x_max, y_min, y_max = b.field_bounds()
    return Control(
        tick_period_s=params.control.chart_dt, listeners=list(listeners),
        data={
            "x11": x_max, "y11": y_max, "L": b.cell_size, "cells": b.cells,
            # the pen is pressed 1.5 mm into its spring while it draws; the sponge 2.5 mm
            "z_draw": b.surface_z - 0.0015,
            "z_up": b.surface_z + 0.008,
            "z_travel": b.surface_z + b.zone_clearance,
            "z_sponge": b.surface_z + params.sponge.offset - 0.0025,
        },
    )


class ControlStage:
    """Task stage: the Control chart between the game and inverse kinematics."""

    def __init__(self, params: ArmParams, arm: Arm, init: DriveInitStage, chart: Control) -> None:
        self.params = params
        self.arm = arm
        self.init = init
        self.chart = chart
        #: The game's request to erase (the thesis' Erase_flag); cleared once erased.
        self.erase_requested = False
        #: Inputs forced by a test or scenario (``Robot.set_input(..., force=True)``),
        #: applied after the wiring's own: name -> value.
        self.overrides: dict[str, object] = {}
        self._no_task = np.full(4, np.nan)
        self._inputs = vars(chart)  # plain attribute writes: this runs every chart step
        g = params.geometry
        self._geometry = (g.L1, g.L2, g.L3, g.L4, g.l_f)

    def tick(self, signals: Signals) -> None:
        """Inputs in, chart ticked, tool pose out."""
        c = self.chart
        arm = self.arm
        q1, q2, q3 = arm.encoder_angles()
        servo = float(signals.q_set[3])
        if not math.isfinite(servo):
            # no setpoint yet (the first chart step): the servo has no sensor, so
            # its pose is the angle it was last commanded
            servo = arm.servo_setpoint
        x, y, z, _ = _fk_python(q1, q2, q3, servo, *self._geometry)
        if self.erase_requested and "turn_pen" in c.active_ids:
            self.erase_requested = False
        d = self._inputs
        d["X_now"], d["Y_now"], d["Z_now"] = x, y, z
        d["initialised"], d["erase"] = self.init.done, self.erase_requested
        if self.overrides:
            d.update(self.overrides)
        c.tick()
        if math.isfinite(c.X_out):
            signals.task = [c.X_out, c.Y_out, c.Z_out, c.phi]
        else:
            signals.task = self._no_task
        signals.fr_sw = bool(c.fr_sw)
