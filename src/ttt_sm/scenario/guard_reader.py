"""A chart's guards read as conditions: which inputs they test, and values that make them hold or not.

The scenario generator (:mod:`.generate`) needs, for every transition, the
inputs that decide it and values to give them.  It reads each guard into the
syntax tree of the condition language (:mod:`ttt_sm.runtime.conditions`, the
tuples ``("compare", ops, operands)``, ``("and", items)`` ...):

- a guard written as text (``cond="travel >= max_travel"``,
  ``"o_pos != o_pos_used or hold"``) is parsed by the condition parser itself;
  a name in it that is a guard method is read as that method;
- a guard method (``stalled``, ``arrived``) is read from its Python source:
  its ``return`` expressions, its ``if ...: return`` branches (an ``("ifexp",
  test, then, else)`` node, the one node the condition language lacks), and
  its local names replaced by what was assigned to them;
- what cannot be read so (a temporal operator ``after(n)``, a loop) is an
  ``("opaque", text, clock)`` node: the generator treats it as "either value"
  and lets the chart's own run decide.

:func:`atoms` lists the comparisons and boolean data a tree tests;
:func:`settings_for` finds input values at a comparison's boundary (``x >=
limit``: ``limit`` and just below it; ``abs(x - c) < tol``: ``c`` and
``c + tol``); :func:`kleene` evaluates a tree with some atoms fixed and the
rest unknown (the truth tables of ``and``, ``or``, ``not``).
"""

from __future__ import annotations

import ast
import inspect
import math
import operator
import textwrap
from collections.abc import Callable, Container, Mapping
from dataclasses import dataclass
from typing import Any

from ..runtime import TickChart
from ..runtime.conditions import ExprError, Ref, parse
from ..runtime.temporal import duration_of, temporal_of

Node = Any  # a tuple of the condition language's tree, or ("ifexp", t, a, b) / ("opaque", text, clock)

#: How deep a guard method may call another before the reader gives up (an ``opaque`` node).
MAX_INLINE = 4
_CMP_AST = {ast.Eq: "==", ast.NotEq: "!=", ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">="}
_ARITH_AST = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/"}
_CMP = {"==": operator.eq, "!=": operator.ne, "<": operator.lt, "<=": operator.le,
        ">": operator.gt, ">=": operator.ge}
_FUNCTIONS: dict[str, Callable[..., Any]] = {"abs": abs, "min": min, "max": max}
_ARITH = {"+": operator.add, "-": operator.sub, "*": operator.mul, "/": operator.truediv}


class Unknown(Exception):
    """A value the reader cannot compute (an opaque node, a missing datum)."""


def opaque(text: str, clock: bool = False) -> Node:
    """A part of a guard that is not read: either value is possible (``clock``: it counts time)."""
    return ("opaque", text, clock)


class GuardReader:
    """Reads the guards and actions of one chart class into condition trees."""

    def __init__(self, cls: type[TickChart]) -> None:
        self.cls = cls
        self.data = {d.name: d for d in cls.declarations()}
        self.inputs = {d.name for d in cls.declarations() if d.kind == "input"}
        self._methods: dict[str, Node] = {}

    # -- guards -------------------------------------------------------------------------

    def guard(self, transition: Any) -> Node:
        """The tree of all guards of a python-statemachine transition (``and`` of them), or ``("const", True)``."""
        parts = []
        for spec in transition.cond:
            func = getattr(spec, "func", None)
            if temporal_of(func) is not None or duration_of(func) is not None:
                node = opaque(str(spec), clock=True)
            elif isinstance(func, str) and func.isidentifier():
                node = self.name(func, 0)
            elif isinstance(func, str):
                node = self.text(func, 0)
            else:
                node = opaque(str(spec))
            parts.append(("not", node) if spec.expected_value is False else node)
        if not parts:
            return ("const", True)
        return parts[0] if len(parts) == 1 else ("and", tuple(parts))

    def text(self, text: str, depth: int) -> Node:
        """A guard written as text, parsed by the condition language; its names resolved."""
        try:
            tree = parse(text).tree
        except ExprError:
            return opaque(text)
        return self._resolve(tree, depth)

    def _resolve(self, node: Node, depth: int) -> Node:
        kind = node[0]
        if kind == "ref":
            ref: Ref = node[1]
            return self.name(ref.name, depth) if ref.chart is None and ref.index is None else opaque(str(ref))
        if kind in ("and", "or"):
            return (kind, tuple(self._resolve(n, depth) for n in node[1]))
        if kind in ("not", "neg"):
            return (kind, self._resolve(node[1], depth))
        if kind == "arith":
            return ("arith", node[1], self._resolve(node[2], depth), self._resolve(node[3], depth))
        if kind == "compare":
            return _pairs(node[1], [self._resolve(n, depth) for n in node[2]])
        if kind == "call":
            return ("call", node[1], tuple(self._resolve(n, depth) for n in node[2]))
        return node

    def name(self, name: str, depth: int) -> Node:
        """A name in a guard: a datum, a constant of the class, or a guard method read from its source."""
        if name in self.data:
            return ("ref", Ref(None, name))
        static = inspect.getattr_static(self.cls, name, None)
        if isinstance(static, bool | int | float):
            return ("const", static)
        if isinstance(static, property) and static.fget is not None:
            return self.method(static.fget, depth)
        if callable(static):
            return self.method(static, depth)
        return opaque(name)

    def method(self, func: Callable[..., Any], depth: int) -> Node:
        """A guard method read from its source: what it returns, as a tree."""
        key = getattr(func, "__qualname__", repr(func))
        if key in self._methods:
            return self._methods[key]
        if depth >= MAX_INLINE:
            return opaque(key)
        tree = _function_ast(func)
        node = opaque(key) if tree is None else _Body(self, depth + 1).block(tree.body, {})
        self._methods[key] = node
        return node

    # -- actions ---------------------------------------------------------------------------

    def action_atoms(self, func: Callable[..., Any]) -> list[Node]:
        """The comparisons an action makes (``still_1 = ... if c1 > moving and ...``): inputs that
        change what the action does, so the generator tries their boundary values too."""
        tree = _function_ast(func)
        if tree is None:
            return []
        body = _Body(self, 1)
        env: dict[str, Node] = {}
        found: list[Node] = []
        for stmt in tree.body:
            body.assign(stmt, env)
            for sub in ast.walk(stmt):
                if isinstance(sub, ast.Compare):
                    found.extend(atoms(body.expr(sub, env)))
        return found


def _function_ast(func: Callable[..., Any]) -> ast.FunctionDef | None:
    try:
        source = textwrap.dedent(inspect.getsource(func))
    except (OSError, TypeError):
        return None
    try:
        module = ast.parse(source)
    except SyntaxError:
        return None
    first = module.body[0] if module.body else None
    return first if isinstance(first, ast.FunctionDef) else None


def _pairs(ops: tuple[str, ...], operands: list[Node]) -> Node:
    """A chained comparison ``a <= q <= b`` as ``a <= q and q <= b``."""
    pairs = tuple(("compare", (op,), (operands[k], operands[k + 1])) for k, op in enumerate(ops))
    return pairs[0] if len(pairs) == 1 else ("and", pairs)


class _Body:
    """Python statements and expressions of one method, to condition trees."""

    def __init__(self, reader: GuardReader, depth: int) -> None:
        self.reader = reader
        self.depth = depth

    def block(self, stmts: list[ast.stmt], env: dict[str, Node]) -> Node:
        env = dict(env)
        for k, stmt in enumerate(stmts):
            if isinstance(stmt, ast.Return):
                return self.expr(stmt.value, env) if stmt.value is not None else ("const", None)
            if isinstance(stmt, ast.If):
                rest = stmts[k + 1:]
                then = self.block(stmt.body + rest, env)
                other = self.block(stmt.orelse + rest, env)
                return ("ifexp", self.expr(stmt.test, env), then, other)
            if isinstance(stmt, ast.Expr) and isinstance(stmt.value, ast.Constant):
                continue  # the docstring
            if not self.assign(stmt, env):
                return opaque(ast.unparse(stmt).splitlines()[0])
        return ("const", None)

    def assign(self, stmt: ast.stmt, env: dict[str, Node]) -> bool:
        """Remember ``name = expr`` (and ``a, b = x, y``); False for another kind of statement."""
        if isinstance(stmt, ast.AnnAssign) and isinstance(stmt.target, ast.Name) and stmt.value is not None:
            env[stmt.target.id] = self.expr(stmt.value, env)
            return True
        if not isinstance(stmt, ast.Assign):
            return False
        for target in stmt.targets:
            if isinstance(target, ast.Name):
                env[target.id] = self.expr(stmt.value, env)
            elif (isinstance(target, ast.Tuple) and isinstance(stmt.value, ast.Tuple)
                  and len(target.elts) == len(stmt.value.elts)):
                for t, v in zip(target.elts, stmt.value.elts, strict=True):
                    if isinstance(t, ast.Name):
                        env[t.id] = self.expr(v, env)
        return True

    def expr(self, node: ast.expr, env: Mapping[str, Node]) -> Node:  # noqa: PLR0911 - one case per kind
        if isinstance(node, ast.Constant):
            return ("const", node.value)
        if isinstance(node, ast.BoolOp):
            return ("and" if isinstance(node.op, ast.And) else "or", tuple(self.expr(v, env) for v in node.values))
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.Not):
            return ("not", self.expr(node.operand, env))
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
            return ("neg", self.expr(node.operand, env))
        if isinstance(node, ast.BinOp) and type(node.op) in _ARITH_AST:
            return ("arith", _ARITH_AST[type(node.op)], self.expr(node.left, env), self.expr(node.right, env))
        if isinstance(node, ast.Compare) and all(type(op) in _CMP_AST for op in node.ops):
            ops = tuple(_CMP_AST[type(op)] for op in node.ops)
            return _pairs(ops, [self.expr(n, env) for n in (node.left, *node.comparators)])
        if isinstance(node, ast.IfExp):
            return ("ifexp", self.expr(node.test, env), self.expr(node.body, env), self.expr(node.orelse, env))
        if isinstance(node, ast.Name):
            if node.id in env:
                return env[node.id]
            if node.id in ("True", "False", "None"):
                return ("const", {"True": True, "False": False, "None": None}[node.id])
            return opaque(node.id)
        if _is_self_attr(node):
            assert isinstance(node, ast.Attribute)
            return self.reader.name(node.attr, self.depth)
        if isinstance(node, ast.Subscript) and isinstance(node.slice, ast.Constant) \
                and isinstance(node.slice.value, str) and node.slice.value in self.reader.data:
            return ("ref", Ref(None, node.slice.value))  # d["name"]: the chart's data mapping
        if isinstance(node, ast.Call):
            return self.call(node, env)
        return opaque(ast.unparse(node))

    def call(self, node: ast.Call, env: Mapping[str, Node]) -> Node:
        func = node.func
        if isinstance(func, ast.Name) and func.id in ("abs", "min", "max") and node.args and not node.keywords:
            return ("call", func.id, tuple(self.expr(a, env) for a in node.args))
        if isinstance(func, ast.Name) and func.id == "bool" and len(node.args) == 1:
            return self.expr(node.args[0], env)
        if _is_self_attr(func) and not node.args and not node.keywords:
            assert isinstance(func, ast.Attribute)
            return self.reader.name(func.attr, self.depth)
        return opaque(ast.unparse(node))


def _is_self_attr(node: ast.expr) -> bool:
    return isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "self"


# -- reading a tree -----------------------------------------------------------------------

def refs(node: Node) -> set[str]:
    """The data names a tree reads."""
    if node[0] == "ref":
        return {node[1].name}
    found: set[str] = set()
    for part in node[1:]:
        if isinstance(part, tuple) and part and isinstance(part[0], str):
            found |= refs(part)
        elif isinstance(part, tuple):
            for item in part:
                if isinstance(item, tuple) and item and isinstance(item[0], str):
                    found |= refs(item)
    return found


def atoms(node: Node) -> list[Node]:
    """The leaves of a tree's logic: comparisons, data read as truth values, opaque parts."""
    kind = node[0]
    if kind in ("and", "or"):
        return [a for n in node[1] for a in atoms(n)]
    if kind == "not":
        return atoms(node[1])
    if kind == "ifexp":
        return atoms(node[1]) + atoms(node[2]) + atoms(node[3])
    if kind == "const":
        return []
    return [node]


def has_clock(node: Node) -> bool:
    """Whether a tree counts time (a temporal operator): waiting alone may change it."""
    return any(a[0] == "opaque" and a[2] for a in atoms(node))


def value(node: Node, data: Mapping[str, Any]) -> Any:
    """Evaluate a tree on data; :class:`Unknown` for an opaque part or a missing datum."""
    kind = node[0]
    if kind == "const":
        return node[1]
    if kind == "ref":
        try:
            return data[node[1].name]
        except KeyError:
            raise Unknown(node[1].name) from None
    if kind == "opaque":
        raise Unknown(node[1])
    if kind == "not":
        return not value(node[1], data)
    if kind == "neg":
        return -value(node[1], data)
    if kind == "and":
        return all(value(n, data) for n in node[1])
    if kind == "or":
        return any(value(n, data) for n in node[1])
    if kind == "arith":
        try:
            return _ARITH[node[1]](value(node[2], data), value(node[3], data))
        except (ZeroDivisionError, TypeError, OverflowError):
            raise Unknown(node[1]) from None
    if kind == "compare":
        try:
            return _CMP[node[1][0]](value(node[2][0], data), value(node[2][1], data))
        except TypeError:
            raise Unknown(node[1][0]) from None
    if kind == "call":
        func: Callable[..., Any] = _FUNCTIONS[node[1]]
        try:
            return func(*(value(n, data) for n in node[2]))
        except (TypeError, ValueError):
            raise Unknown(node[1]) from None
    if kind == "ifexp":
        return value(node[2], data) if value(node[1], data) else value(node[3], data)
    raise Unknown(kind)


def kleene(node: Node, data: Mapping[str, Any], free: Container[Node] = ()) -> bool | None:
    """A tree's truth on ``data``, the atoms in ``free`` and opaque parts unknown; None: either value."""
    if node in free:
        return None
    kind = node[0]
    if kind == "not":
        inner = kleene(node[1], data, free)
        return None if inner is None else not inner
    if kind in ("and", "or"):
        results = [kleene(n, data, free) for n in node[1]]
        decisive = kind == "or"  # an `or` is decided by a true item, an `and` by a false one
        if decisive in results:
            return decisive
        return None if None in results else not decisive
    if kind == "ifexp":
        test = kleene(node[1], data, free)
        if test is not None:
            return kleene(node[2] if test else node[3], data, free)
        a, b = kleene(node[2], data, free), kleene(node[3], data, free)
        return a if a == b else None
    try:
        return bool(value(node, data))
    except Unknown:
        return None


# -- values that make an atom hold, or not ---------------------------------------------------

@dataclass(frozen=True)
class Setting:
    """Input values that give an atom a truth value, and why (for the generated file's comments)."""

    values: tuple[tuple[str, Any], ...]
    why: str


def _invert(node: Node, target: float, x: str, data: Mapping[str, Any]) -> list[float]:
    """Values of input ``x`` for which ``node`` equals ``target`` (the other names as in ``data``)."""
    kind = node[0]
    if kind == "ref":
        return [target] if node[1].name == x else []
    if kind == "neg":
        return _invert(node[1], -target, x, data)
    if kind == "call" and node[1] == "abs" and len(node[2]) == 1:
        return _invert(node[2][0], target, x, data) + _invert(node[2][0], -target, x, data)
    if kind == "ifexp":
        try:
            branch = node[2] if value(node[1], data) else node[3]
        except Unknown:
            return []
        return _invert(branch, target, x, data)
    if kind != "arith":
        return []
    op, left, right = node[1], node[2], node[3]
    in_left = x in refs(left)
    try:
        other = value(right if in_left else left, data)
        if op == "+":
            return _invert(left if in_left else right, target - other, x, data)
        if op == "-":
            return _invert(left, target + other, x, data) if in_left else _invert(right, other - target, x, data)
        if op == "*" and other:
            return _invert(left if in_left else right, target / other, x, data)
        if op == "/":
            return _invert(left, target * other, x, data) if in_left else (
                _invert(right, other / target, x, data) if target else [])
    except (Unknown, TypeError, ZeroDivisionError):
        return []
    return []


def _candidates(atom: Node, x: str, datum: Any, data: Mapping[str, Any]) -> list[Any]:
    """Values of input ``x`` at the atom's boundary: on it and just either side of it."""
    default = datum.default
    if isinstance(default, bool):
        return [True, False]
    if atom[0] != "compare":
        return []
    left, right = atom[2]
    side, other = (left, right) if x in refs(left) else (right, left)
    try:
        target = value(other, data)
    except Unknown:
        return []
    if isinstance(target, str):
        return [target, target + "?"] if isinstance(default, str) else []
    if isinstance(target, bool) or not isinstance(target, int | float) or not math.isfinite(target):
        return []
    found: list[Any] = []
    for b in _invert(side, target, x, data):
        near: list[Any]
        if isinstance(default, int):
            whole = round(b)
            near = [whole, whole - 1, whole + 1]
        else:
            eps = max(abs(b), 1.0) * 1e-6
            near = [b, b - eps, b + eps]
        found.extend(v for v in near if v not in found)
    return found


def settings_for(atom: Node, reader: GuardReader, data: Mapping[str, Any]) -> dict[bool, Setting]:
    """For an atom that reads an input: the values that make it true, and false (as near its boundary
    as possible: exactly on it where that gives the truth value)."""
    names = sorted(refs(atom) & reader.inputs)
    out: dict[bool, Setting] = {}
    text = show(atom)
    for x in names:
        for v in _candidates(atom, x, reader.data[x], data):
            trial = {**data, x: v}
            try:
                truth = bool(value(atom, trial))
            except Unknown:
                continue
            if truth not in out:
                out[truth] = Setting(((x, v),), f"{x} = {show_value(v)} makes '{text}' {str(truth).lower()}")
        if len(out) == 2:
            break
    return out


def show_value(v: Any) -> str:
    """A value as a condition writes it."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return f'"{v}"'
    return repr(v)


def show(node: Node) -> str:  # noqa: PLR0911 - one case per kind
    """A tree written back as a condition (for the comments of a generated file)."""
    kind = node[0]
    if kind == "const":
        return show_value(node[1])
    if kind == "ref":
        return node[1].name
    if kind == "opaque":
        return str(node[1])
    if kind == "not":
        return f"not {show(node[1])}"
    if kind == "neg":
        return f"-{show(node[1])}"
    if kind in ("and", "or"):
        return f" {kind} ".join(f"({show(n)})" if n[0] in ("and", "or", "ifexp") else show(n) for n in node[1])
    if kind == "arith":
        left, right = (f"({show(n)})" if n[0] == "arith" else show(n) for n in node[2:4])
        return f"{left} {node[1]} {right}"
    if kind == "compare":
        return f"{show(node[2][0])} {node[1][0]} {show(node[2][1])}"
    if kind == "call":
        return f"{node[1]}({', '.join(show(n) for n in node[2])})"
    if kind == "ifexp":
        return f"{show(node[2])} if {show(node[1])} else {show(node[3])}"
    return str(node)
