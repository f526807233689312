"""Conditions over chart data and signals: a tiny, safe expression language (no ``eval``).

Conditions read like Python but can only *look*:

    DriveInit1.ini_23 == true and abs(q_true[1] + 100deg) < 0.5deg

Grammar (lowest precedence first)::

    expr    := or
    or      := and ("or" and)*
    and     := not ("and" not)*
    not     := "not" not | compare
    compare := sum (("==" | "!=" | "<" | "<=" | ">" | ">=") sum)*   # chains: 0 < x < 1
    sum     := product (("+" | "-") product)*
    product := unary (("*" | "/") unary)*
    unary   := "-" unary | atom
    atom    := NUMBER [UNIT] | TEXT | "true" | "false" | "(" expr ")"
             | FUNCTION "(" expr ("," expr)* ")"  # abs, min, max
             | NAME "." NAME                      # a chart datum or state: DriveInit1.stop
             | NAME ["[" INTEGER "]"]             # a signal: t, q_true[1]

Values are in SI units, as the charts and signals hold them; a number may
carry a unit that converts it: ``170deg`` (or ``170 deg``), ``20mm``, ``5ms``
(``rad``, ``m``, ``s`` change nothing).  Text in quotes (``"You win."`` or
``'You win.'``, no escapes) is compared with a chart's text data, such as the
game's GUI message.  Vector signals are numbered from 1,
as the thesis numbers joints and drives: ``q_true[1]`` is q1.

It is the one language of scenario files' conditions (:mod:`ttt_sm.scenario`)
and of the debugger's ``break when`` (:mod:`ttt_sm.debug.expr`), so a
condition means the same in both.

The language knows nothing about robots: names are :class:`Ref` objects that
the caller resolves (the scenario runner and the debugger bind them to a
robot's charts and signals).  :func:`parse` checks the syntax and lists the
references, so a caller can check every name before anything runs.
"""

from __future__ import annotations

import math
import operator
import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

__all__ = ["FUNCTIONS", "KEYWORDS", "MAX_CONDITION_CHARS", "MAX_DEPTH", "UNITS", "Expression", "ExprError", "Ref",
           "parse"]

#: Longest condition, characters: checked before it is read (a condition is a line or two).
MAX_CONDITION_CHARS = 2000
#: Deepest nesting of a condition (brackets, calls, ``not``, ``-``, chained operators): deeper
#: would exhaust Python's stack in the parser or the evaluator; a person writes a few levels.
MAX_DEPTH = 40


class ExprError(ValueError):
    """A condition that cannot be parsed or evaluated; ``column`` is 1-based (0: unknown)."""

    def __init__(self, message: str, text: str = "", column: int = 0) -> None:
        self.message = message
        self.text = text
        self.column = column
        where = f" at column {column}" if column else ""
        super().__init__(f"{message}{where} in {_excerpt(text, column)}" if text else message)


def _excerpt(text: str, column: int, width: int = 40) -> str:
    """``repr(text)``, or for a long text the part around ``column`` (a message stays one short line)."""
    if len(text) <= 2 * width:
        return repr(text)
    at = max(column - 1, 0)
    start, end = max(0, at - width), min(len(text), at + width)
    return ("..." if start else "") + repr(text[start:end]) + ("..." if end < len(text) else "")


@dataclass(frozen=True)
class Ref:
    """A name in a condition: ``chart.name`` (chart datum or state) or a signal ``name[index]``.

    ``index`` is as written: 1 for the first element.
    """

    chart: str | None
    name: str
    index: int | None = None
    column: int = 0

    def __str__(self) -> str:
        head = f"{self.chart}.{self.name}" if self.chart else self.name
        return head if self.index is None else f"{head}[{self.index}]"


#: Functions a condition may call: name -> (function, number of arguments or None for 1+).
FUNCTIONS: dict[str, tuple[Callable[..., Any], int | None]] = {
    "abs": (abs, 1),
    "min": (min, None),
    "max": (max, None),
}
#: Units a number may carry: factor to SI.
UNITS: dict[str, float] = {"deg": math.pi / 180, "rad": 1.0, "mm": 1e-3, "m": 1.0, "ms": 1e-3, "s": 1.0}

_NUMBER = (int, float)  # bool is an int: true + 1 is 2, as in Python


def _short(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:40] + "..."


_COMPARE = {"==": operator.eq, "!=": operator.ne, "<": operator.lt, "<=": operator.le,
            ">": operator.gt, ">=": operator.ge}
_ARITH = {"+": operator.add, "-": operator.sub, "*": operator.mul, "/": operator.truediv}
#: Words of the language itself: no chart may be named so.
KEYWORDS = frozenset({"and", "or", "not", "true", "false", "True", "False"})
_TOKEN = re.compile(r"""
    (?P<space>\s+)
  | (?P<text>"[^"]*"|'[^']*')
  | (?P<number>(?:\d+\.\d*|\.\d+|\d+)(?:[eE][+-]?\d+)?)
  | (?P<name>[^\W\d]\w*)  # an identifier, as in Python
  | (?P<op>==|!=|<=|>=|<|>|\+|-|\*|/|\(|\)|\[|\]|\.|,)
""", re.VERBOSE)
_UNCLOSED = "text in quotes ends with the quote it starts with"
_HINTS = {"=": "use == to compare", "&": "use 'and'", "|": "use 'or'", "!": "use 'not' (or != to compare)",
          '"': _UNCLOSED, "'": _UNCLOSED}


@dataclass(frozen=True)
class _Tok:
    kind: str  # number, text, name, op, end
    text: str
    column: int  # 1-based


def _tokenize(text: str) -> list[_Tok]:
    tokens: list[_Tok] = []
    pos = 0
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None:
            ch = text[pos]
            hint = _HINTS.get(ch, "")
            raise ExprError(f"unexpected character {ch!r}" + (f" ({hint})" if hint else ""),
                            text, pos + 1)
        kind = m.lastgroup or ""
        if kind != "space":
            tokens.append(_Tok(kind, m.group(), pos + 1))
        pos = m.end()
    tokens.append(_Tok("end", "", len(text) + 1))
    return tokens


# -- syntax tree: small frozen nodes, evaluated or compiled to closures ----------------

Node = Any  # one of the tuples below; kept as tuples so a tree is cheap and hashable
# ("const", value) | ("ref", Ref) | ("neg", node) | ("not", node) | ("and", nodes) | ("or", nodes)
# ("arith", op, left, right) | ("compare", ops, operands) | ("call", name, args)


class _Parser:
    def __init__(self, text: str) -> None:
        self.text = text
        self.tokens = _tokenize(text)
        self.pos = 0
        self.refs: list[Ref] = []
        self.depth = 0
        self.units: list[str] = []  # the units written after numbers, in order
        self.ref_units: dict[str, str] = {}  # a name compared with numbers of one unit: that unit

    @property
    def tok(self) -> _Tok:
        return self.tokens[self.pos]

    def error(self, message: str, tok: _Tok | None = None) -> ExprError:
        return ExprError(message, self.text, (tok or self.tok).column)

    @property
    def found(self) -> str:
        return repr(self.tok.text) if self.tok.kind != "end" else "the end"

    def take(self, text: str) -> bool:
        if self.tok.text == text and self.tok.kind in ("op", "name"):
            self.pos += 1
            return True
        return False

    def expect(self, text: str, what: str) -> None:
        if not self.take(text):
            raise self.error(f"expected {what}, found {self.found}")

    def parse(self) -> Node:
        if self.tok.kind == "end":
            raise self.error("empty condition")
        node = self.parse_or()
        if self.tok.kind != "end":
            raise self.error(f"unexpected {self.tok.text!r}; expected 'and', 'or', an operator or the end")
        return node

    def deeper(self) -> None:
        """One more level of nesting; an error past :data:`MAX_DEPTH` (the stack is finite)."""
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise self.error(f"nested deeper than {MAX_DEPTH} levels")

    def parse_or(self) -> Node:
        items = [self.parse_and()]
        while self.take("or"):
            items.append(self.parse_and())
        return items[0] if len(items) == 1 else ("or", tuple(items))

    def parse_and(self) -> Node:
        items = [self.parse_not()]
        while self.take("and"):
            items.append(self.parse_not())
        return items[0] if len(items) == 1 else ("and", tuple(items))

    def parse_not(self) -> Node:
        return self.parse_prefix("not", "not", self.parse_compare)

    def parse_compare(self) -> Node:
        refs0, units0 = len(self.refs), len(self.units)
        operands = [self.parse_sum()]
        ops: list[str] = []
        while self.tok.kind == "op" and self.tok.text in _COMPARE:
            ops.append(self.tok.text)
            self.pos += 1
            operands.append(self.parse_sum())
        written = set(self.units[units0:])
        if ops and len(written) == 1:  # q_true[1] > 175deg: q_true[1] is read in degrees
            unit = written.pop()
            for ref in self.refs[refs0:]:
                self.ref_units.setdefault(str(ref), unit)
        return operands[0] if not ops else ("compare", tuple(ops), tuple(operands))

    def parse_sum(self) -> Node:
        return self.parse_arith(("+", "-"), self.parse_product)

    def parse_product(self) -> Node:
        return self.parse_arith(("*", "/"), self.parse_unary)

    def parse_arith(self, ops: tuple[str, str], operand: Callable[[], Node]) -> Node:
        """A chain of `operand` joined by `ops` (one precedence level), nested to the left."""
        node = operand()
        levels = 0  # a chain a + b + c nests to the left: each operator is a level of the tree
        while self.tok.kind == "op" and self.tok.text in ops:
            op = self.tok.text
            self.pos += 1
            self.deeper()
            levels += 1
            node = ("arith", op, node, operand())
        self.depth -= levels
        return node

    def parse_unary(self) -> Node:
        return self.parse_prefix("-", "neg", self.parse_atom)

    def parse_prefix(self, token: str, node_kind: str, operand: Callable[[], Node]) -> Node:
        """`operand` after any number of prefix `token` (``not not a``), each a ``node_kind`` node."""
        if not self.take(token):
            return operand()
        self.deeper()
        node = (node_kind, self.parse_prefix(token, node_kind, operand))
        self.depth -= 1
        return node

    def parse_atom(self) -> Node:
        tok = self.tok
        if tok.kind == "number":
            self.pos += 1
            value: float = float(tok.text) if any(c in tok.text for c in ".eE") else int(tok.text)
            unit = self.tok
            if unit.kind == "name" and unit.text in UNITS:
                self.pos += 1
                try:
                    value = value * UNITS[unit.text]
                except OverflowError:  # a whole number beyond any float, with a unit that makes it one
                    raise self.error(f"a number of {len(tok.text)} digits in {unit.text} is too large", tok) from None
                self.units.append(unit.text)
            elif unit.kind == "name" and unit.text not in KEYWORDS:
                raise self.error(f"unknown unit {unit.text!r}; units: {', '.join(UNITS)}", unit)
            return ("const", value)
        if tok.kind == "text":
            self.pos += 1
            return ("const", tok.text[1:-1])
        if self.take("("):
            self.deeper()
            node = self.parse_or()
            self.expect(")", "')'")
            self.depth -= 1
            return node
        if tok.kind != "name":
            raise self.error(f"expected a number, a name or '(', found {self.found}")
        self.pos += 1
        if tok.text in ("true", "True"):
            return ("const", True)
        if tok.text in ("false", "False"):
            return ("const", False)
        if tok.text in KEYWORDS:
            raise self.error(f"{tok.text!r} needs something before it", tok)
        if self.tok.text == "(" and self.tok.kind == "op":
            return self.parse_call(tok)
        chart: str | None = None
        name = tok.text
        if self.take("."):
            if self.tok.kind != "name":
                raise self.error(f"expected a datum or state name after '{tok.text}.'")
            chart, name = tok.text, self.tok.text
            self.pos += 1
            if self.tok.text == "." and self.tok.kind == "op":
                raise self.error(f"a name has one dot at most (Chart.name): {chart}.{name} is followed by '.'")
        index: int | None = None
        if self.take("["):
            if self.tok.kind != "number" or not self.tok.text.isdigit():
                raise self.error(f"expected an element number (1, 2, ...) inside [ ], found {self.found}")
            index = int(self.tok.text)
            self.pos += 1
            self.expect("]", "']'")
        ref = Ref(chart, name, index, tok.column)
        self.refs.append(ref)
        return ("ref", ref)

    def parse_call(self, tok: _Tok) -> Node:
        if tok.text not in FUNCTIONS:
            raise self.error(f"unknown function {tok.text!r}; functions: {', '.join(FUNCTIONS)}", tok)
        self.expect("(", "'('")
        self.deeper()
        args = [self.parse_or()]
        while self.take(","):
            args.append(self.parse_or())
        self.expect(")", "')' after the arguments")
        self.depth -= 1
        arity = FUNCTIONS[tok.text][1]
        if arity is not None and len(args) != arity:
            raise self.error(f"{tok.text}() takes {arity} argument(s), got {len(args)}", tok)
        if tok.text in ("min", "max") and len(args) < 2:
            raise self.error(f"{tok.text}() takes 2 or more arguments", tok)
        return ("call", tok.text, tuple(args))


def _compile(node: Node, get: Callable[[Ref], Callable[[], Any]], text: str) -> Callable[[], Any]:
    """A closure that evaluates `node`, references read through the getters from `get`."""
    kind = node[0]
    if kind == "const":
        value = node[1]
        return lambda: value
    if kind == "ref":
        return get(node[1])
    if kind == "neg":
        f = _compile(node[1], get, text)

        def neg() -> Any:
            value = f()
            if not isinstance(value, _NUMBER):
                raise ExprError(f"cannot compute '-' of {type(value).__name__} {_short(value)}", text)
            return -value
        return neg
    if kind == "not":
        f = _compile(node[1], get, text)
        return lambda: not f()
    if kind in ("and", "or"):
        fs = tuple(_compile(n, get, text) for n in node[1])
        if kind == "and":
            return lambda: all(f() for f in fs)
        return lambda: any(f() for f in fs)
    if kind == "arith":
        op = _ARITH[node[1]]
        left, right = _compile(node[2], get, text), _compile(node[3], get, text)

        def arith() -> Any:
            a, b = left(), right()
            if not (isinstance(a, _NUMBER) and isinstance(b, _NUMBER)):  # "x" * 10**9 is a memory bomb
                raise ExprError(f"cannot compute {node[1]!r} of {type(a).__name__} {_short(a)} and"
                                f" {type(b).__name__} {_short(b)}: arithmetic takes numbers", text)
            try:
                return op(a, b)
            except (ZeroDivisionError, OverflowError) as exc:
                raise ExprError(f"cannot compute {node[1]!r}: {exc}", text) from None
        return arith
    if kind == "compare":
        ops = tuple(_COMPARE[o] for o in node[1])
        fs = tuple(_compile(n, get, text) for n in node[2])

        def compare() -> bool:
            left = fs[0]()
            for op, f in zip(ops, fs[1:], strict=True):
                right = f()
                try:
                    if not op(left, right):
                        return False
                except TypeError as exc:
                    raise ExprError(f"cannot compare: {exc}", text) from None
                left = right
            return True
        return compare
    if kind == "call":
        func = FUNCTIONS[node[1]][0]
        fs = tuple(_compile(n, get, text) for n in node[2])

        def call() -> Any:
            try:
                return func(*(f() for f in fs))
            except TypeError as exc:
                raise ExprError(f"{node[1]}(): {exc}", text) from None
        return call
    raise AssertionError(f"unknown node {kind!r}")


@dataclass(frozen=True)
class Expression:
    """A parsed condition: its text, its syntax tree and the names it reads."""

    text: str
    tree: Node
    refs: tuple[Ref, ...]
    #: Each name compared with numbers written in one unit (``q_true[1] > 175deg``): that unit.
    units: tuple[tuple[str, str], ...] = ()

    def unit_of(self, ref: Ref) -> str | None:
        """The unit of the numbers ``ref`` is compared with (``deg``, ``mm`` ...), if they have one:
        a message shows the value in it (``q_true[1] = 170.002deg`` beside ``175deg``)."""
        return dict(self.units).get(str(ref))

    def bind(self, get: Callable[[Ref], Callable[[], Any]]) -> Callable[[], Any]:
        """A fast evaluator: ``get(ref)`` returns a getter per name, called once per name here.

        Use it when the same condition is evaluated on every chart step.
        """
        return _compile(self.tree, get, self.text)

    def evaluate(self, lookup: Callable[[Ref], Any]) -> Any:
        """Evaluate once, ``lookup(ref)`` giving each name's value."""
        return self.bind(lambda ref: lambda: lookup(ref))()

    def __str__(self) -> str:
        return self.text


def parse(text: str) -> Expression:
    """Parse a condition; raise :class:`ExprError` (with the column) if it is not one."""
    if not isinstance(text, str):
        shown = repr(text) if len(repr(text)) <= 60 else repr(text)[:60] + "..."
        raise ExprError(f"a condition is text, got {type(text).__name__} {shown}")
    if len(text) > MAX_CONDITION_CHARS:
        raise ExprError(f"a condition is at most {MAX_CONDITION_CHARS} characters, got {len(text)}",
                        text[:40] + "...")
    parser = _Parser(text)
    tree = parser.parse()
    return Expression(text, tree, tuple(parser.refs), tuple(parser.ref_units.items()))
