"""Stateflow temporal guards, counted in chart ticks: ``after(n)`` and ``after_s(t)``.

``after(n)`` holds once the transition's source state has been active for ``n``
chart ticks: a state entered during tick ``k`` lets ``after(n)`` fire at tick
``k + n`` (a chart's initial states are entered at tick 0, before the first tick).
``after_s(t)`` is ``after(ceil(t / tick_period_s))``: seconds of *chart time*, i.e.
ticks times the chart's tick period, never wall time, so a simulation that runs
faster than real time keeps the same behaviour.

Use them as guards, alone or with others::

    searching.to(stalled, cond=[after_s(0.5), "encoder_still"])
"""

from __future__ import annotations

import math
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

    def ticks_in(self, state: Any) -> int:
        """Chart ticks since ``state`` was entered."""
        ...

#: Relative slack when turning seconds into ticks, so 0.3 s at 0.1 s per tick is 3 ticks, not 4.
_EPS = 1e-9


@dataclass(frozen=True)
class Temporal:
    """What a temporal guard counts: ``ticks`` (an int) or ``seconds`` (a float)."""

    unit: str
    amount: float

    def ticks(self, tick_period_s: float | None, where: str = "") -> int:
        """The number of chart ticks this guard waits for."""
        if self.unit == "ticks":
            return int(self.amount)
        if tick_period_s is None:
            raise TemporalLogicError(
                f"after_s({self.amount:g}){where} needs the chart's tick period: pass"
                " tick_period_s=... to the chart or set it on the chart class"
            )
        return max(0, math.ceil(self.amount / tick_period_s - _EPS))


def _temporal_guard(spec: Temporal, label: str) -> Callable[..., bool]:
    # A real function (not a callable object): python-statemachine resolves and
    # caches guards by __qualname__ and __code__, and names them in diagrams by
    # __name__, so ``after(3)`` shows as ``[after(3)]`` on the edge.
    def guard(machine: TickCounter, source: Any) -> bool:
        return machine.ticks_in(source) >= spec.ticks(machine.tick_period_s)

    guard.__name__ = guard.__qualname__ = label
    guard.temporal = spec  # type: ignore[attr-defined]
    return guard


def after(n: int) -> Callable[..., bool]:
    """Guard holding once the source state has been active for ``n`` chart ticks.

    Parameters
    ----------
    n : int
        Number of chart ticks, ``n >= 0``.
    """
    if isinstance(n, bool) or not isinstance(n, int) or n < 0:
        raise TemporalLogicError(f"after(n) takes a whole number of ticks >= 0, got {n!r}")
    return _temporal_guard(Temporal("ticks", n), f"after({n})")


def after_s(t: float) -> Callable[..., bool]:
    """Guard holding once the source state has been active for ``t`` seconds of chart time.

    Parameters
    ----------
    t : float
        Duration in seconds, ``t >= 0``; counted as ``ceil(t / tick_period_s)`` chart ticks.
    """
    if isinstance(t, bool) or not isinstance(t, (int, float)) or not t >= 0 or math.isinf(t):
        raise TemporalLogicError(f"after_s(t) takes a finite duration in seconds >= 0, got {t!r}")
    return _temporal_guard(Temporal("seconds", float(t)), f"after_s({float(t):g})")


def temporal_of(func: Any) -> Temporal | None:
    """The :class:`Temporal` of a guard made by :func:`after` / :func:`after_s`, else ``None``."""
    spec = getattr(func, "temporal", None)
    return spec if isinstance(spec, Temporal) else None
