"""Mutation testing of scenarios: small wrong versions of a chart, and whether the scenarios notice.

``ttt-sm scenario mutate CHART FILES`` (docs/scenarios.md, "Generated
scenarios") builds **mutants** of the chart class from its source, each with
one change a person might make by mistake:

- ``flip``: a guard's comparison negated (``travel >= max_travel`` becomes
  ``travel < max_travel``; a guard that is a bare name, ``index``, becomes
  ``not index``), in a guard written as text or in a guard method;
- ``swap``: two transitions from the same state written in the other order
  (Stateflow tries them in the order written: the priority changes);
- ``drop``: an action left out (a transition's ``on=``, or the body of an
  ``on_enter_``/``on_exit_``/``during_`` method of the class, or of a class
  the chart mixes in: Control's actions live in a module per sub-chart,
  :mod:`ttt_sm.charts.control_drawing` and its neighbours; such a mutant is
  the chart with the method overridden by one that does nothing).

Each mutant runs the scenarios that run the chart bare (a robot scenario is
not run against mutants: the robot builds its own charts).  A mutant is
**killed** when one of them fails.  A mutant no scenario kills is looked at
again: scenarios generated from the mutant itself (:mod:`.generate`) are run
on the original chart and the original's on the mutant; if those pass too, no
search found a difference and it is reported as **equivalent within the
search bound**, otherwise as a survivor with the scenario that tells them
apart.
"""

from __future__ import annotations

import ast
import inspect
import sys
import textwrap
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, cast

from ..params import ArmParams
from ..runtime import TickChart
from .model import BareCharts, Scenario
from .robots import ChartsOnly
from .runner import run_scenario

_NEGATED = {ast.Eq: ast.NotEq, ast.NotEq: ast.Eq, ast.Lt: ast.GtE, ast.GtE: ast.Lt, ast.Gt: ast.LtE, ast.LtE: ast.Gt}
_TEXT_NEGATED = {"==": "!=", "!=": "==", "<=": ">", ">=": "<", "<": ">=", ">": "<="}
_ACTION_PREFIXES = ("on_enter_", "on_exit_", "during_")


@dataclass(frozen=True)
class Mutant:
    """One change to a chart class: its kind, where, and what."""

    kind: str  # flip, swap, drop
    line: int
    description: str
    apply: Callable[[ast.ClassDef], None] = field(compare=False, repr=False)
    #: A method the chart inherits from a class it mixes in, overridden to do nothing (``drop`` only).
    override: str | None = None
    #: The file of ``line`` when it is not the chart class's own (a mixed-in class's method).
    file: str = ""


@dataclass
class MutantResult:
    """What the scenarios made of one mutant."""

    mutant: Mutant
    status: str  # killed, survived, equivalent, stillborn
    detail: str = ""

    def to_dict(self) -> dict[str, Any]:
        out = {"kind": self.mutant.kind, "line": self.mutant.line, "mutant": self.mutant.description,
               "status": self.status, "detail": self.detail}
        if self.mutant.file:
            out["file"] = self.mutant.file
        return out


def _class_def(cls: type) -> tuple[ast.ClassDef, str, int]:
    """The class's syntax tree, its file and the line it starts at."""
    source, start = inspect.getsourcelines(cls)
    tree = ast.parse(textwrap.dedent("".join(source)))
    node = tree.body[0]
    assert isinstance(node, ast.ClassDef)
    return node, inspect.getsourcefile(cls) or "<chart>", start


def _calls(node: ast.AST) -> Iterator[ast.Call]:
    """The ``.to(...)`` / ``.from_(...)`` calls: the transitions written in a class body."""
    for sub in ast.walk(node):
        if isinstance(sub, ast.Call) and isinstance(sub.func, ast.Attribute) and sub.func.attr in ("to", "from_"):
            yield sub


def _path_to(root: ast.AST, target: ast.AST) -> list[int]:
    """Where ``target`` is under ``root``: the indices of the walk, to find it again in a copy."""
    for k, node in enumerate(ast.walk(root)):
        if node is target:
            return [k]
    raise LookupError("node not found")


def _find(root: ast.AST, where: list[int]) -> Any:
    return next(node for k, node in enumerate(ast.walk(root)) if k == where[0])


def mutants(cls: type[TickChart]) -> list[Mutant]:
    """Every mutant of the chart class (see the module's docstring)."""
    tree, _file, start = _class_def(cls)
    line = lambda node: start + getattr(node, "lineno", 1) - 1  # noqa: E731
    found: list[Mutant] = []
    guard_methods: set[str] = set()
    for call in _calls(tree):
        for kw in call.keywords:
            if kw.arg == "cond":
                texts = [kw.value] if not isinstance(kw.value, ast.List) else list(kw.value.elts)
                for text in texts:
                    if isinstance(text, ast.Constant) and isinstance(text.value, str):
                        found += _text_flips(tree, text, line(text))
                        guard_methods.update(w for w in text.value.replace("(", " ").split() if w.isidentifier())
            if kw.arg == "on" and isinstance(kw.value, ast.Constant):
                where = _path_to(tree, call)

                def drop_on(root: ast.ClassDef, where: list[int] = where) -> None:
                    node = _find(root, where)
                    node.keywords = [k for k in node.keywords if k.arg != "on"]
                found.append(Mutant("drop", line(call), f"{ast.unparse(call)}: without on={kw.value.value!r}",
                                    drop_on))
    found += _swaps(tree, line)
    for item in ast.walk(tree):
        if not isinstance(item, ast.FunctionDef):
            continue
        if item.name in guard_methods:
            for cmp in (n for n in ast.walk(item) if isinstance(n, ast.Compare)):
                if type(cmp.ops[0]) in _NEGATED:
                    where = _path_to(tree, cmp)

                    def flip(root: ast.ClassDef, where: list[int] = where) -> None:
                        node = _find(root, where)
                        node.ops = [_NEGATED[type(node.ops[0])](), *node.ops[1:]]
                    before = ast.unparse(cmp)
                    after = ast.unparse(ast.Compare(cmp.left, [_NEGATED[type(cmp.ops[0])](), *cmp.ops[1:]],
                                                    cmp.comparators))
                    found.append(Mutant("flip", line(cmp), f"{item.name}: {before} -> {after}", flip))
        elif item.name.startswith(_ACTION_PREFIXES):
            where = _path_to(tree, item)

            def drop(root: ast.ClassDef, where: list[int] = where) -> None:
                node = _find(root, where)
                node.body = [ast.Pass()]
            found.append(Mutant("drop", line(item), f"{item.name}: does nothing", drop))
    found += _mixed_in_drops(cls, tree)
    return sorted(found, key=lambda m: (m.file, m.line, m.kind, m.description))


def _mixed_in_drops(cls: type[TickChart], tree: ast.ClassDef) -> list[Mutant]:
    """``drop`` of each action method the chart inherits from a plain class it mixes in (not from another
    chart class it extends, nor the runtime's: those are that chart's)."""
    own = {item.name for item in tree.body if isinstance(item, ast.FunctionDef)}
    runtime = set(TickChart.__mro__)
    found = []
    for base in cls.__mro__[1:]:
        if base in runtime or issubclass(base, TickChart):
            continue
        for name, fn in vars(base).items():
            # a method defined under its own name (not an alias of a helper), not redefined nearer the chart
            if not (name.startswith(_ACTION_PREFIXES) and inspect.isfunction(fn) and fn.__name__ == name) \
                    or name in own or getattr(cls, name, None) is not fn:
                continue
            method = cast(Callable[..., Any], fn)
            source, start = inspect.getsourcelines(method)
            line = start + next(k for k, text in enumerate(source) if text.lstrip().startswith("def "))
            found.append(Mutant("drop", line, f"{base.__name__}.{name}: does nothing", _unchanged, override=name,
                                file=inspect.getsourcefile(method) or base.__module__))
    return found


def _unchanged(root: ast.ClassDef) -> None:
    """The chart's own source as it is (a mutant that overrides a mixed-in method instead)."""


def _text_flips(tree: ast.ClassDef, text: ast.Constant, line: int) -> list[Mutant]:
    """A guard written as text: each comparison negated, or a bare name negated."""
    import re

    value = str(text.value)
    where = _path_to(tree, text)
    out = []
    ops = list(re.finditer(r"==|!=|<=|>=|<|>", value))
    variants = [value[:m.start()] + _TEXT_NEGATED[m.group()] + value[m.end():] for m in ops]
    if not ops and value.strip():
        variants = [value[4:].strip() if value.startswith("not ") else f"not ({value})"]
        if " and " in value or " or " in value:
            variants = [f"not ({value})"]
    for variant in variants:
        def flip(root: ast.ClassDef, where: list[int] = where, variant: str = variant) -> None:
            _find(root, where).value = variant
        out.append(Mutant("flip", line, f"cond {value!r} -> {variant!r}", flip))
    return out


def _swaps(tree: ast.ClassDef, line: Callable[[ast.AST], int]) -> list[Mutant]:
    """Two transitions from the same source, written one after the other: the other order."""
    out = []
    for body_owner in ast.walk(tree):
        body = getattr(body_owner, "body", None)
        if not isinstance(body, list):
            continue
        statements = [s for s in body if isinstance(s, ast.Expr) and isinstance(s.value, ast.Call)
                      and isinstance(s.value.func, ast.Attribute) and s.value.func.attr == "to"]
        by_source: dict[str, list[ast.Expr]] = {}
        for s in statements:
            assert isinstance(s.value, ast.Call) and isinstance(s.value.func, ast.Attribute)
            by_source.setdefault(ast.unparse(s.value.func.value), []).append(s)
        for group in by_source.values():
            for a, b in zip(group, group[1:], strict=False):
                wa, wb = _path_to(tree, a), _path_to(tree, b)

                def swap(root: ast.ClassDef, wa: list[int] = wa, wb: list[int] = wb) -> None:
                    na, nb = _find(root, wa), _find(root, wb)
                    na.value, nb.value = nb.value, na.value
                out.append(Mutant("swap", line(a), f"swapped: {ast.unparse(a)} / {ast.unparse(b)}", swap))
    return out


def build(cls: type[TickChart], mutant: Mutant) -> type[TickChart]:
    """The mutant chart class: the class's source changed, run in its module's namespace."""
    import copy

    tree, file, start = _class_def(cls)
    tree = copy.deepcopy(tree)
    mutant.apply(tree)
    module = ast.Module(body=[tree], type_ignores=[])
    ast.increment_lineno(module, start - 1)
    ast.fix_missing_locations(module)
    namespace = dict(vars(sys.modules[cls.__module__]))
    exec(compile(module, file, "exec"), namespace)  # noqa: S102 - the project's own chart source, changed
    built = namespace[cls.__name__]
    assert isinstance(built, type) and issubclass(built, TickChart)
    if mutant.override is not None:
        def nothing(self: Any) -> None:
            """The dropped action: does nothing."""

        nothing.__name__ = nothing.__qualname__ = mutant.override
        built = type(built.__name__, (built,), {mutant.override: nothing, "__module__": built.__module__,
                                                "__qualname__": built.__qualname__})
    return built


def _with_chart(scenario: Scenario, chart: str, cls: type[TickChart]) -> Scenario:
    assert scenario.bare is not None
    charts = {name: (cls if c.__name__ == chart else c) for name, c in scenario.bare.charts.items()}
    return replace(scenario, bare=BareCharts(charts, scenario.bare.where))


def runs_chart(scenario: Scenario, chart: str) -> bool:
    """Whether a scenario runs ``chart`` bare (only those run against its mutants)."""
    return scenario.bare is not None and any(c.__name__ == chart for c in scenario.bare.charts.values())


def _bare(scenario: Scenario, params: ArmParams, listeners: Sequence[object]) -> ChartsOnly:
    assert scenario.bare is not None  # only bare-chart scenarios are run against mutants
    return ChartsOnly(scenario.bare, params, listeners)


def first_failure(scenarios: Sequence[Scenario], chart: str, cls: type[TickChart], params: ArmParams,
                  killers: list[Scenario] | None = None) -> str | None:
    """The first failure of the scenarios with ``chart`` replaced by ``cls`` (None: they all pass).

    ``killers``: the scenarios that failed before, most recent first; they run
    first (a mutant next to the last one in the source is most often caught by
    the same scenario), and the one that fails now moves to their front.
    """
    first = list(killers or ())
    order = first + [s for s in scenarios if not any(s is k for k in first)]
    for scenario in order:
        s = _with_chart(scenario, chart, cls)
        result = run_scenario(s, params, robot_factory=_bare)
        if not result.passed:
            if killers is not None:
                killers[:] = [scenario, *(k for k in killers if k is not scenario)]
            return f"{scenario.file}: {result.failures[0].message}"
    return None


def mutation_test(cls: type[TickChart], scenarios: Sequence[Scenario], params: ArmParams,
                  check_equivalence: bool = True, stride: int = 1) -> list[MutantResult]:
    """Run the scenarios that run ``cls`` bare against each of its mutants (``stride``: every so many, a
    sample of them in the order of the source)."""
    from .generate import generate, to_yaml
    from .loader import load_scenario_text

    chart = cls.__name__
    runnable = [s for s in scenarios if runs_chart(s, chart)]
    results = []
    originals: list[Scenario] = []  # the chart's own generated scenarios: the same for every mutant, made once
    killers: list[Scenario] = []  # the scenarios that killed mutants, the latest first: tried first
    for mutant in mutants(cls)[::stride]:
        try:
            built = build(cls, mutant)
            built(tick_period_s=params.control.chart_dt, chart_name=chart)
        except Exception as exc:  # the change makes no chart at all: nothing to test
            results.append(MutantResult(mutant, "stillborn", f"{type(exc).__name__}: {exc}"))
            continue
        failure = first_failure(runnable, chart, built, params, killers)
        if failure is not None:
            results.append(MutantResult(mutant, "killed", failure))
            continue
        if not check_equivalence:
            results.append(MutantResult(mutant, "survived", "no scenario failed"))
            continue
        # scenarios of the mutant itself: do they tell it from the original? (and the original's)
        probes = [load_scenario_text(to_yaml(g, "mutate"), f"<generated from the mutant #{k}>")
                  for k, g in enumerate(generate(built, params.control.chart_dt).scenarios, 1)]
        apart = first_failure(probes, chart, cls, params)
        if apart is None:
            if not originals:
                originals = [load_scenario_text(to_yaml(g, "mutate"), f"<generated from {chart} #{k}>")
                             for k, g in enumerate(generate(cls, params.control.chart_dt).scenarios, 1)]
            apart = first_failure(originals, chart, built, params)
        if apart is None:
            results.append(MutantResult(mutant, "equivalent", "the scenarios generated from the mutant and from"
                                        " the chart run alike on both: no difference within the search bound"))
        else:
            results.append(MutantResult(mutant, "survived", f"a generated scenario tells it apart: {apart}"))
    return results


def summary(results: Sequence[MutantResult]) -> dict[str, Any]:
    """Counts: killed of the mutants that are not equivalent or stillborn."""
    count = {s: sum(r.status == s for r in results) for s in ("killed", "survived", "equivalent", "stillborn")}
    live = count["killed"] + count["survived"]
    return {**count, "mutants": len(results), "kill_ratio": round(count["killed"] / live, 4) if live else 1.0}
