"""What the user changes from outside the charts, applied now and recorded for replay.

Inputs set or forced, events posted and the clicks of a person at a GUI are
each an :class:`~.records.Action` with the control step it was applied at;
a replay applies them again at the same steps (:meth:`Inputs.apply`).
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from typing import Any

from ..app.game_outcome import GameError
from ..app.precision import PrecisionError, Staircase, StaircaseSpec
from ..app.robot import Robot, RobotError
from ..runtime import Data, UnknownEventError
from .errors import DebugError
from .history import History
from .names import RobotNames, datum_decl, parse_input_value
from .records import Action
from .replay import game_of

#: Events posted to one chart and not yet handled, at most: the chart handles them at its next tick, one
#: wake-up each, so a paused session that is posted to without end would hold them all (and every replay
#: fingerprint a copy).  One more is refused until the chart ticks.
MAX_PENDING_EVENTS = 100
#: Inputs recorded for replay, at most, since power-on (or the last new game): a replay applies every one
#: again.  Past it an input is refused; a replay to an earlier tick drops those after it.
MAX_ACTIONS = 10_000


class Inputs:
    """The inputs set, forced and released, the events posted and a GUI person's clicks, as :class:`Action`\\ s.

    ``forced``: the inputs forced now, kept against the wiring until released
    (the dict is shared with :class:`~.history.History`, whose fingerprints
    include it).  Each change forgets the fingerprints after its step: that
    future is no longer what the session saw.
    """

    def __init__(self, robot: Callable[[], Robot], names: RobotNames, history: History,
                 forced: dict[tuple[str, str], Any]) -> None:
        self._robot = robot
        self._names = names
        self._history = history
        #: What the user did, in order: a replay applies them again at their control steps.
        self.actions: list[Action] = []
        #: Inputs given after the control step a replay went back to, in order: applied again when
        #: the run reaches their steps (:meth:`apply_due`), so going back keeps the future you gave.
        self.ahead: deque[Action] = deque()
        self.forced = forced

    def datum_decl(self, chart: str, name: str) -> Data:
        """The declaration of a chart datum (name, unit, default, doc, kind)."""
        return datum_decl(self._robot(), chart, name)

    def parse_value(self, chart: str, name: str, text: str) -> Any:
        """A value typed for a chart input, by its declared unit (see :func:`.names.parse_input_value`)."""
        return parse_input_value(self.datum_decl(chart, name), f"{chart}.{name}", text)

    def set_input(self, chart: str, name: str, value: Any, force: bool = False) -> Any:
        """Set a chart input (``force``: keep it against the wiring until :meth:`release`).

        A string is parsed by :meth:`parse_value`.  Returns the value set.
        """
        if isinstance(value, str):
            value = self.parse_value(chart, name, value)
        limits = self.datum_decl(chart, name).limits
        if limits is not None and not (isinstance(value, (int, float)) and limits[0] <= value <= limits[1]):
            raise DebugError(f"{chart}.{name} takes {limits[0]:g} to {limits[1]:g}, not {value!r}: the chart"
                             " could not draw there (it would wait for a move that never ends)")
        self._do(Action(self._robot().steps, "force" if force else "set", chart, name, value))
        return value

    def release(self, chart: str | None = None, name: str | None = None) -> list[tuple[str, str]]:
        """Stop forcing one input, or every forced input (no arguments); returns those released."""
        if chart is None:
            keys = list(self.forced)
        else:
            if name is None or (chart, name) not in self.forced:
                forced = ", ".join(f"{c}.{n}" for c, n in self.forced) or "none"
                raise DebugError(f"{chart}.{name} is not forced; forced: {forced}")
            keys = [(chart, name)]
        for c, n in keys:
            self._do(Action(self._robot().steps, "release", c, n))
        return keys

    def post(self, chart: str, event: str, /, **data: Any) -> None:
        """Post an event to a chart; it is handled at the chart's next tick (at most
        :data:`MAX_PENDING_EVENTS` wait for it)."""
        target = self._robot().charts.get(chart)
        waiting = target.pending_events if target is not None else []
        if len(waiting) >= MAX_PENDING_EVENTS:
            raise DebugError(f"post: {chart} has {len(waiting)} events waiting for its next chart tick already, the"
                             f" most it holds; step or run so it handles them, then post again")
        self._do(Action(self._robot().steps, "post", chart, event, data=dict(data)))

    def game_input(self, name: str, **data: Any) -> None:
        """An input of the person at a GUI (``cell`` row= column=, ``play``, ``symbol`` symbol=, ``engine``
        engine=; :meth:`GameSession.person_input`), recorded with its control step like a posted event,
        so a replay repeats the person's clicks where they happened.  A refused one (not the person's
        turn, a locked symbol) raises :class:`DebugError` and is not recorded."""
        self._do(Action(self._robot().steps, "game", "Game", name, data=dict(data)))

    def staircase(self, axis: str, steps: str) -> Staircase:
        """Play the staircase of thesis section 3.5 along ``axis`` with ``steps`` ("small" or "big") stairs
        from the Control chart's pose, and back there (:class:`~ttt_sm.app.precision.Staircase`), recorded
        so a replay plays it again at the same control step.  Returns it, to be measured once played."""
        return self._do(Action(self._robot().steps, "staircase", "Control", axis, data={"steps": steps}))

    def apply(self, action: Action) -> Any:
        """Do what ``action`` says to the robot now (a replay: at the control step it was recorded at).

        Returns the :class:`~ttt_sm.app.precision.Staircase` a ``staircase`` action started, else None."""
        robot = self._robot()
        if action.kind == "staircase":
            try:
                staircase = Staircase(robot, StaircaseSpec.of(action.name, action.data["steps"]),
                                      robot.params.tuning.preset)
            except PrecisionError as exc:
                raise DebugError(f"staircase: {exc}") from None
            staircase.start(back=True)
            return staircase
        if action.kind == "game":
            game = game_of(robot)
            if game is None:
                raise DebugError("this robot plays no game: build it with the game (ttt-sm gui --game)")
            try:
                game.person_input(action.name, **action.data)
            except GameError as exc:
                raise DebugError(str(exc)) from None
            return
        try:
            if action.kind in ("set", "force"):
                robot.set_input(action.chart, action.name, action.value, force=action.kind == "force")
                if action.kind == "force":
                    self.forced[(action.chart, action.name)] = action.value
            elif action.kind == "release":
                robot.release(action.chart, action.name)
                self.forced.pop((action.chart, action.name), None)
            else:
                robot.post(action.chart, action.name, **action.data)
        except (RobotError, UnknownEventError) as exc:
            raise DebugError(str(exc)) from None

    def apply_due(self, steps: int) -> None:
        """Apply the inputs :attr:`ahead` whose control step is ``steps`` (or earlier), and record them."""
        ahead = self.ahead
        while ahead and ahead[0].steps <= steps:
            action = ahead.popleft()
            self.apply(action)
            self.actions.append(action)
        self._names.forget()

    def _do(self, action: Action) -> Any:
        """Apply an action and record it (a refused one raises and is not recorded); what it returned."""
        if len(self.actions) >= MAX_ACTIONS:
            raise DebugError(f"{action.kind}: this run has recorded {len(self.actions)} inputs, the most a replay"
                             " repeats; replay to an earlier tick (it drops the inputs after it) or start the"
                             " session again")
        done = self.apply(action)
        self.actions.append(action)
        # The future after this step is no longer what the session saw.
        self._history.forget_after(action.steps)
        self._history.remember()
        # Conditions keep their last checked value: one the user just made true
        # hits at the next chart tick.
        self._names.forget()
        return done
