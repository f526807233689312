"""The game inside the chart steps: what the flow waits for, and the stages the game adds to the scheduler.

:class:`Wait` is what the session's flow (:meth:`.game.GameSession.flow`)
yields between two of its moves; a :class:`GameDriver` plays that flow from
inside the chart steps (a debugger or a GUI stepping the robot).  Two stages
join the robot's scheduler: :class:`GameStage` runs the Game and
AlgorithmActivator charts before the Control chart (thesis section 3.6,
fig. 3.29: the engine asked on the activator's ``enable``), and
:class:`PenPathStage` keeps where the Control chart sends the pen, for the
game's drawing precision.  What they need of the session is
:class:`StagedSession` (:class:`~.game.GameSession` is one).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Generator
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from ..charts.game import AlgorithmActivator, Game
from ..sched.scheduler import Signals
from .game_outcome import GameError
from .robot import Robot
from .wiring import Wiring, not_wired

#: The drawing precision of a game with nothing to compare (no ink, no pen-down path, no ground truth).
NO_PRECISION: dict[str, float | None] = {"drawing_rms_mm": None, "drawing_max_mm": None}


@dataclass(frozen=True)
class Wait:
    """What the game flow waits for between two of its moves.

    Chart steps run until ``until()`` holds (checked after each step), at most
    ``timeout_s`` of simulated time; ``what`` names it in the error a timeout
    raises.  ``tell``: the Game chart's new messages are shown to the person
    meanwhile.
    """

    until: Callable[[], bool]
    timeout_s: float
    what: str
    tell: bool = True


#: The game flow (:meth:`.game.GameSession.flow`): yields what it waits for, returns at the end of the game.
Flow = Generator[Wait, None, None]


class StagedSession(Protocol):
    """What the game's stage and driver use of the session: its charts, flags and flow, its record's end."""

    robot: Robot
    game: Game
    activator: AlgorithmActivator
    driver: GameDriver | None
    outcome: str | None
    erase_started: bool
    erase_cause: str | None
    erased_seen: bool

    def flow(self, max_moves: int = 25) -> Flow:
        """The game flow, from its start."""

    def watch(self, wait: Wait) -> bool:
        """After a chart step: whether ``wait`` is over (the person is shown the Game chart's news)."""

    def wait_failed(self, wait: Wait) -> GameError:
        """The error of a wait that timed out."""

    def robot_turn_now(self) -> None:
        """The activator enabled the engine: its move goes to the Control chart."""

    def end_record(self, how: str, **data: Any) -> None:
        """The record's last event: how the game ended."""


class GameDriver:
    """Plays the game flow from inside the chart steps: whoever steps the robot plays the game.

    :meth:`.game.GameSession.play` runs the flow itself (``Robot.run_until`` for each
    :class:`Wait`).  A debugger or a GUI steps the robot one control step at a
    time instead; with a driver (:meth:`.game.GameSession.drive`) the Game stage
    checks the flow's wait at the start of each chart step, that is right after
    the previous chart step, where ``run_until`` checks it: the same game,
    move for move.  A wait that times out, or a camera view the game refuses,
    ends the flow with :attr:`error` (the charts run on); nothing is raised
    out of a chart step.
    """

    def __init__(self, session: StagedSession, max_moves: int) -> None:
        self.session = session
        self._flow: Flow | None = session.flow(max_moves)
        self.wait: Wait | None = None
        #: Chart steps run since the flow began its current wait.
        self.waited = 0
        #: Why the flow stopped before the end of the game (a wait that timed out, a refused view).
        self.error: GameError | None = None
        #: The flow ran to its end: the game is over and the arm turned off.
        self.done = False

    @property
    def running(self) -> bool:
        """The flow has not ended (neither finished nor stopped by an error)."""
        return self._flow is not None

    def before_chart_step(self) -> None:
        """Called at the start of every chart step: check the wait, go on with the flow when it holds."""
        flow = self._flow
        if flow is None:
            return
        wait = self.wait
        if self.session.robot.tripped:
            self._stop(GameError(f"safety stop: {self.session.robot.safety.reason}"))
            return
        if wait is not None:
            self.waited += 1
            if not self.session.watch(wait):
                limit = self.session.robot.sched.ticks_for(wait.timeout_s)
                if self.waited >= limit:
                    self._stop(self.session.wait_failed(wait))
                return
        try:
            self.wait = next(flow)
        except StopIteration:
            self._flow, self.wait, self.done = None, None, True
            self.session.end_record("finished", outcome=self.session.outcome, boundary=True)
            return
        except GameError as exc:
            self._stop(exc)
            return
        self.waited = 0

    def _stop(self, error: GameError) -> None:
        assert self._flow is not None
        self._flow.close()
        self._flow, self.error = None, error
        self.session.end_record("error", message=str(error), boundary=True)


class GameStage:
    """Task stage before the Control chart: the Game and AlgorithmActivator charts and the engine.

    What feeds the two charts and where their outputs go is the wiring
    table's (:data:`~ttt_sm.app.wires.GAME_WIRES`); this stage runs them and
    the session's part: the erase flag set once per game, the erasing seen
    through, the engine asked when the activator enables it.
    """

    def __init__(self, session: StagedSession) -> None:
        self.s = session
        self._feed_game: Callable[[], None] = not_wired
        self._after_game: Callable[[], tuple[bool, bool, bool, int, int]] = not_wired
        self._feed_activator: Callable[[], None] = not_wired
        self._enable: Callable[[], bool] = not_wired

    def blocks(self) -> dict[str, object]:
        """The session holds the Session block's outputs."""
        return {"Session": self.s}

    def wire(self, wiring: Wiring) -> None:
        """Compile this stage's part of the wiring table."""
        s = self.s
        self._feed_game = wiring.feed([s.game.chart_name])
        self._after_game = wiring.collect("EraseFlag.request", "Session.erasing", "Session.field_drawn",
                                          "EraseFlag.ctr", "EraseFlag.detected")
        self._feed_activator = wiring.feed([s.activator.chart_name])
        self._enable = wiring.collect("Session.enable")

    def tick(self, signals: Signals) -> None:
        s = self.s
        if s.driver is not None:
            s.driver.before_chart_step()
        self._feed_game()
        s.game.tick()
        request, erasing, field_drawn, ctr, detected = self._after_game()
        flag = s.robot.control_stage
        # the thesis' Erase_flag (section 3.6.1): the symbols drawn by the manipulator and those the
        # camera detected reach 25, a full board; or the game asks (section 3.6: the game is over)
        full = ctr + detected >= FULL_BOARD
        if (request or full) and not flag.erase_requested and not s.erase_started:
            flag.erase_requested = True
            s.erase_started = True
            s.erase_cause = "full board" if full else "game over"
        if s.erase_started and not s.erased_seen and not erasing and not field_drawn:
            s.erased_seen = True
        self._feed_activator()
        s.activator.tick()
        if self._enable():
            s.robot_turn_now()


#: The symbols on a full board: the thesis' Erase_flag turns on when the count reaches it (section 3.6.1).
FULL_BOARD = 25


class PenPathStage:
    """Joint stage: where the Control chart sends the pen each chart step while it draws (not erasing).

    For the game's drawing precision (:meth:`precision`, in :meth:`.game.GameSession.report`): the
    robot's ink against these desired pen-down paths, as ``ttt-sm draw``
    measures one drawing (thesis section 3.5).  Simulation only: the ink is
    the true pen's.
    """

    #: At most this many pen-down samples are kept (a game draws ~60 s of them: 30 000).
    MAX_SAMPLES = 250_000

    def __init__(self, robot: Robot) -> None:
        self.control = robot.control
        self.surface_z = robot.params.board.surface_z
        #: Desired pen positions while it is down, one row per chart step; a row at z = inf where it lifts.
        self.xyz: list[tuple[float, float, float]] = []
        self._down = False
        self.board = robot.board
        #: The robot's ink as it was when the sponge set off (the points of each stroke), kept for the report.
        self.ink: list[np.ndarray] | None = None

    def robot_ink(self) -> list[np.ndarray]:
        """The robot's ink strokes: as they were before erasing when the board was erased, else as they are."""
        if self.ink is not None:
            return self.ink
        return [s.points for s in self.board.strokes if s.author == "robot"]

    def tick(self, signals: Signals) -> None:
        c = self.control
        if c.erasing and self.ink is None:
            self.ink = [np.array(s.points) for s in self.board.strokes if s.author == "robot"]
        if c.busy and not c.erasing and c.Z_out <= self.surface_z:
            if len(self.xyz) < self.MAX_SAMPLES:
                self.xyz.append((c.X_out, c.Y_out, c.Z_out))
            self._down = True
        elif self._down:
            self.xyz.append((c.X_out, c.Y_out, math.inf))
            self._down = False

    def precision(self) -> dict[str, float | None]:
        """The robot's ink against the desired pen-down paths of the whole game, mm (None: nothing to compare)."""
        from .drawing import _distance_to_runs, _pen_down_runs

        ink = [p for p in self.robot_ink() if len(p)]
        if not ink or not self.xyz:
            return dict(NO_PRECISION)
        runs = _pen_down_runs(np.asarray(self.xyz), self.surface_z)
        if not runs:
            return dict(NO_PRECISION)
        err = _distance_to_runs(np.vstack(ink), runs) * 1e3
        return {"drawing_rms_mm": round(float(np.sqrt(np.mean(err ** 2))), 4),
                "drawing_max_mm": round(float(err.max()), 4)}
