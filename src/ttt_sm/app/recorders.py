"""What a measuring run records: the paths of section 3.5 per chart step, and the chart states over time.

Thesis section 3.5 compares where the tool was meant to be (the desired
pose), where forward kinematics of the encoder angles puts it, and where it
truly is.  A recorder is a joint stage run last in the scheduler: while `on`,
it notes the three per chart step.  :class:`PoseRecorder` reads what both
experiments share (the desired pose the stages command, the encoder angles
with the servo's commanded angle: the servo has no encoder);
:class:`RecordStage` adds what a drawing needs (``ttt-sm draw``: FK with the
nominal and the as-built lengths, the true tool, the ink's tip) and
:class:`StairRecorder` what the staircase needs (:mod:`.precision`: FK, the
true tool and a triangulation sensor's reading).  Simulation only: the true
tool is the twin's ground truth.

:class:`ActiveStateLog` notes when each state of a chart became active, for
the labels of the path plot only.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..sched.scheduler import Signals
from ..twin.kinematics import arm_chain_py, fk
from ..twin.sensor import TriangulationSensor
from ..twin.truth import GroundTruth
from .robot import Robot

#: A point of a path, m.
Point = tuple[float, float, float]
#: Joint angles q1..q4, rad.
Angles = tuple[float, float, float, float]


class PoseRecorder:
    """Joint stage run last: while `on`, hands :meth:`note` this chart step's desired pose and encoder angles."""

    def __init__(self, robot: Robot, truth: GroundTruth) -> None:
        self.robot = robot
        self.truth = truth
        self.on = False

    def tick(self, signals: Signals) -> None:
        """Note this chart step, while `on`."""
        if not self.on:
            return
        q1, q2, q3 = self.robot.arm.encoder_angles()
        task = signals.task  # the Control chart's pose, or the pose of a path stage after it
        self.note(signals, (float(task[0]), float(task[1]), float(task[2])), (q1, q2, q3, float(signals.q_set[3])))

    def note(self, signals: Signals, desired: Point, q_encoder: Angles) -> None:
        """Record one chart step: `desired` tool position, m; `q_encoder` with the servo's commanded angle, rad."""
        raise NotImplementedError


@dataclass
class PoseRecord:
    """Per chart step: its time, s, and the desired tool position, m (what both records begin with)."""

    t: list[float] = field(default_factory=list)
    desired: list[Point] = field(default_factory=list)


@dataclass
class DrawRecord(PoseRecord):
    """Per chart step: desired pose, forward kinematics of the encoders, the true tip."""

    fk_encoder: list[Point] = field(default_factory=list)
    #: Forward kinematics of the same encoder angles with the arm's true lengths (``[as_built]``).
    fk_as_built: list[Point] = field(default_factory=list)
    fk_true: list[Point] = field(default_factory=list)
    tip: list[tuple[float, float]] = field(default_factory=list)  # NaN while the pen is lifted


class RecordStage(PoseRecorder):
    """Records the three paths of a drawing (section 3.5) while `on`, and the ink's tip."""

    def __init__(self, robot: Robot, truth: GroundTruth) -> None:
        super().__init__(robot, truth)
        self.record = DrawRecord()

    def note(self, signals: Signals, desired: Point, q_encoder: Angles) -> None:
        r = self.robot
        rec = self.record
        rec.t.append(r.t)
        rec.desired.append(desired)
        rec.fk_encoder.append(tuple(fk(q_encoder, r.params.geometry)[:3]))
        rec.fk_as_built.append(tuple(fk(q_encoder, r.params.true_geometry)[:3]))
        rec.fk_true.append(tuple(self.truth.tool_pose()[:3]))
        contact = r.board.contact
        rec.tip.append(contact.tip_m if contact.pen_touching and contact.tip_m else (math.nan, math.nan))


@dataclass
class StairRecord(PoseRecord):
    """Per chart tick: time, desired pose, FK of the encoders, the true tool and the sensor's coordinate."""

    fk: list[Point] = field(default_factory=list)
    q_encoder: list[Angles] = field(default_factory=list)
    true: list[Point] = field(default_factory=list)
    sensor: list[float | None] = field(default_factory=list)  # the coordinate along the axis, m; None out of range


class StairRecorder(PoseRecorder):
    """Records the three values of the staircase (section 3.5) while `on`: FK, the true tool, the sensor."""

    def __init__(self, robot: Robot, truth: GroundTruth, sensor: TriangulationSensor, axis: np.ndarray) -> None:
        super().__init__(robot, truth)
        self.sensor = sensor
        self.axis = axis
        g = robot.params.geometry  # the nominal lengths: what forward kinematics on a real arm knows
        self._geometry = (g.L1, g.L2, g.L3, g.L4, g.l_f)
        self.record = StairRecord()

    def note(self, signals: Signals, desired: Point, q_encoder: Angles) -> None:
        rec = self.record
        x, y, z, *_ = arm_chain_py(*q_encoder, *self._geometry)
        tip = self.truth.tool_pose()
        rec.t.append(signals.t)
        rec.desired.append(desired)
        rec.fk.append((x, y, z))
        rec.q_encoder.append(q_encoder)
        rec.true.append((float(tip[0]), float(tip[1]), float(tip[2])))
        rec.sensor.append(self.sensor.position(self.sensor.distance(tip), self.axis))


class ActiveStateLog:
    """python-statemachine listener: when each leaf state of a chart became active, by a clock.

    For labelling plots only (which sub-chart drew what): it reads state names,
    so nothing may decide anything by it.
    """

    def __init__(self, clock: Callable[[], float]) -> None:
        self.clock = clock
        #: (time, ``"parent.leaf"``) at each change of the active leaf, oldest first.
        self.changes: list[tuple[float, str]] = []

    def observe(self, chart: Any) -> ActiveStateLog:
        """Attach to a chart and note the leaf active now."""
        chart.add_listener(self)
        self._note(chart)
        return self

    def after_transition(self, machine: Any) -> None:
        self._note(machine)

    def _note(self, machine: Any) -> None:
        leaves = [s for s in machine.configuration if not s.states]
        label = ", ".join(f"{s.parent.id}.{s.id}" if s.parent is not None else s.id for s in leaves)
        if not self.changes or self.changes[-1][1] != label:
            self.changes.append((self.clock(), label))

    def between(self, t0: float, t1: float) -> list[tuple[float, str]]:
        """The changes in [t0, t1], led by the state already active at t0 (stamped t0)."""
        before = [c for c in self.changes if c[0] <= t0]
        inside = [c for c in self.changes if t0 < c[0] <= t1]
        return ([(t0, before[-1][1])] if before else []) + inside

