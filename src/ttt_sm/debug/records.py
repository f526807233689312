"""What the debugger hands back: why it stopped, and what the user did (for replay)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

from ..runtime.listeners import TraceRecord
from .breakpoints import Hit

StopKind = Literal["breakpoint", "timeout", "paused", "transition", "done", "game"]


@dataclass(frozen=True)
class Action:
    """Something the user did to the robot, at control step ``steps``, for replay."""

    steps: int
    kind: Literal["set", "force", "release", "post", "game", "staircase"]
    chart: str
    name: str  # input name, event name for "post", the person's input for "game" (cell, play, symbol, engine),
    #            the axis for "staircase" (its data: steps)
    value: Any = None
    data: dict[str, Any] = field(default_factory=dict)

    def describe(self) -> str:
        where = f"step {self.steps}"
        if self.kind == "post":
            args = "".join(f" {k}={v}" for k, v in self.data.items())
            return f"{where}: post {self.chart} {self.name}{args}"
        if self.kind == "game":
            args = "".join(f" {k}={v}" for k, v in self.data.items())
            return f"{where}: the person's {self.name}{args}"
        if self.kind == "staircase":
            return f"{where}: the staircase of section 3.5 along {self.name}, {self.data.get('steps')} steps"
        if self.kind == "release":
            return f"{where}: release {self.chart}.{self.name}"
        return f"{where}: {self.kind} {self.chart}.{self.name} {self.value!r}"


@dataclass(frozen=True)
class StopReason:
    """Why the debugger stopped, and where.

    ``kind``: ``breakpoint`` (``hits`` says which), ``timeout`` (the simulated
    time given ran out), ``paused`` (:meth:`Debugger.pause` or Ctrl-C),
    ``transition`` (``next`` saw one), ``done`` (``step``/``tick`` did what
    was asked), ``game`` (the game around the charts could not go on:
    ``detail`` says why).  ``transitions`` are the transitions taken during
    the command.
    """

    kind: StopKind
    t: float
    steps: int
    chart_ticks: int
    hits: tuple[Hit, ...] = ()
    transitions: tuple[TraceRecord, ...] = ()
    detail: str = ""

    @property
    def breakpoint(self) -> Hit | None:
        """The first breakpoint hit, if it stopped on one."""
        return self.hits[0] if self.hits else None

    def describe(self) -> str:
        where = f"t = {self.t:.3f} s, step {self.steps}, chart tick {self.chart_ticks}"
        if self.kind == "breakpoint":
            return f"stopped at {where}: " + "; ".join(h.describe() for h in self.hits)
        if self.kind == "game":
            return f"the game stopped at {where}: {self.detail}"
        text = {"timeout": "time is up", "paused": "paused", "transition": "transition",
                "done": "done"}[self.kind]
        return f"{text} at {where}"


@dataclass(frozen=True)
class DataChange:
    """A chart datum that changed: its value ``before`` the last chart tick and ``after`` (now)."""

    chart: str
    name: str
    kind: str
    unit: str
    before: Any
    after: Any


@dataclass(frozen=True)
class DataDiff:
    """What changed in the charts' data since just before chart tick ``tick`` (the last one run).

    ``changes`` lists the data whose value differs, chart by chart in the
    robot's order, each chart's data in declaration order.  Inputs the user
    set after the tick count as changed too: the diff is between the data
    before the tick and the data now.
    """

    tick: int
    changes: tuple[DataChange, ...]
