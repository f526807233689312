"""What an action does, in the chart's own terms: the text the diagrams write for it.

Stateflow writes a state's actions in its box (``du: X_out = X_out_p + inc;``)
and a transition's on its edge.  A chart here says it beside the method, in one
place::

    @does("X_out = X_out_p - inc; Y_out = X_out + h1 (eqs. 3.40-3.41)")
    def during_line_1(self) -> None: ...

A method without :func:`does` is written by its own statements when they are
simple assignments and calls (``self.`` dropped, ``self.tick_period_s`` read as
``dt``): ``self.ctr = self.ctr + 1`` reads ``ctr = ctr + 1``.  Otherwise the
diagram shows the method's name.

The text is the chart's action language: statements separated by ``;``, naming
only the chart's data (an output's previous value as ``<name>_p``), the helpers
of :data:`HELPERS` and those the chart documents in its ``action_helpers``
(``{"aim(x, y, z)": "tx, ty, tz = x, y, z: the next move's target"}``), numbers,
quoted text and equation references ``(eq. 3.41)``.  :func:`unknown_names` lists
any other name (the charts' tests check every packaged chart with it).

Long texts: the picture shows ``summary`` (given, it is always shown; else the
first statement) and ``…``, and keeps the full text for the tooltip and the
cockpit's click panel.
"""

from __future__ import annotations

import ast
import inspect
import keyword
import re
import textwrap
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, TypeVar

F = TypeVar("F", bound=Callable[..., Any])

#: Attribute the text is kept in on the function :func:`does` marks.
_ATTR = "__does__"
#: A statement longer than this, or more than :data:`MAX_LINES` of them, is summarised on the picture.
MAX_CHARS = 56
MAX_LINES = 4

#: Names every chart's action texts may use, with what they mean (documented in docs/runtime.md).
HELPERS: dict[str, str] = {
    "dt": "the chart's tick period, s",
    "abs": "absolute value", "min": "smaller of", "max": "larger of", "sqrt": "square root",
    "sin": "sine", "cos": "cosine", "exp": "exponential", "pi": "π", "nan": "not a number (no value)",
    "isnan": "whether a value is NaN", "bool": "true or false", "int": "whole number",
}
_WORDS = frozenset({"and", "or", "not", "if", "else", "True", "False", "None", "in"})
_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
_QUOTED = re.compile(r"\"[^\"]*\"|'[^']*'")
_EQUATION = re.compile(r"\(eqs?\.\s*[0-9.,\s\u2013-]+\)|\(section [0-9.]+\)")


def does(text: str, summary: str | None = None) -> Callable[[F], F]:
    """Declare what the decorated action does, for the diagrams (see the module's docstring).

    The function itself is returned unchanged, with the text beside it.
    """
    if not text.strip():
        raise ValueError("does(): empty action text")

    def mark(fn: F) -> F:
        setattr(fn, _ATTR, (text.strip(), summary))
        return fn

    return mark


@dataclass(frozen=True)
class ActionText:
    """The text of one action: ``full`` (every statement), ``lines`` (as the picture writes it)."""

    name: str
    full: str
    lines: tuple[str, ...]
    declared: bool

    @property
    def short(self) -> bool:
        """Whether the picture shows the whole text."""
        return " ".join(self.lines) == " ".join(statements(self.full))


def statements(text: str) -> list[str]:
    """The statements of a text, split at ``;`` outside quotes and brackets."""
    out, depth, quote, start = [], 0, "", 0
    for i, ch in enumerate(text):
        if quote:
            quote = "" if ch == quote else quote
        elif ch in "\"'":
            quote = ch
        elif ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
        elif ch == ";" and depth == 0:
            out.append(text[start:i].strip())
            start = i + 1
    out.append(text[start:].strip())
    return [s for s in out if s]


def _picture_lines(full: str, summary: str | None) -> tuple[str, ...]:
    """The statements, one a line; a declared summary instead (``…`` after it), or the first statement
    when they are too many or too long for a picture."""
    parts = statements(full)
    if summary:
        short = statements(summary)
        return (*short[:-1], short[-1] + " …")
    if len(parts) <= MAX_LINES and all(len(p) <= MAX_CHARS for p in parts):
        return tuple(parts)
    first = parts[0]
    if len(first) > MAX_CHARS:  # cut at a word's end
        cut = first[:MAX_CHARS].rstrip()
        first = cut[:cut.rfind(" ")].rstrip(" ,=+-*/") if " " in cut else cut
    return (first + " …",)


class _Unself(ast.NodeTransformer):
    """``self.x`` -> ``x`` (``self.tick_period_s`` -> ``dt``, ``self._aim`` -> ``aim``), ``math.f`` -> ``f``."""

    def visit_Attribute(self, node: ast.Attribute) -> ast.AST:
        self.generic_visit(node)
        if isinstance(node.value, ast.Name) and node.value.id in ("self", "math"):
            name = "dt" if node.attr == "tick_period_s" else node.attr.lstrip("_")
            return ast.copy_location(ast.Name(id=name, ctx=node.ctx), node)
        return node

    def visit_Name(self, node: ast.Name) -> ast.AST:
        if node.id.startswith("_"):  # a module's private helper, _step_towards -> step_towards
            return ast.copy_location(ast.Name(id=node.id.lstrip("_"), ctx=node.ctx), node)
        return node


def derived_text(fn: Callable[..., Any]) -> str | None:
    """A method's own statements as action text, if they are all assignments and calls; else None."""
    try:
        source = textwrap.dedent(inspect.getsource(fn))
        tree = ast.parse(source)
    except (OSError, TypeError, SyntaxError):
        return None
    func = tree.body[0] if tree.body else None
    if not isinstance(func, ast.FunctionDef):
        return None
    body = list(func.body)
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
        body = body[1:]  # the docstring
    if not body or not all(isinstance(s, (ast.Assign, ast.AugAssign, ast.Expr)) for s in body):
        return None
    if any(isinstance(s, ast.Expr) and not isinstance(s.value, ast.Call) for s in body):
        return None
    module = _Unself().visit(ast.Module(body=body, type_ignores=[]))
    return "; ".join(ast.unparse(s) for s in module.body)


def action_text(cls: type, name: str) -> ActionText | None:
    """What action ``name`` of chart class ``cls`` does, declared or derived; None if neither."""
    fn = getattr(cls, name, None)
    if fn is None or not callable(fn):
        return None
    declared = getattr(fn, _ATTR, None)
    if declared is not None:
        text, summary = declared
        return ActionText(name, text, _picture_lines(text, summary), True)
    derived = derived_text(fn)
    if derived is None:
        return None
    return ActionText(name, derived, _picture_lines(derived, None), False)


def helpers(cls: type) -> dict[str, str]:
    """The helpers a chart's texts may name: :data:`HELPERS` and its own ``action_helpers`` (with bases')."""
    found: dict[str, str] = dict(HELPERS)
    for klass in reversed(cls.__mro__):
        own = klass.__dict__.get("action_helpers")
        if isinstance(own, dict):
            found.update(own)
    return found


def helper_name(signature: str) -> str:
    """``aim(x, y, z)`` -> ``aim``."""
    return signature.split("(", 1)[0].strip()


def names_in(text: str) -> list[str]:
    """The names a text uses: identifiers outside quotes and equation references, keywords dropped."""
    bare = _EQUATION.sub(" ", _QUOTED.sub(" ", text))
    return [n for n in _IDENT.findall(bare) if n not in _WORDS and not keyword.iskeyword(n)]


def unknown_names(cls: type, text: str) -> list[str]:
    """Names in ``text`` that are neither the chart's data nor a documented helper (see the module)."""
    known = {helper_name(h) for h in helpers(cls)}
    for d in cls.declarations() if hasattr(cls, "declarations") else ():
        known.add(d.name)
        if d.kind == "output":
            known.add(f"{d.name}_p")
    return sorted({n for n in names_in(text) if n not in known})
