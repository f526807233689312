"""Stateflow's temporal logic: ``after``, ``before``, ``at``, ``every``, ``duration``, ``temporal_count``.

Each operator counts from the moment its *state* was last entered: the source
state of the transition that uses it (for a segment leaving a junction, the
state the junction sits in), or the state of an ``action_on`` state action.
What it counts is its unit:

* ``"tick"`` (the default): chart ticks, i.e. time steps of the chart.  A state
  entered during tick ``k`` has a count of ``n`` at tick ``k + n``; a chart's
  initial states count as entered at tick 0.  Wake-ups on events between
  ticks do not count (docs/runtime.md, "Temporal logic").
* ``"sec"``, ``"msec"``, ``"usec"``: chart time (ticks times the tick period),
  never wall time, so a simulation faster than real time behaves the same.
  An amount of time is turned into the first whole tick at or after it:
  ``ceil(t / tick_period_s)``.
* any other name: an event.  ``after(3, "E")`` counts the wake-ups on event
  ``E`` while the state is active, the current one included, and is tried
  only on wake-ups by ``E`` (Stateflow's event-based temporal logic).

With a count ``c`` and an amount ``n``: ``after`` holds when ``c >= n``,
``before`` when ``c < n``, ``at`` when ``c == n``, ``every`` when ``c`` is a
positive multiple of ``n``.  ``after_s(t)`` is ``after(t, "sec")``, kept
for the charts written before the units.

``duration("x > 0") >= 2.0`` holds once the condition has been true without
a break for 2 seconds of chart time while the state is active (the runtime
samples the condition at every wake-up); ``self.temporal_count(unit)`` reads
a count in an action or a guard method.

Use them as guards, alone or with others::

    searching.to(stalled, cond=[after(0.5, "sec"), "encoder_still"])
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

from .errors import TemporalLogicError


class TickCounter(Protocol):
    """What a temporal guard reads of its chart; :class:`~.chart.TickChart` is one.

    Declared here, not imported from :mod:`.chart`, so the clock's guards do
    not depend on the chart that uses them (no import circle).
    """

    tick_period_s: float | None

    def temporal_holds(self, spec: Temporal, state: Any) -> bool:
        """Whether `spec` holds for `state` now."""
        ...


#: Relative slack when turning seconds into ticks, so 0.3 s at 0.1 s per tick is 3 ticks, not 4.
_EPS = 1e-9
#: Units of time and their length in seconds; "tick" counts chart ticks.
TIME_UNITS = {"sec": 1.0, "msec": 1e-3, "usec": 1e-6}
#: What each operator asks of a count `c` and an amount `n`.
_HOLDS: dict[str, Callable[[int, int], bool]] = {
    "after": lambda c, n: c >= n,
    "before": lambda c, n: c < n,
    "at": lambda c, n: c == n,
    "every": lambda c, n: c > 0 and c % n == 0,
}


@dataclass(frozen=True)
class Temporal:
    """One temporal operator: ``op(amount, unit)``.

    ``unit`` is ``"tick"``, ``"sec"``, ``"msec"``, ``"usec"`` or an event name.
    """

    op: str
    amount: float
    unit: str = "tick"

    @property
    def event(self) -> str | None:
        """The event this operator counts, or ``None`` for ticks and time."""
        return None if self.unit == "tick" or self.unit in TIME_UNITS else self.unit

    def ticks(self, tick_period_s: float | None, where: str = "") -> int:
        """The amount in chart ticks (an event count for an event unit)."""
        if self.unit not in TIME_UNITS:
            return int(self.amount)
        if tick_period_s is None:
            raise TemporalLogicError(
                f"{self.label}{where} needs the chart's tick period: pass"
                " tick_period_s=... to the chart or set it on the chart class"
            )
        seconds = self.amount * TIME_UNITS[self.unit]
        return max(0, math.ceil(seconds / tick_period_s - _EPS))

    def holds(self, count: int, n: int) -> bool:
        """Whether the operator holds at `count` with the amount `n` (in the count's unit)."""
        return _HOLDS[self.op](count, n)

    @property
    def label(self) -> str:
        """How diagrams write it: ``after(3)``, ``after(2, sec)``, ``every(4, E)``."""
        amount = f"{self.amount:g}"
        return f"{self.op}({amount})" if self.unit == "tick" else f"{self.op}({amount}, {self.unit})"


def _operator(op: str, n: float, unit: str, label: str | None = None) -> Callable[..., bool]:
    if isinstance(n, bool) or not isinstance(n, (int, float)) or not n >= 0 or math.isinf(n):
        raise TemporalLogicError(f"{op}(n, ...) takes a finite amount >= 0, got {n!r}")
    if not isinstance(unit, str) or not unit.isidentifier():
        raise TemporalLogicError(f"{op}({n!r}, {unit!r}): the unit is tick, sec, msec, usec or an event's name")
    if unit not in TIME_UNITS and n != int(n):
        raise TemporalLogicError(f"{op}({n!r}, {unit}): ticks and events count in whole numbers")
    if op == "every" and n <= 0:
        raise TemporalLogicError(f"every({n!r}, {unit}): the period must be > 0")
    spec = Temporal(op, float(n) if unit in TIME_UNITS else int(n), unit)
    return _temporal_guard(spec, label or spec.label)


def _temporal_guard(spec: Temporal, label: str) -> Callable[..., bool]:
    # A real function (not a callable object): python-statemachine resolves and
    # caches guards by __qualname__ and __code__, and names them in diagrams by
    # __name__, so ``after(3)`` shows as ``[after(3)]`` on the edge.
    def guard(machine: TickCounter, source: Any) -> bool:
        return machine.temporal_holds(spec, source)

    guard.__name__ = guard.__qualname__ = label
    guard.temporal = spec  # type: ignore[attr-defined]
    return guard


def after(n: float, unit: str = "tick") -> Callable[..., bool]:
    """Guard holding once the state has been active for `n` units (ticks, seconds, events).

    Parameters
    ----------
    n : int or float
        The amount: a whole number of ticks or events, or a duration in ``unit``.
    unit : str
        ``"tick"`` (default), ``"sec"``, ``"msec"``, ``"usec"``, or an event's name.
    """
    if unit == "tick" and (isinstance(n, bool) or not isinstance(n, int) or n < 0):
        raise TemporalLogicError(f"after(n) takes a whole number of ticks >= 0, got {n!r}")
    return _operator("after", n, unit)


def before(n: float, unit: str = "tick") -> Callable[..., bool]:
    """Guard holding while the state has been active for fewer than `n` units."""
    return _operator("before", n, unit)


def at(n: float, unit: str = "tick") -> Callable[..., bool]:
    """Guard holding exactly when the state has been active for `n` units."""
    return _operator("at", n, unit)


def every(n: float, unit: str = "tick") -> Callable[..., bool]:
    """Guard holding every `n` units while the state is active (at n, 2n, 3n, ...)."""
    return _operator("every", n, unit)


def after_s(t: float) -> Callable[..., bool]:
    """``after(t, "sec")``: seconds of chart time, counted as ``ceil(t / tick_period_s)`` ticks."""
    if isinstance(t, bool) or not isinstance(t, (int, float)) or not t >= 0 or math.isinf(t):
        raise TemporalLogicError(f"after_s(t) takes a finite duration in seconds >= 0, got {t!r}")
    return _operator("after", float(t), "sec", label=f"after_s({float(t):g})")


def temporal_of(func: Any) -> Temporal | None:
    """The :class:`Temporal` of a guard made by :func:`after` and its kin, else ``None``."""
    spec = getattr(func, "temporal", None)
    return spec if isinstance(spec, Temporal) else None


# -- duration ------------------------------------------------------------------------------

_COMPARE = {">=": operator.ge, ">": operator.gt, "<=": operator.le, "<": operator.lt}


@dataclass(frozen=True)
class DurationSpec:
    """``duration(condition) <op> seconds``: how long `condition` has held without a break."""

    condition: str
    op: str
    seconds: float

    @property
    def label(self) -> str:
        return f"duration({self.condition}) {self.op} {self.seconds:g}"

    def holds(self, elapsed_s: float) -> bool:
        """Whether `elapsed_s` compares so; a sum of tick periods within rounding of the bound is the bound."""
        slack = _EPS * max(1.0, self.seconds)
        if abs(elapsed_s - self.seconds) <= slack:
            elapsed_s = self.seconds
        return bool(_COMPARE[self.op](elapsed_s, self.seconds))


class duration:  # noqa: N801 - reads like Stateflow's operator
    """``duration("x > 0") >= 2.0``: a guard on how long a condition has held, in seconds of chart time.

    The condition is written in the chart's guard language (data, guard methods,
    ``and``/``or``/``not``, comparisons); the runtime samples it at every
    wake-up while the state is active, and the time restarts when it is false
    or the state is entered again.
    """

    def __init__(self, condition: str) -> None:
        if not isinstance(condition, str) or not condition.strip():
            raise TemporalLogicError(f"duration(condition) takes a condition as text, got {condition!r}")
        self.condition = condition.strip()

    def _compare(self, op: str, seconds: float) -> Callable[..., bool]:
        if isinstance(seconds, bool) or not isinstance(seconds, (int, float)) or not seconds >= 0:
            raise TemporalLogicError(f"duration({self.condition}) {op} {seconds!r}: seconds must be a number >= 0")
        spec = DurationSpec(self.condition, op, float(seconds))

        def guard(machine: Any, source: Any) -> bool:
            return bool(machine.duration_holds(spec, source))

        guard.__name__ = guard.__qualname__ = spec.label
        guard.duration = spec  # type: ignore[attr-defined]
        return guard

    def __ge__(self, seconds: float) -> Callable[..., bool]:  # type: ignore[override]
        return self._compare(">=", seconds)

    def __gt__(self, seconds: float) -> Callable[..., bool]:  # type: ignore[override]
        return self._compare(">", seconds)

    def __le__(self, seconds: float) -> Callable[..., bool]:  # type: ignore[override]
        return self._compare("<=", seconds)

    def __lt__(self, seconds: float) -> Callable[..., bool]:  # type: ignore[override]
        return self._compare("<", seconds)


def duration_of(func: Any) -> DurationSpec | None:
    """The :class:`DurationSpec` of a guard made by :class:`duration`, else ``None``."""
    spec = getattr(func, "duration", None)
    return spec if isinstance(spec, DurationSpec) else None
