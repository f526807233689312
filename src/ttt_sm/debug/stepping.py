"""Run control: the one loop that moves the robot under the debugger, and what stops it.

Every command that moves the robot forward (``step``, ``tick``, ``next``,
``run``) runs :meth:`Stepper._advance`: one control step at a time, and
after each the checks that may stop it, in this order: a breakpoint hit (the
:class:`~.breakpoints.BreakListener`'s hits during the step, then the
``when`` conditions after a chart tick), the game's flow stopped by an error,
a transition taken (``next``), the chart ticks asked for (``tick``), a pause
(:meth:`Stepper.pause`, Ctrl-C).  A replay runs the same control steps
quietly (:meth:`Stepper.fast_forward`).

A stop inside a chart tick (a junction segment taken, a local event raised,
once the chart runtime reports them) is a new breakpoint kind in
:mod:`.breakpoints` whose listener hits during the tick, as ``transition``
and ``event`` do; :meth:`Stepper._advance` reads those hits after each
control step already.  A stepping unit finer than the control step would be
a new command here, beside :meth:`Stepper.tick`.
"""

from __future__ import annotations

import math
import signal
import threading
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager

from ..app.robot import Robot
from .breakpoints import BreakpointTable
from .errors import DebugError
from .records import Action, StopKind, StopReason
from .replay import game_of
from .watch import ChartWatch

#: A long run tells :attr:`Stepper.progress` where it is every this many simulated seconds.
PROGRESS_EVERY_S = 5.0


class Stepper:
    """Runs the robot one control step at a time until something stops it.

    ``robot``: the robot now (a replay replaces it); ``breakpoints`` and
    ``watch``: what hits and what keeps the data before each chart tick;
    ``remember``: called when a command ends (the session's history keeps a
    fingerprint there).  ``max_run_s``: the longest one command may run,
    seconds of simulated time; longer is refused before a step is taken.
    """

    def __init__(self, robot: Callable[[], Robot], breakpoints: BreakpointTable, watch: ChartWatch,
                 remember: Callable[[], None], max_run_s: float) -> None:
        self._robot = robot
        self._breakpoints = breakpoints
        self._watch = watch
        self._remember = remember
        self.max_run_s = max_run_s
        #: ``progress(t, t_end)``, called every :data:`PROGRESS_EVERY_S` of simulated time while a
        #: command runs (the REPL shows it on a terminal); None: silent.
        self.progress: Callable[[float, float], None] | None = None
        self._pause = threading.Event()
        self._game_stopped = False
        #: Inputs waiting for their control step (a replay went back before them), oldest first, and
        #: what applies the due ones (:meth:`~.inputs.Inputs.apply_due`); set by the debugger.
        self.ahead: deque[Action] = deque()
        self.apply_due: Callable[[int], None] | None = None

    def note_game(self) -> None:
        """Take the game as it stands: a run stops for an error of its flow that happens from now on."""
        self._game_stopped = game_error(self._robot()) is not None

    def pause(self) -> None:
        """Ask a running :meth:`run` / :meth:`next` to stop after the current control step.

        Safe to call from another thread (a GUI's pause button).
        """
        self._pause.set()

    def step(self, n: int = 1) -> StopReason:
        """Run ``n`` control steps (fewer if a breakpoint hits)."""
        _check_count(n, "step")
        dt = self._robot().params.control.dt
        self._check_bound(n * dt, "step", f"{n} control steps ({n * dt:g} s)")
        return self._advance(n, end="done")

    def tick(self, n: int = 1) -> StopReason:
        """Run up to and through the next ``n`` chart ticks (fewer if a breakpoint hits)."""
        _check_count(n, "tick")
        control = self._robot().params.control
        seconds = n * control.chart_dt
        self._check_bound(seconds, "tick", f"{n} chart ticks ({seconds:g} s)")
        return self._advance((n + 1) * control.chart_divider, ticks=n, end="done")

    def next(self, timeout_s: float = 10.0) -> StopReason:
        """Run until some chart takes a transition, at most ``timeout_s`` simulated seconds."""
        return self._advance(self._steps_for(timeout_s, "next"), until_transition=True, end="timeout")

    def run(self, max_seconds: float = 60.0) -> StopReason:
        """Run until a breakpoint hits, ``max_seconds`` of simulated time pass, or a pause."""
        return self._advance(self._steps_for(max_seconds, "run"), end="timeout")

    def fast_forward(self, steps: int, actions: Iterable[Action], apply: Callable[[Action], None]) -> None:
        """Run the robot from where it is to control step ``steps``, applying each action at its step.

        For a replay: no breakpoint hits and the trace file gets none of these
        transitions (it has them already); the data before each chart tick is
        kept as a command keeps it.
        """
        robot = self._robot()
        divider = robot.params.control.chart_divider
        queue = deque(actions)
        listener, trace = self._breakpoints.listener, self._watch.trace
        listener.muted = True
        trace.sink = None
        try:
            while True:
                while queue and queue[0].steps == robot.steps:
                    apply(queue.popleft())
                if robot.steps >= steps:
                    break
                if robot.steps % divider == 0:
                    self._watch.keep_before_tick()
                robot.control_step()
        finally:
            listener.muted = False
            trace.sink = self._watch.trace_file

    def _steps_for(self, seconds: float, what: str) -> int:
        if not (isinstance(seconds, (int, float)) and math.isfinite(seconds) and seconds > 0):
            raise DebugError(f"{what}: the time must be a positive number of seconds, got {seconds!r}")
        self._check_bound(seconds, what, f"{seconds:g} s")
        return max(1, int(round(seconds / self._robot().params.control.dt)))

    def _check_bound(self, seconds: float, what: str, asked: str) -> None:
        if seconds > self.max_run_s * (1 + 1e-9):
            raise DebugError(f"{what}: {asked} is beyond {self.max_run_s:g} s of simulated time, the longest one"
                             f" command runs (start the debugger with --max-run SECONDS to allow more)")

    def _advance(self, max_steps: int, *, ticks: int | None = None, until_transition: bool = False,
                 end: StopKind = "timeout") -> StopReason:
        robot = self._robot()
        table = self._breakpoints
        listener = table.listener
        charts = list(robot.charts.values())
        dt = robot.params.control.dt
        divider = robot.params.control.chart_divider
        listener.hits.clear()
        self._pause.clear()
        watch = self._watch
        trace = watch.trace
        first = trace.count
        ticks_done = 0
        kind: StopKind = end
        when = table.conditions()
        watch_events = table.watch_events()
        report_every = max(1, int(round(PROGRESS_EVERY_S / dt)))
        t_end = robot.t + max_steps * dt
        game_error_now = self._game_error_now
        ahead, apply_due = self.ahead, self.apply_due
        with self._sigint_pauses():
            for done in range(1, max_steps + 1):
                if ahead and apply_due is not None and ahead[0].steps <= robot.steps:
                    apply_due(robot.steps)
                ticking = robot.steps % divider == 0
                pending = [[e for e, _ in c.pending_events] for c in charts] \
                    if ticking and watch_events else None
                mark = trace.count
                if ticking:
                    watch.keep_before_tick()
                robot.control_step()
                if ticking:
                    ticks_done += 1
                    if pending is not None:
                        for chart, events in zip(charts, pending, strict=True):
                            if events:
                                listener.events_handled(chart, events)
                    if when:
                        table.check_conditions(when, robot.chart_ticks)
                if listener.hits:
                    kind = "breakpoint"
                    break
                if ticking and game_error_now():
                    kind = "game"
                    break
                if until_transition and trace.count > mark:
                    kind = "transition"
                    break
                if ticks is not None and ticks_done >= ticks:
                    kind = "done"
                    break
                if self._pause.is_set():
                    kind = "paused"
                    break
                if self.progress is not None and done % report_every == 0:
                    self.progress(robot.t, t_end)
        self._remember()
        detail = str(game_error(robot)) if kind == "game" else ""
        return StopReason(kind, robot.t, robot.steps, robot.chart_ticks, tuple(listener.hits),
                          tuple(trace.since(first)), detail)

    def _game_error_now(self) -> bool:
        """The game's flow stopped with an error in the chart step just run (reported once)."""
        if self._game_stopped or game_error(self._robot()) is None:
            return False
        self._game_stopped = True
        return True

    @contextmanager
    def _sigint_pauses(self) -> Iterator[None]:
        """Ctrl-C pauses at the next step boundary instead of breaking a step in half."""
        if threading.current_thread() is not threading.main_thread():
            yield
            return
        try:
            previous = signal.signal(signal.SIGINT, lambda _sig, _frame: self._pause.set())
        except ValueError:
            yield
            return
        try:
            yield
        finally:
            signal.signal(signal.SIGINT, previous)


def game_error(robot: Robot) -> Exception | None:
    """Why the robot's game flow stopped before the end, if it did."""
    game = game_of(robot)
    return None if game is None or game.driver is None else game.driver.error


def _check_count(n: int, what: str) -> None:
    if not isinstance(n, int) or n < 1:
        raise DebugError(f"{what}: the count must be a whole number >= 1, got {n!r}")
