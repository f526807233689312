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

from ..charts.control import Control
from ..params import ArmParams
from ..sched.scheduler import Signals
from ..twin.kinematics import fk
from ..twin.plant import ArmSim
from .init_wiring import DriveInitStage


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

    def __init__(self, params: ArmParams, sim: ArmSim, init: DriveInitStage, chart: Control) -> None:
        self.params = params
        self.sim = sim
        self.init = init
        self.chart = chart
        #: The game's request to erase (the thesis' Erase_flag); cleared once erased.
        self.erase_requested = False
        self._no_task = np.full(4, np.nan)

    def tick(self, signals: Signals) -> None:
        """Inputs in, chart ticked, tool pose out."""
        c = self.chart
        sim = self.sim
        q_enc = sim.q_encoder
        servo = signals.q_set[3] if math.isfinite(signals.q_set[3]) else sim.q_true[3]
        x, y, z, _ = fk((q_enc[0], q_enc[1], q_enc[2], servo), self.params.geometry)
        c.X_now, c.Y_now, c.Z_now = x, y, z
        c.initialised = self.init.done
        if self.erase_requested and "turn_pen" in c.configuration_values:
            self.erase_requested = False
        c.erase = self.erase_requested
        c.tick()
        if math.isfinite(c.X_out):
            signals.task = np.array([c.X_out, c.Y_out, c.Z_out, c.phi])
        else:
            signals.task = self._no_task
        signals.fr_sw = bool(c.fr_sw)
