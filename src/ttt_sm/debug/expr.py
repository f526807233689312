"""Conditions of ``break when``: the runtime's condition language, read from the robot.

The language is :mod:`ttt_sm.runtime.conditions`, the one scenario files use
(parsed, never ``eval``-ed): ``q_true[1] > 90deg and not DriveInit1.stop``.
Here its names mean the debugger's robot: ``Chart.datum`` is a chart's declared
datum, a bare name is one of the robot's signals (``t``, ``q_true`` ...), whose
elements are numbered from 1 as in the thesis.  Every name is checked when the
breakpoint is added, so a typo is an error at once; an error names the column.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

from ..runtime.conditions import ExprError, Expression, Ref, parse
from .errors import DebugError


class Names(Protocol):
    """What a condition's names are checked and read against (the debugger's robot)."""

    def check_datum(self, chart: str, name: str) -> None:
        """Raise :class:`DebugError` if the chart or its datum does not exist."""

    def check_signal(self, name: str, index: int | None) -> None:
        """Raise :class:`DebugError` if the signal (or its element) does not exist."""

    def datum(self, chart: str, name: str) -> Any:
        """The datum's value now."""

    def signal(self, name: str, index: int | None) -> Any:
        """The signal's value now (``index`` is 1-based)."""


@dataclass(frozen=True)
class Condition:
    """A parsed ``break when`` condition: ``text`` as written, bound to the names it was checked against.

    ``evaluate(names)`` returns a bool; values that cannot be compared or
    computed (a list, ``None``) raise :class:`DebugError`.
    """

    text: str
    expression: Expression
    names: Names = field(repr=False)
    _evaluate: Callable[[], Any] = field(repr=False, compare=False)

    def value(self) -> Any:
        """The expression's value now (a number or a flag), as ``display`` shows it."""
        try:
            return self._evaluate()
        except ExprError as exc:
            raise DebugError(f"cannot be evaluated: {exc.message}") from None
        except TypeError as exc:
            raise DebugError(f"cannot be evaluated: {exc}") from None

    def evaluate(self, names: Names | None = None) -> bool:
        # Bound once at parse time: a condition is evaluated after every chart tick.
        evaluate = self._evaluate if names is None or names is self.names else _bind(self.expression, names)
        try:
            return bool(evaluate())
        except ExprError as exc:
            raise DebugError(f"condition {self.text!r} cannot be evaluated: {exc.message}") from None
        except TypeError as exc:
            raise DebugError(f"condition {self.text!r} cannot be evaluated: {exc}") from None


def _bind(expression: Expression, names: Names) -> Callable[[], Any]:
    def getter(ref: Ref) -> Callable[[], Any]:
        chart, name, index = ref.chart, ref.name, ref.index
        if chart is not None:
            return lambda: names.datum(chart, name)
        return lambda: names.signal(name, index)
    return expression.bind(getter)


def _check(ref: Ref, names: Names) -> None:
    if ref.chart is None:
        names.check_signal(ref.name, ref.index)
        return
    names.check_datum(ref.chart, ref.name)
    if ref.index is not None:
        raise DebugError(f"{ref.chart}.{ref.name} is a datum, not a list: write it without [{ref.index}]")


def parse_condition(text: str, names: Names) -> Condition:
    """Parse a ``break when`` condition, checking every name against ``names``."""
    text = text.strip()
    if not text:
        raise DebugError("empty condition: write e.g. 'DriveInit1.pos_Encoder > 1.0'")
    try:
        expression = parse(text)
    except ExprError as exc:
        raise DebugError(str(exc)) from None
    for ref in expression.refs:
        try:
            _check(ref, names)
        except DebugError as exc:
            raise DebugError(f"{exc} (at column {ref.column} of {text!r})") from None
    return Condition(text, expression, names, _bind(expression, names))
