"""What a scenario runs on: the simulated robot, or a bare-chart scenario's charts alone.

:class:`RobotLike` is what the runner (:mod:`.runner`) needs of a robot;
:class:`~ttt_sm.app.robot.Robot` has it all.  A bare-chart scenario
(``chart: Game``) runs on :class:`ChartsOnly`: its charts alone, ticked
together at the arm's chart rate; nothing feeds their inputs, so a value set
stays until the scenario sets another.  :func:`default_robot` chooses.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any, Protocol

from ..params import ArmParams
from ..runtime import TickChart
from .model import BareCharts, Scenario


class RobotLike(Protocol):
    """What the runner needs from a robot (:class:`~ttt_sm.app.robot.Robot` has it all)."""

    params: ArmParams
    charts: dict[str, TickChart]

    @property
    def t(self) -> float: ...
    def chart(self, name: str) -> TickChart: ...
    def run_until(self, predicate: Callable[[], bool], timeout_s: float) -> bool: ...
    def set_input(self, chart: str, name: str, value: Any, force: bool = False) -> None: ...
    def release(self, chart: str, name: str) -> None: ...
    def post(self, chart: str, event: str, /, **data: Any) -> None: ...
    def value(self, chart: str, name: str) -> Any: ...
    def active(self, chart: str) -> set[str]: ...
    def signal_values(self) -> dict[str, Any]: ...


#: Builds the robot of a scenario: (scenario, params, listeners) -> robot.
RobotFactory = Callable[[Scenario, ArmParams, Sequence[object]], RobotLike]


class ChartsOnly:
    """The charts of a bare-chart scenario, ticked together: what the runner needs of a robot, no arm.

    Each chart is built with the arm's chart period (``params.control.chart_dt``)
    and ticked once per chart step, in the order the scenario lists them; ``t``
    is the chart time.  Nothing feeds their inputs: a value set stays.
    """

    def __init__(self, bare: BareCharts, params: ArmParams, listeners: Sequence[object]) -> None:
        self.params = params
        self.chart_dt = params.control.chart_dt
        self.charts: dict[str, TickChart] = {
            name: cls(tick_period_s=self.chart_dt, chart_name=name, listeners=list(listeners))
            for name, cls in bare.charts.items()
        }
        self.ticks = 0

    @property
    def t(self) -> float:
        """Chart time, s."""
        return self.ticks * self.chart_dt

    def chart(self, name: str) -> TickChart:
        return self.charts[name]

    def run_until(self, predicate: Callable[[], bool], timeout_s: float) -> bool:
        """Tick every chart until `predicate()` holds (checked after each step); False on timeout."""
        charts = tuple(self.charts.values())
        for _ in range(int(round(timeout_s / self.chart_dt))):
            for chart in charts:
                chart.tick()
            self.ticks += 1
            if predicate():
                return True
        return False

    def set_input(self, chart: str, name: str, value: Any, force: bool = False) -> None:
        self.charts[chart].set_inputs(**{name: value})

    def release(self, chart: str, name: str) -> None:
        """Nothing is forced: nothing feeds the inputs (the loader refuses ``release``)."""

    def post(self, chart: str, event: str, /, **data: Any) -> None:
        self.charts[chart].post(event, **data)

    def value(self, chart: str, name: str) -> Any:
        return getattr(self.charts[chart], name)

    def active(self, chart: str) -> set[str]:
        return set(self.charts[chart].configuration_values)

    def signal_values(self) -> dict[str, Any]:
        return {"t": self.t}


def default_robot(scenario: Scenario, params: ArmParams, listeners: Sequence[object]) -> RobotLike:
    """The simulated robot at the scenario's power-on pose; the charts alone in bare-chart mode."""
    if scenario.bare is not None:
        return ChartsOnly(scenario.bare, params, listeners)
    from ..app.robot import Robot

    q = [math.radians(v) for v in scenario.start.q_deg] if scenario.start.q_deg is not None else None
    return Robot(params, seed=scenario.seed, q_start=q, settle_s=scenario.start.settle_s,
                 listeners=listeners)
