"""Scenarios generated from a chart: files that together take every transition the search can reach.

``ttt-sm scenario generate CHART`` (docs/scenarios.md, "Generated scenarios")
searches the chart's behaviour (:mod:`.explore`) and writes bare-chart
scenarios in today's format (``chart: X``), each step commented with the
transitions it takes and why its inputs have their values, each step checked
(``expect``: the states active after it, the outputs it changed) and each
file ending with ``expect_states`` (``match: exact``) on the path it was built
for.

Two strategies:

- ``shortest``: one scenario per path the search found first for a
  transition (transitions first taken by the same step share it);
- ``tour``: fewer, longer scenarios: from the end of the scenario so far, the
  nearest transition not yet taken (a breadth-first search from there), until
  none can be reached from there; then a new scenario from power-on.

A transition that no path takes is reported with the reason
(:func:`unreachable_reason`), never left out silently.  The lower bound of a
tour is the number of reachable transitions: a set of scenarios that takes
every one takes each at least once.
"""

from __future__ import annotations

import itertools
import re
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..files import write_atomic
from ..runtime import TickChart
from ..runtime.jsonable import dumps
from ..runtime.structure import TransitionInfo
from .explore import Bounds, Explorer
from .guard_reader import atoms, kleene, refs, show, show_value
from .paths import Sim, Step

STRATEGIES = ("shortest", "tour")
#: How many nodes the greedy tours may search in all, and each extension of a tour (nodes, not seconds:
#: the same files on a busy machine).
TOUR_NODES = 300
TOUR_BOUNDS = Bounds(max_nodes=40)
#: The longest condition a generated ``expect`` writes (the language allows 2000 characters).
MAX_EXPECT_CHARS = 400


@dataclass(frozen=True)
class GeneratedScenario:
    """One generated scenario: its steps, and the transitions it was built to take."""

    chart: str
    path: tuple[Step, ...]
    takes: tuple[str, ...]
    leaves: tuple[str, ...]  #: the leaf states entered since power-on (``expect_states``)
    strategy: str
    initial: tuple[str, ...] = ()  #: the leaf states active at power-on

    @property
    def chart_steps(self) -> int:
        return sum(s.ticks for s in self.path)


@dataclass
class Generated:
    """What generating a chart's scenarios found."""

    chart: str
    strategy: str
    transitions: tuple[str, ...]
    scenarios: list[GeneratedScenario] = field(default_factory=list)
    unreachable: dict[str, str] = field(default_factory=dict)
    seconds: float = 0.0  #: wall-clock time of the search and the paths
    cpu_seconds: float = 0.0  #: processor time of this process meanwhile (a busy machine changes it less)
    nodes: int = 0
    files: list[str] = field(default_factory=list)

    def scenario_for(self, label: str) -> GeneratedScenario | None:
        """The scenario that takes transition ``label`` (the first made: for ``shortest``, the shortest
        path found to it), or None (:meth:`reason` says why)."""
        return next((s for s in self.scenarios if label in s.takes), None)

    def reason(self, label: str) -> str:
        """Why no scenario takes transition ``label``: the search's reason."""
        return self.unreachable.get(label, "the search did not take it")

    @property
    def covered(self) -> list[str]:
        taken = {label for s in self.scenarios for step in s.path for label in step.taken}
        return [t for t in self.transitions if t in taken]

    def to_dict(self) -> dict[str, Any]:
        """What ``ttt-sm scenario generate --json`` prints per chart."""
        return {
            "chart": self.chart,
            "strategy": self.strategy,
            "transitions": len(self.transitions),
            "covered": len(self.covered),
            "unreachable": [{"transition": t, "reason": r} for t, r in self.unreachable.items()],
            "scenarios": len(self.scenarios),
            "steps": sum(len(s.path) for s in self.scenarios),
            "chart_steps": sum(s.chart_steps for s in self.scenarios),
            "tour_lower_bound": len(self.transitions) - len(self.unreachable),
            "search_nodes": self.nodes,
            "seconds": round(self.seconds, 3),
            "cpu_seconds": round(self.cpu_seconds, 3),
            "files": list(self.files),
        }


def generate(cls: type[TickChart], dt: float, strategy: str = "shortest",
             bounds: Bounds | None = None) -> Generated:
    """Search ``cls`` and make its scenarios (nothing written: see :func:`write`)."""
    if strategy not in STRATEGIES:
        raise ValueError(f"strategy {strategy!r}; strategies: {', '.join(STRATEGIES)}")
    t0, cpu0 = time.perf_counter(), time.process_time()
    explorer = Explorer(cls, dt, bounds)
    found = explorer.search()
    labels = tuple(t.label for t in cls.structure().transitions)
    out = Generated(cls.__name__, strategy, labels)
    out.unreachable = {t.label: unreachable_reason(explorer, t) for t in cls.structure().transitions
                       if t.label not in found}
    paths = _tour(explorer, found) if strategy == "tour" else _shortest(found)
    for path in paths:
        out.scenarios.append(_scenario(cls, dt, path, labels, strategy))
    out.seconds = time.perf_counter() - t0
    out.cpu_seconds = time.process_time() - cpu0
    out.nodes = explorer.nodes
    return out


def _shortest(found: dict[str, tuple[Step, ...]]) -> list[tuple[Step, ...]]:
    """One path per transition, the first found (paths shared by several transitions once)."""
    return list(dict.fromkeys(found.values()))


def _tour(explorer: Explorer, found: dict[str, tuple[Step, ...]]) -> list[tuple[Step, ...]]:
    """Greedy tours: extend the current path to the nearest transition not yet taken (a small search
    from its end); once :data:`TOUR_NODES` are searched, the transitions left get their first paths."""
    left = set(found)
    paths: list[tuple[Step, ...]] = []
    budget = explorer.nodes + TOUR_NODES
    while left and explorer.nodes < budget:
        path: tuple[Step, ...] = ()
        here: Sim | None = None  # the chart run through `path`, when the last search left it there
        while left and explorer.nodes < budget:
            nearest = explorer.search(path, wanted=left, stop_at_first=True, bounds=TOUR_BOUNDS, root=here)
            if nearest:
                path, here = next(iter(nearest.values())), explorer.last_sim
            elif not path:  # far from power-on: start with the shortest first path of those left
                path, here = min((found[label] for label in sorted(left)), key=len), None
            else:
                break
            left -= {label for step in path for label in step.taken}
        paths.append(path)
    # what the tours did not reach in time, or from power-on within their small searches: first paths
    paths.extend(dict.fromkeys(found[label] for label in sorted(left)
                               if not any(label in step.taken for p in paths for step in p)))
    return paths


def _scenario(cls: type[TickChart], dt: float, path: tuple[Step, ...], labels: Sequence[str],
              strategy: str) -> GeneratedScenario:
    initial = Sim(cls, dt).leaf_sequence()
    leaves = [*initial, *(state for step in path for state in step.entered)]
    taken = {label for step in path for label in step.taken}
    if strategy == "shortest":
        takes = tuple(label for label in labels if label in path[-1].taken)
    else:
        takes = tuple(label for label in labels if label in taken)
    return GeneratedScenario(cls.__name__, path, takes, tuple(leaves), strategy, tuple(initial))


# -- why a transition was not taken ---------------------------------------------------------

def unreachable_reason(explorer: Explorer, t: TransitionInfo) -> str:
    """One sentence: why no explored path takes ``t``."""
    guard = explorer.guards[t.label]
    bound = (f"the search explored {explorer.nodes} nodes, paths of at most {explorer.bounds.max_depth} steps,"
             f" each waiting at most {explorer.bounds.max_ticks} chart steps"
             + ("" if explorer.complete else ", and stopped at that bound"))
    if not _satisfiable(guard):
        return f"its guard '{show(guard)}' holds for no truth values of its comparisons: it is never true"
    if t.source not in explorer.seen_states:
        return f"its source state {t.source} is never active on any explored path ({bound})"
    group = [u for u in explorer.structure.transitions
             if u.source == t.source and u.trigger == t.trigger and u.scope == t.scope and u.priority < t.priority]
    for u in group:
        if kleene(explorer.guards[u.label], {}, set(atoms(explorer.guards[u.label]))) is True:
            return f"'{u.label}' goes before it (Stateflow's order) and always holds"
    names = sorted(refs(guard))
    if names and not set(names) & explorer.reader.inputs:
        return (f"its guard '{show(guard)}' reads only the chart's own data ({', '.join(names)}), which no"
                f" explored path made true while {t.source} was active ({bound})")
    return f"no explored path made its guard '{show(guard)}' true while {t.source} was active ({bound})"


def _satisfiable(guard: Any) -> bool:
    leaves = list(dict.fromkeys(a for a in atoms(guard)))
    if len(leaves) > 12:
        return True
    for values in itertools.product((True, False), repeat=len(leaves)):
        if _truth(guard, dict(zip(leaves, values, strict=True))) is not False:
            return True
    return False


def _truth(node: Any, fixed: dict[Any, bool]) -> bool | None:
    if node in fixed:
        return fixed[node]
    kind = node[0]
    if kind == "const":
        return bool(node[1])
    if kind == "not":
        inner = _truth(node[1], fixed)
        return None if inner is None else not inner
    if kind in ("and", "or"):
        results = [_truth(n, fixed) for n in node[1]]
        decisive = kind == "or"
        if decisive in results:
            return decisive
        return None if None in results else not decisive
    if kind == "ifexp":
        test = _truth(node[1], fixed)
        if test is None:
            a, b = _truth(node[2], fixed), _truth(node[3], fixed)
            return a if a == b else None
        return _truth(node[2] if test else node[3], fixed)
    return None


# -- the files ---------------------------------------------------------------------------

def file_name(scenario: GeneratedScenario, number: int) -> str:
    """``driveinit3_01_takes_approach_to_back_off.yaml``: the chart, a number, what it takes."""
    first = scenario.takes[0] if scenario.takes else "power_on"
    head = first.split(":")[0].replace("->", "to").replace("(none)", "none")
    slug = re.sub(r"[^a-z0-9]+", "_", head.lower()).strip("_")
    more = f"_and_{len(scenario.takes) - 1}_more" if len(scenario.takes) > 1 else ""
    return f"{scenario.chart.lower()}_{number:02d}_takes_{slug}{more}.yaml"


def yaml_value(v: Any) -> str:
    """A value as YAML writes it and the scenario loader reads it back exactly."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        text = repr(v)
        if "e" in text and "." not in text:  # YAML 1.1 reads 1e-06 as text: 1.0e-06
            mantissa, exponent = text.split("e")
            text = f"{mantissa}.0e{exponent}"
        return text
    if isinstance(v, str):
        return dumps(v)
    return repr(v)


def _condition_value(v: Any) -> str | None:
    """A value in a condition (None: the language cannot write it exactly: NaN, infinity, both quotes)."""
    if isinstance(v, float) and (v != v or v in (float("inf"), float("-inf"))):
        return None
    if isinstance(v, str):
        if '"' not in v:
            return f'"{v}"'
        return f"'{v}'" if "'" not in v else None
    if isinstance(v, bool | int | float):
        return show_value(v)
    return None


def _expect(chart: str, step: Step) -> list[str]:
    """The conditions that check a step: the leaf states active, and each output it changed."""
    parts = [f"{chart}.{leaf}" for leaf in step.active]
    for name, v in step.outputs:
        written = _condition_value(v)
        if written is not None:
            parts.append(f"{chart}.{name} == {written}")
    lines: list[str] = []
    current: list[str] = []
    for part in parts:
        if current and len(" and ".join([*current, part])) > MAX_EXPECT_CHARS:
            lines.append(" and ".join(current))
            current = []
        current.append(part)
    if current:
        lines.append(" and ".join(current))
    return lines


def to_yaml(scenario: GeneratedScenario, command: str) -> str:
    """The scenario file: in today's format, commented."""
    chart = scenario.chart
    out = [
        f"# Generated by `{command}` (docs/scenarios.md, \"Generated scenarios\"):",
        "# generate it again rather than edit it.",
        ("# The shortest path found to:" if scenario.strategy == "shortest"
         else "# A tour: from each step, the nearest transition not yet taken. It takes:"),
        *(f"#   {label}" for label in scenario.takes),
        f"name: {chart} takes {_name_part(scenario)}",
        "description: >",
        f"  Generated from the guards of {chart}: {len(scenario.path)} steps,"
        f" {scenario.chart_steps} chart steps, from power-on.",
        f"chart: {chart}",
        "steps:",
    ]
    before = scenario.initial
    for k, step in enumerate(scenario.path, 1):
        doing = "; ".join(step.why) or (f"posts {', '.join(step.events)}" if step.events else "waits")
        out.append(f"  # step {k}: {doing}")
        if step.taken:
            out.append(f"  # takes {'; '.join(step.taken)} (after {step.ticks} chart step"
                       f"{'s' if step.ticks != 1 else ''})")
        else:
            out.append("  # (sets the inputs only: nothing happens until a later step adds what is missing)")
        if step.sets:
            values = ", ".join(f"{chart}.{name}: {yaml_value(v)}" for name, v in step.sets)
            out.append(f"  - set: {{{values}}}")
        for event in step.events:
            out.append(f"  - post: {{chart: {chart}, event: {event}}}")
        if step.ticks > 1:  # the transition comes at the last chart step, not one sooner
            out.append(f"  - run: {{chart_steps: {step.ticks - 1}}}")
            out.append(f"  - expect: {dumps(' and '.join(f'{chart}.{leaf}' for leaf in before))}")
            out.append("  - run: {chart_steps: 1}")
        elif step.ticks:
            out.append(f"  - run: {{chart_steps: {step.ticks}}}")
        for condition in _expect(chart, step):
            out.append(f"  - expect: {dumps(condition)}")
        before = step.active
    out.append(f"  - expect_states: {{chart: {chart}, sequence: [{', '.join(scenario.leaves)}], match: exact}}")
    return "\n".join(out) + "\n"


def _name_part(scenario: GeneratedScenario) -> str:
    if not scenario.takes:
        return "no transition"
    first = scenario.takes[0].split(":")[0]
    return first if len(scenario.takes) == 1 else f"{first} and {len(scenario.takes) - 1} more"


def write(generated: Generated, out_dir: Path, command: str) -> list[Path]:
    """Write the scenario files into ``out_dir`` (made if missing); their paths."""
    out_dir.mkdir(parents=True, exist_ok=True)
    paths = []
    for k, scenario in enumerate(generated.scenarios, 1):
        path = out_dir / file_name(scenario, k)
        write_atomic(path, to_yaml(scenario, command))
        paths.append(path)
    generated.files = [str(p) for p in paths]
    return paths


__all__ = ["STRATEGIES", "Bounds", "Generated", "GeneratedScenario", "file_name", "generate", "to_yaml",
           "unreachable_reason", "write"]
