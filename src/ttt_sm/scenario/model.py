"""What a scenario is once loaded: frozen steps, each with the file and line it came from.

A :class:`Catalog` says what a scenario may name: the charts (by the name the
robot knows them by), their states, data and events, and the robot's signals.
The loader checks every name against it before anything runs.  A scenario in
bare-chart mode (:class:`BareCharts`) may name only its own charts, and of the
signals only ``t``, the chart time.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

from ..runtime import TickChart
from ..runtime.conditions import Expression

#: Signals a condition may read (``Robot.signal_values()``): name -> vector length, None for a scalar.
#: SI units: seconds, radians, metres, amperes.  Elements are numbered from 1: ``q_true[1]`` is q1.
SIGNALS: dict[str, int | None] = {
    "t": None,  # simulated time since power-on, s
    "q_set": 4,  # joint setpoints sent to the drives this chart step, rad
    "q_encoder": 3,  # joint angles the controllers see (encoder + offset), rad
    "q_true": 4,  # true joint angles of the twin, rad (simulation only)
    "offset_estimate": 3,  # encoder offsets applied so far, rad
    "index": 3,  # index switch levels
    "counts": 3,  # raw encoder counts
    "current_a": 3,  # motor currents, A
    "tool_true": 4,  # true tool pose X, Y, Z (m), phi (rad) (simulation only)
    "fr_sw": None,  # setpoint filter switch (slow filter when true)
}


@dataclass(frozen=True)
class Where:
    """A place in a scenario file."""

    file: str
    line: int

    def __str__(self) -> str:
        return f"{self.file}:{self.line}"


@dataclass(frozen=True)
class ChartRef:
    """``Chart.name``: a chart datum or state, with the line it was written on."""

    chart: str
    name: str

    def __str__(self) -> str:
        return f"{self.chart}.{self.name}"


@dataclass(frozen=True)
class Step:
    """One step of a scenario; ``where`` is the line of its ``- ``."""

    where: Where

    kind = "step"


@dataclass(frozen=True)
class SetStep(Step):
    """Set chart inputs now; ``force`` holds inputs the wiring feeds until ``release``."""

    values: tuple[tuple[ChartRef, Any], ...]
    force: bool = False
    kind = "set"


@dataclass(frozen=True)
class ReleaseStep(Step):
    """Stop forcing inputs: the wiring feeds them again from the next chart step."""

    targets: tuple[ChartRef, ...]
    kind = "release"


@dataclass(frozen=True)
class PostStep(Step):
    """Post an event to a chart; it is handled at the chart's next tick."""

    chart: str
    event: str
    data: Mapping[str, Any] = field(default_factory=dict)
    kind = "post"


@dataclass(frozen=True)
class RunStep(Step):
    """Let the robot run for some seconds or some chart steps."""

    seconds: float | None = None
    chart_steps: int | None = None
    kind = "run"

    def duration_s(self, chart_dt: float) -> float:
        return self.seconds if self.seconds is not None else (self.chart_steps or 0) * chart_dt


@dataclass(frozen=True)
class RunUntilStep(Step):
    """Run until a state is entered, a state is active, or a condition holds; fail after ``timeout_s``."""

    timeout_s: float
    entered: ChartRef | None = None
    active: ChartRef | None = None
    condition: Expression | None = None
    kind = "run_until"

    @property
    def missed(self) -> str:
        """What did not happen, for a timeout message."""
        if self.entered is not None:
            return f"{self.entered.chart} did not enter {self.entered.name}"
        if self.active is not None:
            return f"{self.active} was not active"
        return f"{str(self.condition)!r} did not hold"


@dataclass(frozen=True)
class ExpectStep(Step):
    """A condition that holds now, within some seconds, or at every chart step for some seconds."""

    condition: Expression
    within_s: float | None = None
    for_s: float | None = None
    kind = "expect"


@dataclass(frozen=True)
class ExpectStatesStep(Step):
    """The states a chart entered since the start (or the last ``mark``), in order."""

    chart: str
    sequence: tuple[str, ...]
    match: Literal["subsequence", "exact"] = "subsequence"
    kind = "expect_states"


@dataclass(frozen=True)
class ExpectEventsStep(Step):
    """The local events a chart broadcast (``send`` in its actions) since the start or the last ``mark``."""

    chart: str
    sequence: tuple[str, ...]
    match: Literal["subsequence", "exact"] = "subsequence"
    kind = "expect_events"


@dataclass(frozen=True)
class MarkStep(Step):
    """Start a new window for ``expect_states``: states entered before it no longer count."""

    label: str = ""
    kind = "mark"


@dataclass(frozen=True)
class Start:
    """The power-on pose (degrees, q1..q4) and how long the unpowered arm settles first."""

    q_deg: tuple[float, ...] | None = None
    settle_s: float = 0.0
    where: Where | None = None


@dataclass(frozen=True)
class BareCharts:
    """Bare-chart mode (``chart:`` or ``charts:``): only these charts, ticked together, no robot.

    ``charts`` maps the names the steps use (a chart's class name, or one the
    scenario chose for one of several instances) to the chart classes it was
    checked against; ``where`` is the line of ``chart:`` / ``charts:``.
    """

    charts: Mapping[str, type[TickChart]]
    where: Where

    def __str__(self) -> str:
        return ", ".join(n if n == c.__name__ else f"{n} ({c.__name__})" for n, c in self.charts.items())


#: The longest a step may run unless the file raises it with ``max_step_s:``, seconds of
#: simulated time (a ``run``, a ``run_until``'s ``timeout_s``, an ``expect``'s ``within_s`` or
#: ``for_s``, the start's ``settle_s``): a typo like ``timeout_s: 1e12`` would never end.
DEFAULT_MAX_STEP_S = 600.0


@dataclass(frozen=True)
class Scenario:
    """A loaded, checked scenario file; ``bare`` is set for a bare-chart scenario."""

    name: str
    file: str
    steps: tuple[Step, ...]
    description: str = ""
    seed: int = 0
    start: Start = Start()
    where: Where | None = None
    bare: BareCharts | None = None
    #: The longest any step may run, seconds of simulated time (``max_step_s:`` raises it).
    max_step_s: float = DEFAULT_MAX_STEP_S


@dataclass(frozen=True)
class Catalog:
    """What scenarios may name: charts by name, and the robot's signals.

    ``robot_charts`` names the charts the robot holds (None: all of them); the
    others can only run bare (``chart: Game``).
    """

    charts: Mapping[str, type[TickChart]]
    signals: Mapping[str, int | None]
    robot_charts: tuple[str, ...] | None = None

    @classmethod
    def default(cls) -> Catalog:
        """The project's charts (named by class, as :class:`~ttt_sm.app.robot.Robot` names them).

        A slot a command filled (:func:`~ttt_sm.app.slots.chosen_slots`) names the class
        in it.  The robot holds the drive-initialisation charts, Control and Safety; the game's
        charts (AlgorithmActivator, Game) are added by the game session, so a
        scenario runs them bare.
        """
        from ..app.slots import chosen_slots
        from ..charts import ALL_CHARTS, INIT_CHARTS, Control, Safety

        robot = tuple(c.__name__ for c in (*INIT_CHARTS, Control, Safety))
        # a chart slot filled by a student's class (``ttt-sm --chart``) names that class
        slots = chosen_slots()
        charts = {c.__name__: (slots.cls(c.__name__) if c.__name__ in slots.chosen else c) for c in ALL_CHARTS}
        return cls(charts, SIGNALS, robot)

    def chart(self, name: str) -> type[TickChart] | None:
        return self.charts.get(name)


def chart_states(cls: type[TickChart]) -> dict[str, str]:
    """A chart's states by id: ``"leaf"``, ``"compound"``, ``"history"`` or ``"junction"``."""
    out: dict[str, str] = {}
    for s in cls.structure().states:
        out[s.id] = ("history" if s.history else "junction" if s.junction
                     else "compound" if s.is_compound else "leaf")
    return out


def chart_data(cls: type[TickChart]) -> dict[str, str]:
    """A chart's declared data by name: their kind (``input``, ``output``, ``local``)."""
    return {d.name: d.kind for d in cls.declarations()}
