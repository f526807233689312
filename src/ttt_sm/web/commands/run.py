"""Run control, on every page: run, pause, step by control steps, chart ticks or transitions, the speed."""

from __future__ import annotations

from collections.abc import Callable

from ...debug.errors import DebugError
from ...debug.records import StopReason
from ..fields import MAX_COUNT, integer, number, optional, speed
from .spec import Cockpit, Reply, command

#: The wall time one command may hold the simulation thread (the session pauses it after that;
#: ``ttt_sm.web.session_thread.COMMAND_BUDGET_S`` is the same number).
COMMAND_BUDGET_S = 1.0


@command("run")
def run(session: Cockpit, cid: int) -> Reply:
    """Run until a breakpoint or a pause."""
    _refuse_after_fault(session)
    session.mode = "running"
    session.last_stop = None
    session.clock.restart()
    return {"text": "running"}


@command("pause")
def pause(session: Cockpit, cid: int) -> Reply:
    """Pause between two control steps."""
    robot = session.debugger.robot
    if session.mode == "running":
        session.mode = "paused"
        session.last_stop = {"kind": "paused", "text": f"paused at t = {robot.t:.4f} s, step {robot.steps},"
                             f" chart tick {robot.chart_ticks}", "tick": robot.chart_ticks, "hits": []}
    return {"text": "paused"}


def _refuse_after_fault(session: Cockpit) -> None:
    if session.fault is not None:
        raise ValueError(f"{session.fault} (a replay to an earlier tick, or with --lab the next save, builds it again)")


def _stepping(session: Cockpit, go: Callable[[], StopReason]) -> Reply:
    _refuse_after_fault(session)
    session.mode = "paused"
    try:
        reason = go()
    except DebugError:
        raise  # refused before a step was taken
    except Exception as exc:  # a chart raised (a ValueError too, which would read as a refusal): the arm holds
        session.robot_raised(exc)
        raise ValueError(str(session.fault)) from None
    session.note_stop(reason)
    if reason.kind == "paused":  # only the session's budget pauses a command (a page's pause waits for it)
        return {"text": f"{reason.describe()}: the most one command may hold the session is {COMMAND_BUDGET_S:g} s"
                        " of wall time; send it again to go on", "budget": True}
    return {"text": reason.describe()}


@command("step", n=optional(integer(1, MAX_COUNT), 1))
def step(session: Cockpit, cid: int, n: int) -> Reply:
    """``n`` control steps (1 ms each)."""
    return _stepping(session, lambda: session.debugger.step(n))


@command("tick", n=optional(integer(1, MAX_COUNT), 1))
def tick(session: Cockpit, cid: int, n: int) -> Reply:
    """To just after the ``n``-th chart tick from now."""
    return _stepping(session, lambda: session.debugger.tick(n))


@command("next", timeout_s=optional(number(0.001, 3600.0), 10.0))
def next_transition(session: Cockpit, cid: int, timeout_s: float) -> Reply:
    """Run to the next chart tick that takes a transition (at most ``timeout_s`` simulated seconds)."""
    return _stepping(session, lambda: session.debugger.next(timeout_s))


@command("speed", value=speed)
def set_speed(session: Cockpit, cid: int, value: float | None) -> Reply:
    """Pace the run: 0.1 .. 10 times real time, or ``"max"``: as fast as it goes."""
    session.clock.set_speed(value)
    session.speed = value
    return {"text": "as fast as it goes" if value is None else f"x{value:g}"}
