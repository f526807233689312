"""Cost of a chart tick: the quiet fast path against the same tick through ``send()``.

Run ``python -m ttt_sm.runtime.bench`` (prints JSON), or call :func:`bench_quiet_tick`.
"""

from __future__ import annotations

import statistics
import timeit
from typing import Any

from statemachine import State, StateChart

from .chart import TickChart
from .data import Data
from .jsonable import dumps


class BenchMove(TickChart):
    """A drawing-like chart: ``run`` holds ``move``; three guards, one during action."""

    inputs = (Data("stop", "bool", False, "operator stop"),
              Data("limit", "m", 1e9, "end of the line"))
    outputs = (Data("x", "m", 0.0, "tool position"),)
    local = (Data("inc", "m", 1e-4, "step per tick"),)

    idle = State(initial=True)

    class run(State.Compound):
        move = State(initial=True)
        stalled = State()
        move.to(stalled, cond="timed_out")
        stalled.to(move, cond="stop")

    done = State()
    idle.to(run, cond="not stop")
    run.to(idle, cond="stop")
    run.to(done, cond="x >= limit")
    done.to(idle, cond="stop")

    def timed_out(self) -> bool:
        return self.x > 2 * self.limit

    def during_move(self) -> None:
        self.x = self.x_p + self.inc


class BenchMoveSend(StateChart):
    """The same chart and guards, all tick transitions under one ``tick`` event for ``send()``."""

    catch_errors_as_events = False
    idle = State(initial=True)

    class run(State.Compound):
        move = State(initial=True)
        stalled = State()
        tick = move.to(stalled, cond="timed_out") | stalled.to(move, cond="stop")

    done = State()
    tick = (idle.to(run, cond="not stop") | run.to(idle, cond="stop")
            | run.to(done, cond="x >= limit") | done.to(idle, cond="stop"))

    def __init__(self) -> None:
        self.stop = False
        self.limit = 1e9
        self.x = self.x_p = 0.0
        self.inc = 1e-4
        super().__init__()

    def timed_out(self) -> bool:
        return self.x > 2 * self.limit

    def during_move(self) -> None:
        self.x = self.x_p + self.inc


class BenchToggle(TickChart):
    """Two states that swap on every tick: every tick takes a transition."""

    a = State(initial=True)
    b = State()
    a.to(b)
    b.to(a)


def _median_us(fn: Any, number: int, repeat: int) -> float:
    runs = timeit.repeat(fn, number=number, repeat=repeat)
    return statistics.median(runs) / number * 1e6


def bench_quiet_tick(repeat: int = 21, number: int = 2000) -> dict[str, float]:
    """Median cost in microseconds of one chart tick on the fast path and through ``send()``.

    Returns
    -------
    dict
        ``chart_quiet_tick_us``: a tick with 2 active states (``run``, ``move``),
        3 guards tried, none holding, and one during action, on the fast path.
        ``chart_send_tick_us``: the same tick as ``send("tick")`` with the library
        evaluating the guards, plus the same during action.
        ``chart_transition_tick_us``: a tick that takes a transition (through ``send``).
        ``speedup``: send / quiet.
    """
    chart = BenchMove()
    chart.tick()  # idle -> run.move
    assert chart.configuration_values == {"run", "move"}
    chart.tick()  # builds the plan of this configuration
    quiet = _median_us(chart.tick, number, repeat)
    assert chart.configuration_values == {"run", "move"}

    twin = BenchMoveSend()
    twin.send("tick")
    assert twin.configuration_values == {"run", "move"}

    def send_tick() -> None:
        twin.x_p = twin.x
        twin.send("tick")
        twin.during_move()

    sent = _median_us(send_tick, max(1, number // 20), repeat)

    toggle = BenchToggle()
    moving = _median_us(toggle.tick, max(1, number // 20), repeat)
    return {
        "chart_quiet_tick_us": round(quiet, 3),
        "chart_send_tick_us": round(sent, 3),
        "chart_transition_tick_us": round(moving, 3),
        "speedup": round(sent / quiet, 1),
    }


if __name__ == "__main__":
    print(dumps(bench_quiet_tick(), indent=2))
