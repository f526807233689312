"""A quiet tick as generated straight-line code: the chart's *plan* for one configuration.

Most ticks of most charts take no transition: the guards of the active
configuration are tried and its during actions run, in Stateflow's order
(:mod:`.engine`).  :class:`~.chart.TickChart` builds, per configuration, one
function that does exactly that with no loop and no event data
(:func:`plan_runner`), and one that copies every output to its previous value
(:func:`previous_copier`); when a guard holds, the plan hands over to the
interpreter where it stopped (:data:`Resume`).  This is what keeps a quiet tick
under a microsecond (docs/runtime.md).  The generated code names only checked
identifiers and the chart's own callables, bound as default arguments.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from .program import Node

#: Where a plan hands over to the interpreter: the states from the top down to the one whose
#: transition held, the phase ("outer" or "inner") and the transition's place in that list.
Resume = tuple[tuple[Node, ...], str, int]


class Plan:
    """What a quiet tick does in one configuration, as generated functions (see :func:`plan_runner`)."""

    __slots__ = ("active", "run", "run_tick", "resume")

    def __init__(self, active: frozenset[str], run: Callable[[dict[str, Any]], int],
                 run_tick: Callable[[dict[str, Any]], int], resume: Sequence[Resume]) -> None:
        self.active = active
        self.run = run
        self.run_tick = run_tick
        self.resume = tuple(resume)


def plan_runner(steps: Sequence[tuple[str, Any]], prev_pairs: Sequence[tuple[str, str]] | None = None,
                 slot_pairs: Sequence[tuple[int, int]] = ()) -> Callable[[dict[str, Any]], int]:
    """A quiet wake-up of one configuration as straight-line code: the index of the first
    transition whose guard holds, or -1 once every step ran.

    ``steps`` are, in Stateflow's order, ``("guard", (k, fn))``: return ``k`` if
    ``fn()`` holds (``fn`` None: always); ``("act", (node, fn))``: note the state
    whose action runs (for an event it sends) and call ``fn()``.  A loop over the
    steps costs about a third more, and it runs on every tick of every chart.

    With ``prev_pairs`` the function first counts the tick and copies every output
    to its previous value (the whole tick when no event is queued, in one call).
    ``slot_pairs`` are the (output, previous) places of a buffered chart's outputs in
    its buffer; ``prev_pairs`` then names only the outputs kept as plain attributes.
    """
    lines, bound = [], {}
    if prev_pairs is not None:
        lines.append("    d['_ticks'] += 1")
        lines += copy_lines(prev_pairs, slot_pairs)
    acted = False
    for n, (kind, item) in enumerate(steps):
        if kind == "guard":
            k, fn = item
            if fn is None:
                lines.append(f"    return {k}")
                break
            bound[f"g{n}"] = fn
            lines += [f"    if g{n}():", f"        return {k}"]
        else:
            node, fn = item
            bound[f"n{n}"], bound[f"a{n}"] = node, fn
            lines += [f"    d['_cur'] = n{n}", f"    a{n}()"]
            acted = True
    else:
        if acted:
            lines.append("    d['_cur'] = None")
        lines.append("    return -1")
    args = ", ".join(["d"] + [f"{name}={name}" for name in bound])
    namespace: dict[str, Any] = dict(bound)
    exec(compile(f"def run_plan({args}):\n" + "\n".join(lines) + "\n", "<tick plan>", "exec"),  # noqa: S102
         namespace)
    return namespace["run_plan"]  # type: ignore[no-any-return]


def copy_lines(pairs: Sequence[tuple[str, str]], slot_pairs: Sequence[tuple[int, int]]) -> list[str]:
    """``X_p = X`` as lines of code: plain attributes by name, a buffered chart's numbers by place."""
    lines = [f"    d[{prev!r}] = d[{out!r}]" for out, prev in pairs]
    if slot_pairs:
        lines.append("    b = d['_data_view']")
        lines += [f"    b[{prev}] = b[{out}]" for out, prev in slot_pairs]
    return lines


def previous_copier(name: str, pairs: tuple[tuple[str, str], ...],
                     slot_pairs: tuple[tuple[int, int], ...] = ()) -> Callable[[dict[str, Any]], None]:
    """``X_p = X`` for every output of a chart class, as straight-line code.

    It runs at the start of every tick of every chart; a loop over the pairs
    costs about a third more per output.  The names are checked identifiers.
    """
    body = "".join(line + "\n" for line in copy_lines(pairs, slot_pairs)) or "    pass\n"
    namespace: dict[str, Any] = {}
    exec(compile("def copy_previous(d):\n" + body, f"<{name}.copy_previous>", "exec"), namespace)  # noqa: S102
    return namespace["copy_previous"]  # type: ignore[no-any-return]
