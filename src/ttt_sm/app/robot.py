"""The robot as a whole: the arm, the scheduler and the charts, wired.

:class:`Robot` is the one object the debugger, the scenario runner, the CLI
and (later) the GUIs drive.  It knows the charts by name, steps the loop by a
control step or a chart step, runs until a condition holds, and exposes the
chart data and the signals of the current step without anyone reading code.

It holds the three drive-initialisation charts, the Control chart and the
Safety chart (docs/safety.md), wired by the table of :mod:`.wires`; a game
adds its charts (:meth:`Robot.add_charts`).

The charts' wiring and the scheduler talk to an :class:`~ttt_sm.arm.Arm`
(:attr:`Robot.arm`).  Ground truth (:attr:`Robot.truth`, the simulated arm's
``truth``) feeds only what exists in simulation alone: the whiteboard's
inking and the ``q_true`` / ``tool_true`` signals.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ..arm import Arm
from ..params import ArmParams
from ..runtime import TickChart
from ..sched.scheduler import Scheduler, Signals, Stage
from ..twin.gains import preset_params
from ..twin.gains_cache import kept_gains
from ..twin.sim import ArmSim
from ..twin.truth import GroundTruth
from ..twin.whiteboard import Whiteboard
from ..twin.workspace import check_drives, check_reach
from .compensation import GearPlayCompensation
from .control_wiring import ControlStage, make_control_chart
from .init_wiring import DriveInitStage, make_init_charts, settled_pose
from .safety_wiring import CameraStatus, SafetyStage, make_safety_chart
from .slots import ChartSlots, chosen_slots
from .wires import BLOCKS, ROBOT_WIRES
from .wiring import Wire, WiredStage, wire_stages


class BoardStage:
    """Joint stage run after the setpoints are set: the whiteboard sees the true pen and sponge.

    Simulation only: the simulated whiteboard is inked by the true tool.
    """

    def __init__(self, board: Whiteboard, truth: GroundTruth) -> None:
        self.board = board
        self.truth = truth

    def tick(self, signals: Signals) -> None:
        """Ink or wipe where the true tool touches the board now."""
        self.board.update(signals.t, self.truth.angles())


class PresetGainsStage:
    """Joint stage: once the drives are initialised, switch the cascades to the file's tuning preset.

    The init charts' stall rule (a setpoint ``stall_lag`` ahead of a still
    encoder) is set for the designed loops, which follow a search ramp
    closely; the "thesis" preset's position loop, with no speed
    feedforward, trails a 1 rad/s ramp by 1/kp = 0.06 rad and would read as
    a stall.  So the arm initialises with the designed gains and runs the
    preset's from the first chart step after (docs/tuning.md).
    """

    def __init__(self, arm: Any, gains: Any, initialised: Callable[[], bool]) -> None:
        self.arm = arm
        self.gains = gains
        self.initialised = initialised
        self.switched = False

    def tick(self, signals: Signals) -> None:
        """Switch the gains at the first chart step the drives are initialised in (once)."""
        if not self.switched and self.initialised():
            self.arm.set_gains(self.gains)
            self.switched = True


class RobotError(ValueError):
    """A request the robot cannot take: unknown chart, datum or event."""


class Robot:
    """The simulated robot with its charts, ready to step.

    Parameters
    ----------
    params : ArmParams
        The arm.
    seed : int
        Seeds the twin.
    q_start : array_like, shape (4,), optional
        Pose before power-on (default: the twin's rest pose).
    settle_s : float
        Seconds the unpowered arm settles under gravity before power-on.
    listeners : sequence
        python-statemachine listeners attached to every chart (trace, coverage,
        the debugger's breakpoints).
    arm : Arm, optional
        The arm to drive; None builds the simulated arm (:class:`ArmSim`) from
        `params`, `seed`, `q_start` and `settle_s`.
    truth : GroundTruth, optional
        Ground truth for the simulation-only parts (the whiteboard's ink, the
        ``q_true`` and ``tool_true`` signals); by default the simulated arm's
        own.  Without it (an arm that is no simulation) the whiteboard stays
        blank and those signals are NaN.
    wires : sequence of Wire
        The wiring table (default :data:`~ttt_sm.app.wires.ROBOT_WIRES`); a row
        that does not fit the charts' declarations raises
        :class:`~ttt_sm.app.wiring.WiringError` naming it.
    slots : ChartSlots, optional
        The class in each replaceable chart's place (:mod:`.slots`: a student's
        chart in the lab); None takes the command's choice
        (:func:`~.slots.chosen_slots`, the thesis' charts unless ``--chart``).
    """

    def __init__(self, params: ArmParams, seed: int = 0, q_start: Sequence[float] | None = None,
                 settle_s: float = 0.0, listeners: Sequence[object] = (), arm: Arm | None = None,
                 truth: GroundTruth | None = None, wires: Sequence[Wire] = ROBOT_WIRES,
                 slots: ChartSlots | None = None) -> None:
        check_drives(params)  # an encoder too coarse for the charts, a gear too stiff for the twin's step
        check_reach(params)  # a field out of reach would be drawn as nothing, silently
        params = preset_params(params)  # the Safety chart's thresholds a slower tuning preset needs
        self.params = params
        self.seed = seed
        #: The class in each replaceable chart's place (the game takes its charts' from here too).
        self.slots = slots if slots is not None else chosen_slots()
        #: The simulated arm when this robot built it, else None.
        self.sim: ArmSim | None = None
        if arm is None:
            q0 = np.asarray(q_start, dtype=float) if q_start is not None else None
            if settle_s > 0:
                q0 = settled_pose(params, q0, settle_s, seed)
            self.sim = ArmSim(params, seed=seed, q0=q0)
            arm, truth = self.sim, self.sim.truth
        #: What the scheduler and the charts' wiring talk to.
        self.arm: Arm = arm
        #: Ground truth, simulation only (None for an arm that is no simulation).
        self.truth = truth
        self.sched = Scheduler(params, arm)
        self.listeners = list(listeners)
        init = make_init_charts(params, listeners, slots=self.slots)
        self.init_stage = DriveInitStage(params, arm, self.sched, init)
        self.compensation = GearPlayCompensation(params, lambda: self.init_stage.done)
        self.board = Whiteboard(params, seed=seed)
        #: The ``Camera`` block the Safety chart watches: a game sets it from its camera link.
        self.camera_status = CameraStatus()
        self.safety = make_safety_chart(params, listeners)
        self.safety_stage = SafetyStage(params, arm, self.sched, self.safety, self.reinitialise, self.camera_status)
        joint_stages: list[Stage] = [self.init_stage, self.compensation, self.safety_stage]
        if params.tuning.preset != "ours" and hasattr(arm, "set_gains"):
            preset = kept_gains(params, params.tuning.preset)
            joint_stages.append(PresetGainsStage(arm, preset, lambda: self.init_stage.done))
        if truth is not None:
            joint_stages.append(BoardStage(self.board, truth))
        self.sched.joint_stages = joint_stages
        self.control = make_control_chart(params, listeners, self.slots)
        self.control_stage = ControlStage(params, arm, self.init_stage, self.control)
        self.sched.task_stages = [self.control_stage]
        self.charts: dict[str, TickChart] = {c.chart_name: c for c in (*init, self.control, self.safety)}
        #: The wiring table this robot runs (:mod:`.wires`), checked against the charts here.
        self.wires: tuple[Wire, ...] = tuple(wires)
        self._wired: list[WiredStage] = [self.init_stage, self.control_stage, self.safety_stage]
        self._objects: dict[str, object] = {}
        self.wiring = wire_stages(self.wires, self.charts, self._wired, BLOCKS)
        #: The game around the charts when a :class:`~.game.GameSession` added its own, else None
        #: (typed loosely: the game is built on the robot, not the robot on the game).
        self.game: object | None = None
        #: Called with the new charts each time :meth:`reinitialise` puts them in the old ones' place
        #: (a debugger attaches its trace and breakpoints to them).
        self.charts_replaced: list[Callable[[Sequence[TickChart]], None]] = []

    def add_charts(self, charts: Sequence[TickChart], wires: Sequence[Wire], stage: WiredStage,
                   objects: dict[str, object] | None = None) -> None:
        """Add charts run by a task stage that runs before the others (the game's), and their wires.

        The whole table is checked again and every stage recompiled: a wire may
        feed a chart that was there before (the Game chart's `finish` feeds Control's).
        """
        charts_now = {**self.charts, **{c.chart_name: c for c in charts}}
        wired = [stage, *self._wired]
        table = (*self.wires, *wires)
        self.wiring = wire_stages(table, charts_now, wired, BLOCKS, objects)
        self.charts, self._wired, self.wires = charts_now, wired, table
        self._objects = dict(objects or {})
        self.sched.task_stages.insert(0, stage)  # type: ignore[arg-type]

    def reinitialise(self) -> None:
        """Initialise the drives again, as at power-on: the Safety chart's reset (docs/safety.md).

        Every encoder reads 0 where the drive stands, as at power-on (its
        offset is minus its counts), and the joint limits are no longer
        enforced (the drives do not know where they are); new drive-
        initialisation charts and a new Control chart take the place of the
        old ones (their clocks going on from the old ones' chart tick), the
        whole table is wired again and :attr:`charts_replaced` is told.  The
        init charts search their switches from where the arm stands.  An arm
        with a link first re-arms it (``rearm``, the :class:`~ttt_sm.arm.Arm`
        protocol's optional surface): a firmware that stopped the drives takes
        ``START`` again once the link answers; while it does not, the Safety
        chart trips on the link again.
        """
        rearm = getattr(self.arm, "rearm", None)
        if rearm is not None:
            rearm()
        counts = self.arm.sensors().counts
        offsets = [-c * d.rad_per_count for c, d in zip(counts, self.params.drives, strict=True)]
        for drive in (1, 2, 3):
            self.arm.set_offset_estimate(drive, offsets[drive - 1])
        self.sched.forget_homing()
        init = make_init_charts(self.params, self.listeners, offsets, self.slots)
        old_init, old_control = self.init_stage, self.control_stage
        self.init_stage = DriveInitStage(self.params, self.arm, self.sched, init)
        self.control = make_control_chart(self.params, self.listeners, self.slots)
        self.control_stage = ControlStage(self.params, self.arm, self.init_stage, self.control)
        self.sched.joint_stages = [self.init_stage if s is old_init else s for s in self.sched.joint_stages]
        self.sched.task_stages = [self.control_stage if s is old_control else s for s in self.sched.task_stages]
        self._wired = [self.init_stage if s is old_init else self.control_stage if s is old_control else s
                       for s in self._wired]
        for chart in (*init, self.control):
            # the run's clock goes on: the new chart's ticks (its trace, its timeline) follow the old one's
            chart.start_clock_at(self.charts[chart.chart_name].tick_count)
            self.charts[chart.chart_name] = chart
        self.wiring = wire_stages(self.wires, self.charts, self._wired, BLOCKS, self._objects)
        for tell in self.charts_replaced:
            tell((*init, self.control))

    @property
    def tripped(self) -> bool:
        """The Safety chart holds the arm in a safe state (its `reason` says why)."""
        return bool(self.safety.tripped)

    # -- time ------------------------------------------------------------------

    @property
    def t(self) -> float:
        """The arm's time since power-on, s."""
        return self.arm.t

    @property
    def steps(self) -> int:
        """Control steps run so far."""
        return self.sched.steps

    @property
    def chart_ticks(self) -> int:
        """Chart steps run so far."""
        return self.sched.chart_ticks

    def control_step(self) -> None:
        """One control step (a chart step too, every `chart_divider`-th)."""
        self.sched.control_step()

    def chart_step(self) -> None:
        """Run control steps up to and through the next chart step."""
        self.sched.run_until(lambda: True, timeout_s=self.params.control.chart_dt)

    def run_for(self, seconds: float) -> None:
        """Run whole chart steps for `seconds` of simulated time."""
        self.sched.run_for(seconds)

    def run_until(self, predicate: Callable[[], bool], timeout_s: float) -> bool:
        """Run chart steps until `predicate()` holds; False if `timeout_s` passed first."""
        return self.sched.run_until(predicate, timeout_s)

    # -- charts ------------------------------------------------------------------

    def chart(self, name: str) -> TickChart:
        """A chart by name (``DriveInit1`` ...); a clear error names the charts there are."""
        try:
            return self.charts[name]
        except KeyError:
            raise RobotError(f"no chart {name!r}; charts: {', '.join(self.charts)}") from None

    def active(self, chart: str) -> set[str]:
        """The active configuration (state ids) of a chart."""
        return set(self.chart(chart).configuration_values)

    def set_input(self, chart: str, name: str, value: Any, force: bool = False) -> None:
        """Set a chart input.

        Inputs that the wiring feeds every chart step (the Encoder block's
        `index`, the Control chart's `erase` from :attr:`ControlStage.erase_requested`,
        ...) would be overwritten at the next step: `force` keeps the value
        there until :meth:`release`, as a test of a broken switch needs.
        """
        c = self.chart(chart)
        names = {d.name for d in c.declarations() if d.kind == "input"}
        if name not in names:
            raise RobotError(f"{chart} has no input {name!r}; inputs: {', '.join(sorted(names))}")
        setattr(c, name, value)
        if force:
            overrides, key = self._forced(chart, name)
            overrides[key] = value

    def release(self, chart: str, name: str) -> None:
        """Stop forcing an input (see :meth:`set_input`)."""
        overrides, key = self._forced(chart, name)
        overrides.pop(key, None)

    def _forced(self, chart: str, name: str) -> tuple[dict[Any, object], Any]:
        """Where a forced input of `chart` is kept, and its key there."""
        if chart == self.control.chart_name:
            return self.control_stage.overrides, name
        if chart == self.safety.chart_name:
            return self.safety_stage.overrides, name
        return self.init_stage.overrides, (self._init_index(chart), name)

    def post(self, chart: str, event: str, /, **data: Any) -> None:
        """Send an event to a chart; it is handled at the chart's next tick."""
        self.chart(chart).post(event, **data)

    def value(self, chart: str, name: str) -> Any:
        """A chart datum (input, output or local) by name."""
        c = self.chart(chart)
        names = {d.name for d in c.declarations()}
        if name not in names:
            raise RobotError(f"{chart} has no datum {name!r}; data: {', '.join(sorted(names))}")
        return getattr(c, name)

    def _init_index(self, chart: str) -> int:
        names = [c.chart_name for c in self.init_stage.charts]
        if chart not in names:
            raise RobotError(f"only the init charts', Control's and Safety's inputs can be forced, not {chart!r}")
        return names.index(chart)

    # -- signals -------------------------------------------------------------------

    def signal_values(self) -> dict[str, Any]:
        """The signals of the current step, as plain numbers (SI units).

        ``q_true`` and ``tool_true`` are simulation only: the ground truth of
        the simulated arm (NaN when the robot has none).
        """
        s = self.sched.signals
        arm = self.arm
        if self.truth is not None:
            q_true = [float(v) for v in self.truth.q]
            tool = [float(v) for v in self.truth.tool_pose()]
        else:
            q_true = tool = [math.nan] * 4
        sensors = arm.sensors()
        return {
            "t": round(arm.t, 6),
            "q_set": [float(v) for v in s.q_set],
            "q_encoder": list(arm.encoder_angles()),
            "q_true": q_true,
            "offset_estimate": list(arm.offset_estimates()),
            "index": list(sensors.index),
            "counts": list(sensors.counts),
            "current_a": [round(float(v), 4) for v in sensors.current_a],
            "tool_true": tool,
            "fr_sw": bool(s.fr_sw),
            "ik_error": s.ik_error,
        }

    def snapshot(self) -> dict[str, Any]:
        """Every chart's configuration and data, and the signals: what a debugger shows."""
        return {
            "t": round(self.arm.t, 6),
            "charts": {name: {"active": sorted(c.configuration_values), "data": c.snapshot()}
                       for name, c in self.charts.items()},
            "signals": self.signal_values(),
        }

    @property
    def initialised(self) -> bool:
        """True once every drive passes its commanded position through."""
        return self.init_stage.done
