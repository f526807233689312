"""The step-through debugger's engine: run, pause, step, breakpoints, inputs, replay.

:class:`Debugger` drives a :class:`~ttt_sm.app.robot.Robot` one control step
at a time and stops *between control steps*.  A chart tick is the first part
of the control step it starts (every ``chart_divider``-th step), so when a
breakpoint hits at chart tick *k* the debugger stops right after the control
step holding tick *k*: the charts show the configuration and data that tick
produced, and the twin has moved one control step (1 ms) since (the loop:
:mod:`.stepping`).

It watches the charts through python-statemachine listeners only (a
:class:`~ttt_sm.runtime.listeners.Trace` and a
:class:`~.breakpoints.BreakListener`), so it sees exactly what the library did.

Everything the user changes (inputs set or forced, events posted) is recorded
with the control step it was applied at (:mod:`.inputs`); :meth:`Debugger.replay` rebuilds the
robot from its recipe (parameters, seed, power-on pose), re-applies them at the
same steps and runs to a chart tick, and tells whether it arrived in exactly the
state recorded when the session was there before (:mod:`.history`).

A robot built with the game (:class:`~.replay.GameRecipe`, ``ttt-sm debug
--game``) carries the Game and AlgorithmActivator charts and plays its game
from inside the chart steps (the simulated person, the camera, the engine):
stepping the robot plays the game, and a breakpoint on ``Game.drawing``
stops at the robot's turn.

Besides the trace it keeps a :class:`~.timeline.Timeline` (when each state
was entered and left) and the charts' data as they were just before the last
chart tick, for :meth:`Debugger.data_diff` (:mod:`.watch`).

Bounded in memory: the trace keeps the newest :data:`TRACE_KEEP` transitions
(a ring buffer); given a ``trace_path``, the whole trace is streamed to that
file as it happens, each line flushed (:class:`~ttt_sm.runtime.recordfile.RecordFile`:
a head line, the transitions, a mark at each replay, and an ending that
says how the session ended, written by :meth:`Debugger.end_trace`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from ..app.game import GameSession
from ..app.robot import Robot
from ..app.slots import ChartSlots, chosen_slots
from ..arm import Arm
from ..params import ArmParams
from ..runtime.listeners import Trace
from ..runtime.recordfile import RecordFile
from ..twin.truth import GroundTruth
from .breakpoints import Breakpoint, BreakpointTable
from .errors import DebugError
from .history import History
from .inputs import Inputs
from .names import RobotNames
from .replay import ArmRecipe, GameRecipe, Recipe, ReplayResult, RobotRecipe, game_of
from .stepping import Stepper
from .timeline import Timeline
from .watch import ChartWatch, trace_head

#: The longest one command (run, next, step, tick) may run unless raised, seconds of
#: simulated time: a typo like ``run 1e12`` would never end.  ``ttt-sm debug --max-run``.
DEFAULT_MAX_RUN_S = 600.0
#: Transitions the trace keeps in memory (the newest); the trace file, if any, gets them all.
TRACE_KEEP = 5000


class Debugger:
    """Step through a :class:`Robot`'s charts: the API under ``ttt-sm debug`` (and a GUI).

    Parameters
    ----------
    robot : Robot
        The robot to debug.  Listeners are added to its charts.
    recipe : Recipe, optional
        How to build the same robot again, for :meth:`replay`.  By default it
        is read from the robot when it has not run yet (parameters, seed and
        the pose it was powered on in); :meth:`build` records it too.
    max_run_s : float
        The longest one command may run, seconds of simulated time
        (:data:`DEFAULT_MAX_RUN_S`); longer is refused before a step is taken.
    trace_path : path, optional
        Stream the whole trace to this file as it happens (JSON Lines, each
        line flushed); opened now, so an ``OSError`` says it cannot be written
        before anything runs.  :meth:`end_trace` writes its last line.
    trace_keep : int
        Transitions kept in memory (:data:`TRACE_KEEP`), the newest.

    The work is done by five parts, each an attribute; the debugger offers
    their commands under its own names:

    - :attr:`watch` (:class:`~.watch.ChartWatch`): the listeners on every
      chart, the charts by name, the data before a tick, the trace:
      ``add_listener``, ``chart``, ``where``, ``timeline``, ``data_diff``,
      ``diagram``, ``save_trace``, ``end_trace``, ``where_now``;
    - :attr:`breakpoint_table` (:class:`~.breakpoints.BreakpointTable`):
      ``add_breakpoint``, ``delete``, ``enable``, ``disable``;
    - :attr:`stepper` (:class:`~.stepping.Stepper`), run control:
      ``pause``, ``step``, ``tick``, ``next``, ``run``;
    - :attr:`inputs` (:class:`~.inputs.Inputs`), recorded for replay:
      ``datum_decl``, ``parse_value``, ``set_input``, ``release``, ``post``,
      ``game_input``;
    - :attr:`history` (:class:`~.history.History`), where the session has
      been: ``fingerprint``, ``steps_of_tick``.

    The debugger itself builds the robot again (:meth:`replay`,
    :meth:`start_over`) and sets every part on the new one.
    """

    def __init__(self, robot: Robot, recipe: Recipe | None = None, *,
                 max_run_s: float = DEFAULT_MAX_RUN_S, trace_path: str | Path | None = None,
                 trace_keep: int = TRACE_KEEP) -> None:
        if recipe is None and robot.steps == 0:
            recipe = RobotRecipe.of(robot)
        if not (isinstance(max_run_s, (int, float)) and math.isfinite(max_run_s) and max_run_s > 0):
            raise DebugError(f"max_run_s must be a positive number of seconds, got {max_run_s!r}")
        self.recipe = recipe
        self.robot = robot

        def now() -> Robot:  # what every part asks for: a replay replaces the robot
            return self.robot

        names = RobotNames(now)
        #: The charts' data and the robot's signals by name (what conditions and ``display`` read).
        self.names = names
        self.trace_keep = trace_keep
        #: The file the whole trace streams to (None: the kept transitions only).
        self.trace_file: RecordFile | None = None
        if trace_path is not None:
            self.trace_file = RecordFile(trace_path)
            self.trace_file.add(trace_head(robot, recipe, trace_keep))
        self.breakpoint_table = BreakpointTable(lambda: self.watch.index, names)
        self.watch = ChartWatch(names, [self.breakpoint_table.listener], self.trace_file, trace_keep)
        forced: dict[tuple[str, str], Any] = {}
        self.history = History(now, forced)
        self.inputs = Inputs(now, names, self.history, forced)
        self.stepper = Stepper(now, self.breakpoint_table, self.watch, self.history.remember, float(max_run_s))
        self.stepper.ahead, self.stepper.apply_due = self.inputs.ahead, self.inputs.apply_due
        #: The breakpoints, in the order they were added.
        self.breakpoints: list[Breakpoint] = self.breakpoint_table.items
        #: What the user did (inputs set, forced, released, events posted), in order, for replay.
        self.actions = self.inputs.actions
        #: The inputs forced now: (chart, name) -> value.
        self.forced = forced
        # The parts' commands, under the names the shell, the cockpit and docs/debugger.md use.
        watch, table, stepper, inputs = self.watch, self.breakpoint_table, self.stepper, self.inputs
        self.add_listener, self.chart, self.where = watch.add_listener, watch.chart, watch.where
        self.timeline, self.data_diff, self.diagram = watch.timeline, watch.data_diff, watch.diagram
        self.save_trace, self.end_trace, self.where_now = watch.save_trace, watch.end_trace, watch.where_now
        self.add_breakpoint, self.delete = table.add, table.delete
        self.enable, self.disable = table.enable, table.disable
        self.pause, self.step, self.tick, self.next, self.run = (stepper.pause, stepper.step, stepper.tick,
                                                                  stepper.next, stepper.run)
        self.datum_decl, self.parse_value = inputs.datum_decl, inputs.parse_value
        self.set_input, self.release = inputs.set_input, inputs.release
        self.post, self.game_input, self.staircase = inputs.post, inputs.game_input, inputs.staircase
        self.fingerprint, self.steps_of_tick = self.history.fingerprint, self.history.steps_of_tick
        self._attach(robot)
        self.history.restart()

    @classmethod
    def build(cls, params: ArmParams, seed: int = 0, q_start: Sequence[float] | None = None,
              settle_s: float = 0.0, *, game: bool = False, person: str = "simulated",
              max_run_s: float = DEFAULT_MAX_RUN_S, trace_path: str | Path | None = None,
              record_root: Path | None = None, arm: Arm | None = None,
              truth: GroundTruth | None = None, slots: ChartSlots | None = None) -> Debugger:
        """A debugger on a new robot, with its recipe for :meth:`replay`.

        ``game``: the robot plays a game (:class:`~.replay.GameRecipe`: the Game
        and AlgorithmActivator charts, a simulated person, the camera read
        in-process, the strong engine; the robot draws O).  ``person``: who plays
        against it, ``"simulated"`` or ``"page"`` (a person at the ``/game`` page).
        ``trace_path``: stream the whole trace there (see the class).
        ``record_root``: with ``game``, the game's record is written to
        ``record_root/game-1/game.jsonl`` as it is played.
        ``arm`` (and the ``truth`` it offers): another arm than the twin
        (``--arm serial:PORT``); the robot is built on it once (no replay).
        ``slots``: the class in each replaceable chart's place, kept in the recipe
        (default: the command's, :func:`~ttt_sm.app.slots.chosen_slots`).
        """
        if arm is not None:
            arm_recipe = ArmRecipe(params, arm, truth, seed, game=game, person=person, record_root=record_root)
            return cls(arm_recipe.build(), arm_recipe, max_run_s=max_run_s, trace_path=trace_path)
        pose = None if q_start is None else tuple(float(v) for v in q_start)
        chosen = slots if slots is not None else chosen_slots()
        recipe: Recipe = GameRecipe(params, seed, pose, settle_s, person=person, record_root=record_root,
                                    slots=chosen) if game else RobotRecipe(params, seed, pose, settle_s, slots=chosen)
        return cls(recipe.build(), recipe, max_run_s=max_run_s, trace_path=trace_path)

    def _attach(self, robot: Robot) -> None:
        """Debug ``robot`` from now on (one built again by a replay or a start over): every part on it."""
        self.robot = robot
        self.watch.attach(robot)
        self.stepper.note_game()

    @property
    def game(self) -> GameSession | None:
        """The game around the charts (``build(..., game=True)``), else None."""
        return game_of(self.robot)

    @property
    def chart_names(self) -> list[str]:
        return list(self.robot.charts)

    def signals(self) -> dict[str, Any]:
        """The robot's signals now (SI units)."""
        return self.robot.signal_values()

    @property
    def trace(self) -> Trace:
        """The transitions since power-on or the last replay (the newest :attr:`trace_keep`)."""
        return self.watch.trace

    @property
    def trace_failure(self) -> OSError | None:
        """Why the trace file stopped before the session's end (the disk full), or None: the file holds
        whole lines only, the session goes on with the transitions in memory."""
        return self.watch.trace_failure

    @property
    def state_history(self) -> Timeline:
        """When each chart's states were entered and left (see :meth:`~.watch.ChartWatch.timeline`)."""
        return self.watch.state_history

    @property
    def max_run_s(self) -> float:
        """The longest one command may run, seconds of simulated time."""
        return self.stepper.max_run_s

    @property
    def progress(self) -> Callable[[float, float], None] | None:
        """``progress(t, t_end)``, told where a long command is every few simulated seconds; None: silent."""
        return self.stepper.progress

    @progress.setter
    def progress(self, progress: Callable[[float, float], None] | None) -> None:
        self.stepper.progress = progress

    @property
    def furthest_tick(self) -> int:
        """The furthest chart tick the session has run to: :meth:`replay` takes any tick up to it."""
        return self.history.furthest_tick

    # -- building the robot again ------------------------------------------------------

    def start_over(self, recipe: Recipe) -> None:
        """A new run from power-on on the robot ``recipe`` builds (a new game): the inputs recorded,
        the replay fingerprints and how far the session has been are those of the new run only;
        breakpoints are kept."""
        old = game_of(self.robot)
        if old is not None:
            old.close()  # its record ends (as interrupted, unless the game ended)
        self.recipe = recipe
        self.actions.clear()
        self.inputs.ahead.clear()
        self.forced.clear()
        self._attach(recipe.build())
        self.watch.mark("start_over")  # the trace goes on: the transitions after this mark are the new run's
        self.history.restart()
        self.breakpoint_table.rearm()

    def replay(self, tick: int, *, drop: bool = False) -> ReplayResult:
        """Rebuild the robot and run it to chart ``tick``, re-applying the recorded inputs.

        It stops where a breakpoint at that tick stops: right after the control
        step holding the tick (:meth:`~.history.History.steps_of_tick`).  Inputs
        and events recorded after that point are kept and applied again when a
        run reaches their control steps (the future you gave is not lost);
        ``drop``: they are dropped instead.  Breakpoints do not hit during a
        replay; the trace is recorded anew.
        """
        if not isinstance(tick, int) or tick < 0:
            raise DebugError(f"replay: the chart tick must be a whole number >= 0, got {tick!r}")
        if self.steps_of_tick(tick) > self.history.furthest_steps:
            raise DebugError(f"replay: chart tick {tick} lies beyond where this session has been (chart tick"
                             f" {self.furthest_tick}); replay goes back, run goes forward")
        return self.replay_to_step(self.steps_of_tick(tick), drop=drop)

    def back(self, ticks: int = 1) -> ReplayResult:
        """Go back ``ticks`` chart ticks (a replay): to right after the chart tick ``ticks`` before the
        last one run (right after the last one, if the robot has stepped past it since)."""
        if not isinstance(ticks, int) or ticks < 1:
            raise DebugError(f"back: the count must be a whole number >= 1, got {ticks!r}")
        now = self.robot.chart_ticks
        target = now - ticks if self.robot.steps <= self.steps_of_tick(now) else now - ticks + 1
        if target < 0:
            raise DebugError(f"back: {ticks} chart tick{'s' if ticks != 1 else ''} back is before power-on"
                             f" (the robot is at chart tick {now})")
        return self.replay(target)

    def step_back(self, steps: int = 1) -> ReplayResult:
        """Go back ``steps`` control steps (a replay)."""
        if not isinstance(steps, int) or steps < 1:
            raise DebugError(f"step back: the count must be a whole number >= 1, got {steps!r}")
        if steps > self.robot.steps:
            raise DebugError(f"step -{steps}: that is before power-on (the robot is at step {self.robot.steps})")
        return self.replay_to_step(self.robot.steps - steps)

    def replay_to_step(self, steps: int, *, drop: bool = False) -> ReplayResult:
        """:meth:`replay` to any control step count (a position between two ticks, too)."""
        if self.recipe is None:
            raise DebugError("replay needs the robot's recipe: build with Debugger.build(...) or"
                             " pass recipe=RobotRecipe(params, seed, q_start, settle_s)")
        if not isinstance(steps, int) or steps < 0:
            raise DebugError(f"replay: the step must be a whole number >= 0, got {steps!r}")
        furthest = self.history.furthest_steps
        if steps > furthest:
            raise DebugError(f"replay: control step {steps} lies beyond where this session has been (step"
                             f" {furthest}); replay goes back, run goes forward")
        # a replay runs the robot again from power-on: its work is the simulated time to `steps`, bounded
        # as one command's run is (docs/gui.md, "Limits"), so no replay holds the session for minutes
        seconds = steps * self.robot.params.control.dt
        limit = self.stepper.max_run_s
        if seconds > limit * (1 + 1e-9):
            raise DebugError(f"replay: it would run {seconds:g} s of simulated time again from power-on (to control"
                             f" step {steps}), beyond the {limit:g} s one command runs (start the debugger with"
                             f" --max-run SECONDS to allow more)")
        given = [*self.actions, *self.inputs.ahead]
        kept = [a for a in given if a.steps <= steps]
        later = [a for a in given if a.steps > steps]
        self.inputs.ahead.clear()
        self.forced.clear()
        old = game_of(self.robot)
        if old is not None and old.record.attached:
            old.record.close()  # the rebuilt game writes its record anew, to the same file
        self._attach(self.recipe.build())
        try:
            self.stepper.fast_forward(steps, kept, self.inputs.apply)
        finally:  # the trace file has these transitions already: a mark stands for them
            self.watch.mark("replay", actions=len(kept))
        self.stepper.note_game()
        self.actions[:] = kept
        if not drop:
            self.inputs.ahead.extend(later)
        identical, diffs = self.history.arrived(steps, drop and bool(later))
        self.breakpoint_table.rearm()
        robot = self.robot
        return ReplayResult(robot.chart_ticks, robot.steps, robot.t, len(kept), len(later) if drop else 0,
                            identical, diffs, ahead=0 if drop else len(later))
