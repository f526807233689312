"""Conditions of ``break when``: a tiny expression grammar, parsed, never ``eval``-ed.

::

    condition  := or_expr
    or_expr    := and_expr ("or" and_expr)*
    and_expr   := not_expr ("and" not_expr)*
    not_expr   := "not" not_expr | comparison
    comparison := operand (("<" | "<=" | ">" | ">=" | "==" | "!=") operand)*
    operand    := "(" condition ")" | ["-"] NUMBER [unit] | "true" | "false"
                | Chart "." datum | signal ["[" INTEGER "]"]

A number may carry a unit, converted to SI: ``170deg`` (or ``170 deg``),
``20mm``, ``5ms``; ``rad``, ``m`` and ``s`` are accepted and change nothing.
A signal is one of the robot's signals (``t``, ``q_true``, ``current_a`` ...);
the joints and drives are numbered from 1 as in the thesis, so ``q_true[1]`` is
q1.  Comparisons chain as in Python (``0 < DriveInit1.pos_Encoder < 1``); an
operand alone is true when it is non-zero.  A syntax error names the token and
its column.
"""

from __future__ import annotations

import math
import operator
import re
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, Protocol

from .errors import DebugError

#: Unit suffixes of numbers: factor to SI.
UNITS: Mapping[str, float] = {
    "deg": math.pi / 180, "rad": 1.0, "mm": 1e-3, "m": 1.0, "ms": 1e-3, "s": 1.0,
}
_COMPARE: Mapping[str, Callable[[Any, Any], Any]] = {
    "<": operator.lt, "<=": operator.le, ">": operator.gt, ">=": operator.ge,
    "==": operator.eq, "!=": operator.ne,
}
_KEYWORDS = frozenset({"and", "or", "not", "true", "false"})
_TOKEN = re.compile(r"""
    (?P<space>\s+)
  | (?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)
  | (?P<name>[A-Za-z_]\w*(?:\.[A-Za-z_]\w*)*)
  | (?P<op><=|>=|==|!=|<|>|\(|\)|\[|\]|-)
""", re.VERBOSE)


@dataclass(frozen=True)
class Token:
    """One token of a condition; ``col`` is 1-based."""

    kind: str  # number, name, op, end
    text: str
    col: int


def tokenize(text: str) -> list[Token]:
    """Split a condition into tokens; an unknown character raises :class:`DebugError`."""
    tokens: list[Token] = []
    pos = 0
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None:
            raise DebugError(f"unexpected character {text[pos]!r} at column {pos + 1} of {text!r}")
        kind = m.lastgroup
        assert kind is not None
        if kind != "space":
            tokens.append(Token(kind, m.group(), pos + 1))
        pos = m.end()
    tokens.append(Token("end", "", len(text) + 1))
    return tokens


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


# A compiled node: a function of the names source.
Node = Callable[[Names], Any]


@dataclass(frozen=True)
class Condition:
    """A parsed condition: ``text`` as written, the data and signals it reads.

    ``evaluate(names)`` returns a bool; a comparison of values that cannot be
    compared (a list, ``None``) raises :class:`DebugError`.
    """

    text: str
    data: tuple[tuple[str, str], ...]
    signals: tuple[tuple[str, int | None], ...]
    _root: Node

    def evaluate(self, names: Names) -> bool:
        try:
            return bool(self._root(names))
        except TypeError as exc:
            raise DebugError(f"condition {self.text!r} cannot be evaluated: {exc}") from None


class _Parser:
    def __init__(self, text: str, names: Names) -> None:
        self.text = text
        self.names = names
        self.tokens = tokenize(text)
        self.pos = 0
        self.data: list[tuple[str, str]] = []
        self.signals: list[tuple[str, int | None]] = []

    @property
    def tok(self) -> Token:
        return self.tokens[self.pos]

    def _error(self, expected: str) -> DebugError:
        tok = self.tok
        found = "the end" if tok.kind == "end" else repr(tok.text)
        return DebugError(f"expected {expected} at column {tok.col} of {self.text!r}, found {found}")

    def _accept(self, *texts: str) -> Token | None:
        tok = self.tok
        if tok.kind in ("op", "name") and tok.text in texts:
            self.pos += 1
            return tok
        return None

    def parse(self) -> Condition:
        if self.tok.kind == "end":
            raise DebugError("empty condition: write e.g. 'DriveInit1.pos_Encoder > 1.0'")
        root = self._or()
        if self.tok.kind != "end":
            raise self._error("'and', 'or' or a comparison operator")
        return Condition(self.text, tuple(self.data), tuple(self.signals), root)

    def _or(self) -> Node:
        parts = [self._and()]
        while self._accept("or"):
            parts.append(self._and())
        if len(parts) == 1:
            return parts[0]
        return lambda n: any(p(n) for p in parts)

    def _and(self) -> Node:
        parts = [self._not()]
        while self._accept("and"):
            parts.append(self._not())
        if len(parts) == 1:
            return parts[0]
        return lambda n: all(p(n) for p in parts)

    def _not(self) -> Node:
        if self._accept("not"):
            inner = self._not()
            return lambda n: not inner(n)
        return self._comparison()

    def _comparison(self) -> Node:
        operands = [self._operand()]
        ops: list[Callable[[Any, Any], Any]] = []
        while self.tok.kind == "op" and self.tok.text in _COMPARE:
            ops.append(_COMPARE[self.tok.text])
            self.pos += 1
            operands.append(self._operand())
        if not ops:
            return operands[0]

        def chain(n: Names) -> bool:
            left = operands[0](n)
            for op, right_node in zip(ops, operands[1:], strict=True):
                right = right_node(n)
                if not op(left, right):
                    return False
                left = right
            return True
        return chain

    def _operand(self) -> Node:
        tok = self.tok
        if self._accept("("):
            inner = self._or()
            if not self._accept(")"):
                raise self._error("')'")
            return inner
        if tok.kind == "op" and tok.text == "-":
            self.pos += 1
            if self.tok.kind != "number":
                raise self._error("a number after '-'")
            value = -self._number()
            return lambda n: value
        if tok.kind == "number":
            value = self._number()
            return lambda n: value
        if tok.kind == "name":
            if tok.text in ("true", "false"):
                self.pos += 1
                flag = tok.text == "true"
                return lambda n: flag
            if tok.text in _KEYWORDS:
                raise self._error("a number, a Chart.datum or a signal")
            self.pos += 1
            if "." in tok.text:
                return self._datum(tok)
            return self._signal(tok)
        raise self._error("a number, a Chart.datum or a signal")

    def _number(self) -> float:
        tok = self.tok
        self.pos += 1
        value = float(tok.text)
        unit = self.tok
        if unit.kind == "name" and unit.text in UNITS:
            self.pos += 1
            value *= UNITS[unit.text]
        elif unit.kind == "name" and unit.text not in _KEYWORDS:
            raise DebugError(f"unknown unit {unit.text!r} at column {unit.col} of {self.text!r};"
                             f" units: {', '.join(UNITS)}")
        return value

    def _datum(self, tok: Token) -> Node:
        parts = tok.text.split(".")
        if len(parts) != 2:
            raise DebugError(f"{tok.text!r} at column {tok.col}: write Chart.datum (one dot)")
        chart, name = parts
        try:
            self.names.check_datum(chart, name)
        except DebugError as exc:
            raise DebugError(f"{exc} (at column {tok.col} of {self.text!r})") from None
        self.data.append((chart, name))
        return lambda n: n.datum(chart, name)

    def _signal(self, tok: Token) -> Node:
        index: int | None = None
        if self._accept("["):
            if self.tok.kind != "number" or not self.tok.text.isdigit():
                raise self._error("an element number (1, 2, ...)")
            index = int(self.tok.text)
            self.pos += 1
            if not self._accept("]"):
                raise self._error("']'")
        try:
            self.names.check_signal(tok.text, index)
        except DebugError as exc:
            raise DebugError(f"{exc} (at column {tok.col} of {self.text!r})") from None
        self.signals.append((tok.text, index))
        name = tok.text
        return lambda n: n.signal(name, index)


def parse_condition(text: str, names: Names) -> Condition:
    """Parse a ``break when`` condition, checking every name against ``names``."""
    return _Parser(text.strip(), names).parse()

