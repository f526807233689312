"""Guards compiled to plain zero-argument Python calls for the quiet-tick fast path.

python-statemachine evaluates a guard through its callback registry and signature
adapter (microseconds per guard, plus ~50-200 us for the event machinery around
it).  On a tick in which nothing happens that cost would dominate a simulation,
so the runtime resolves each guard of a tick transition once per chart instance
into a plain callable:

* a method or function of the chart -> the bound method (its ``machine``,
  ``model``, ``source``/``state``, ``target``, ``transition`` parameters bound once);
* a name of a datum or attribute -> a dictionary read;
* a boolean expression (``"ready and not stop"``) -> the library's own parser,
  with the names above;
* ``after(n)`` / ``after_s(t)`` -> a comparison of tick counters.

Anything else (a guard that wants the event or its data) falls back to the
library's evaluation of that transition's guards: correct, only slower.
"""

from __future__ import annotations

import ast
import inspect
import operator
from collections.abc import Callable
from functools import partial
from typing import Any, Protocol, cast

from statemachine import StateChart
from statemachine.callbacks import SpecReference
from statemachine.event_data import EventData, TriggerData
from statemachine.spec_parser import operator_mapping, parse_boolean_expr, replace_operators
from statemachine.transition import Transition

from .temporal import Temporal, TickCounter, duration_of, temporal_of


class FastPathChart(TickCounter, Protocol):  # noqa: D101
    """What compiling a guard reads of its chart; :class:`~.chart.TickChart` is one.

    A protocol rather than an import of :mod:`.chart`, which imports this
    module: the chart's own declarations (``_entered_at``) and the library's
    (``model``, ``_callbacks``) that the fast path binds once.
    """

    _entered_at: dict[str, int]
    model: Any
    _callbacks: Any

    def _duration_s(self, spec: Any, state_id: str) -> float: ...

Guard = Callable[[], Any]


class _Unsupported(Exception):
    """This guard cannot be made a plain call; use the library's evaluation."""


def compile_guard(chart: FastPathChart, transition: Transition, clock: str | None = None) -> tuple[Guard | None, bool]:
    """A zero-argument callable that is truthy when all guards of ``transition`` hold.

    ``clock`` is the state whose clock its temporal operators read (default: its source).
    Returns ``(guard, fast)``: ``guard`` is ``None`` when the transition has no
    guard; ``fast`` is False when the library's evaluation had to be used.
    """
    specs = list(transition.cond)
    if not specs:
        return None, True
    clock = clock if clock is not None else transition.source.id
    try:
        parts = [_compile_spec(chart, transition, spec, clock) for spec in specs]
    except _Unsupported:
        return _library_guard(chart, transition), False
    if len(parts) == 1:
        return parts[0], True

    def all_hold() -> bool:
        for part in parts:
            if not part():
                return False
        return True

    return all_hold, True


def _compile_spec(chart: FastPathChart, transition: Transition, spec: Any, clock: str) -> Guard:
    if spec.reference is SpecReference.CALLABLE:
        fn = _compile_callable(chart, transition, spec, clock)
    elif spec.reference is SpecReference.PROPERTY:
        fn = partial(spec.func.fget, chart)
    elif spec.attr_name.isidentifier():
        fn = _compile_name(chart, transition, spec.attr_name)
    else:
        fn = _compile_expression(chart, transition, spec.attr_name)
    if spec.expected_value is False:  # an ``unless=`` guard
        return _negate(fn)
    return fn


def _negate(fn: Guard) -> Guard:
    def negated() -> bool:
        return not fn()

    return negated


def _compile_callable(chart: FastPathChart, transition: Transition, spec: Any, clock: str) -> Guard:
    func = spec.func
    temporal = temporal_of(func)
    if temporal is not None:
        return _compile_temporal(chart, transition, temporal, clock)
    span = duration_of(func)
    if span is not None:
        def held() -> bool:
            return bool(span.holds(chart._duration_s(span, clock)))

        return held
    if not spec.is_bounded:
        bound = getattr(chart, spec.lookup_name, None)
        if getattr(bound, "__func__", None) is func:
            func = bound
    return _bind_known(chart, transition, func)


def _compile_temporal(chart: FastPathChart, transition: Transition, temporal: Temporal, clock: str) -> Guard:
    """A temporal operator as a comparison of the chart's counters (ticks since entry, or events)."""
    n = temporal.ticks(chart.tick_period_s, f" on {transition.source.id} -> "
                       f"{transition.target.id if transition.target else '(none)'}")
    counters = chart.__dict__
    if temporal.event is not None:
        counts, event, holds = counters["_counts"], temporal.event, temporal.holds

        def counted() -> bool:
            return holds(counts.get(clock, {}).get(event, 0), n)

        return counted
    entered_at = chart._entered_at
    if temporal.op == "after":
        def elapsed() -> bool:
            return counters["_ticks"] - entered_at[clock] >= n

        return elapsed
    holds = temporal.holds

    def ticks() -> bool:
        return holds(counters["_ticks"] - entered_at[clock], n)

    return ticks


def _compile_name(chart: FastPathChart, transition: Transition, name: str) -> Guard:
    static = inspect.getattr_static(chart, name, _MISSING)
    if static is _MISSING:
        model = chart.model
        if hasattr(model, name):
            value = getattr(model, name)
            if callable(value):
                return _bind_known(chart, transition, value)
            return partial(getattr, model, name)
        raise _Unsupported(name)
    if isinstance(static, property) and static.fget is not None:
        return partial(static.fget, chart)
    if name in chart.__dict__:
        value = chart.__dict__[name]
        if callable(value):
            return _bind_known(chart, transition, value)
        return partial(operator.getitem, chart.__dict__, name)
    value = getattr(chart, name)
    if callable(value):
        return _bind_known(chart, transition, value)
    return partial(getattr, chart, name)


_ALLOWED_NODES = (
    ast.Expression, ast.BoolOp, ast.And, ast.Or, ast.UnaryOp, ast.Not, ast.Compare,
    ast.Eq, ast.NotEq, ast.Lt, ast.LtE, ast.Gt, ast.GtE, ast.Name, ast.Load, ast.Constant,
)


class _Inline(ast.NodeTransformer):
    """Rewrite each name of a guard expression into a read of the chart's data or a call."""

    def __init__(self, chart: FastPathChart, transition: Transition) -> None:
        self.chart = chart
        self.transition = transition
        self.env: dict[str, Any] = {"_d": chart.__dict__}

    def visit_Name(self, node: ast.Name) -> ast.AST:
        name = node.id
        d = self.chart.__dict__
        if name in d and not callable(d[name]):
            # A datum: a dictionary read, so it stays live when the chart assigns it.
            new: ast.AST = ast.Subscript(ast.Name("_d", ast.Load()), ast.Constant(name), ast.Load())
        else:
            ref = f"_g{len(self.env)}"
            self.env[ref] = _compile_name(self.chart, self.transition, name)
            new = ast.Call(ast.Name(ref, ast.Load()), [], [])
        return ast.copy_location(new, node)


def _inline_expression(chart: FastPathChart, transition: Transition, expr: str) -> Guard:
    """Compile ``"a and not b"`` / ``"n >= 3"`` into one Python lambda, or give up."""
    try:
        tree = ast.parse(replace_operators(expr).strip(), mode="eval")
    except SyntaxError as err:
        raise _Unsupported(expr) from err
    if not all(isinstance(node, _ALLOWED_NODES) for node in ast.walk(tree)):
        raise _Unsupported(expr)
    inline = _Inline(chart, transition)
    body = inline.visit(tree).body
    lam = ast.Expression(ast.Lambda(
        ast.arguments(posonlyargs=[], args=[], kwonlyargs=[], kw_defaults=[], defaults=[]), body,
    ))
    ast.fix_missing_locations(lam)
    code = compile(lam, f"<guard {expr!r}>", "eval")
    return eval(code, {"__builtins__": {}, **inline.env})  # noqa: S307 - our own AST, names only


def _compile_expression(chart: FastPathChart, transition: Transition, expr: str) -> Guard:
    try:
        return _inline_expression(chart, transition, expr)
    except _Unsupported:
        pass  # e.g. In('state'): let the library's parser build it

    def resolve(name: str) -> Callable[..., Any]:
        fn = _compile_name(chart, transition, name)

        def leaf(*_args: Any, **_kwargs: Any) -> Any:
            return fn()

        leaf.__name__ = name
        return leaf

    try:
        compiled = parse_boolean_expr(expr, resolve, operator_mapping)
    except _Unsupported:
        raise
    except Exception as err:  # the library reports a bad expression when the chart is built
        raise _Unsupported(expr) from err
    # ``In('state')`` reads the machine from the keyword arguments.
    return partial(compiled, machine=chart)


_MISSING = object()


def _bind_known(chart: FastPathChart, transition: Transition, func: Callable[..., Any]) -> Guard:
    """Bind the parameters python-statemachine would pass by name, or give up."""
    try:
        signature = inspect.signature(func)
    except (TypeError, ValueError) as err:
        raise _Unsupported(str(func)) from err
    source = getattr(chart, transition.source.id, transition.source)
    target = transition.target
    known = {
        "machine": chart, "model": chart.model, "transition": transition,
        "source": source, "state": source,
        "target": getattr(chart, target.id, target) if target is not None else None,
    }
    kwargs: dict[str, Any] = {}
    for param in signature.parameters.values():
        if param.kind in (param.VAR_POSITIONAL, param.VAR_KEYWORD):
            continue
        if param.name in known:
            kwargs[param.name] = known[param.name]
        elif param.default is param.empty:
            raise _Unsupported(f"{func!r} needs {param.name!r}")
    return partial(func, **kwargs) if kwargs else func


def _library_guard(chart: FastPathChart, transition: Transition) -> Guard:
    key = transition.cond.key
    evaluate = chart._callbacks.all
    # The arguments the library gives a guard when the transition's own event is sent.
    event = next(iter(transition.events), None)
    trigger = TriggerData(machine=cast(StateChart, chart), event=event)  # a TickChart is a StateChart
    kwargs = EventData(trigger_data=trigger, transition=transition).extended_kwargs

    def library_guard() -> bool:
        return bool(evaluate(key, **kwargs))

    return library_guard


def compile_condition(chart: FastPathChart, text: str, state: Any) -> Guard:
    """A condition in the guard language (data, guard methods, and/or/not, comparisons) as a plain call.

    Used for ``duration(condition)``, whose condition is sampled at every wake-up.
    """
    from statemachine.transition import Transition as _T

    probe = _T(state, state)  # binds `source`/`state` for a guard method that asks for them
    if text.isidentifier():
        return _compile_name(chart, probe, text)
    try:
        return _inline_expression(chart, probe, text)
    except _Unsupported:
        return _compile_expression(chart, probe, text)
