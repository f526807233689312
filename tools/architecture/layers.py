"""The layering contract of ``ttt_sm``, and the checker that holds the code to it.

The package is cut into *components* (a package, or a few modules of one),
stacked in *tiers*.  A component may import components of lower tiers only,
never one beside it in its own tier nor one above, and where it names an
``only`` list, only those.  Besides, no module may take part in an import
circle, even one made only of ``TYPE_CHECKING`` or function-level imports:
every ``import`` statement in the source counts, wherever it stands.

:data:`CONTRACT` is the contract; :func:`scan` reads the imports of a source
tree with :mod:`ast` (nothing is imported or run); :func:`check` returns
every import that breaks the contract and every circle, each named by file
and line.  ``tests/test_layers.py`` runs it on the package, and
``docs/architecture.md`` (``make docs``) draws it.

Why a checker of our own rather than import-linter: the contract needs
three things at once, tiers, per-component ``only`` lists and module-level
circles including ``TYPE_CHECKING`` imports, and the whole checker is ~250
lines of standard library that the tests can point at a synthetic package;
it adds no dependency to the package or to CI.
"""

from __future__ import annotations

import ast
from collections import defaultdict
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import ttt_sm

ROOT_PACKAGE = "ttt_sm"
SOURCE_ROOT = Path(ttt_sm.__file__).resolve().parent
"""The ``ttt_sm`` package folder this module was loaded from."""


@dataclass(frozen=True)
class Component:
    """A part of the package: the modules under ``prefixes``, in tier ``tier``.

    ``only``, when not ``None``, narrows what it may import to those
    components (all of a lower tier); ``None`` allows every lower tier.
    ``exact``: the prefixes name single modules, not their submodules.
    ``base``: every component may import it, those of its own tier too (only
    ``files``: the one way anything is written to disk); it imports nothing.
    """

    name: str
    tier: int
    prefixes: tuple[str, ...]
    role: str
    only: tuple[str, ...] | None = None
    exact: bool = False
    base: bool = False


#: Tier names, bottom up.
TIERS = ("foundations", "parts", "assemblies", "application", "tools", "views", "benchmarks", "command line")

CONTRACT: tuple[Component, ...] = (
    Component("package", 0, ("ttt_sm",), "the package's docstring and version", exact=True),
    Component("runtime", 0, ("ttt_sm.runtime",),
              "the Stateflow clock on python-statemachine, traces, diagrams, strict JSON: generic, no robot code"),
    Component("files", 0, ("ttt_sm.files",),
              "files a full disk cannot corrupt: records a whole line at a time, one writer each; pictures renamed"
              " into place", only=(), exact=True, base=True),
    Component("params", 0, ("ttt_sm.params", "ttt_sm.data"), "the arm's assumed physical values (arm.toml)"),
    Component("arm", 0, ("ttt_sm.arm",), "the Arm protocol the scheduler drives: the twin or a real arm"),
    Component("runner", 0, ("ttt_sm.runner",),
              "independent tasks here, on a local pool or a Dask cluster: the long sweeps and lab grade",
              only=()),
    Component("ptylink", 0, ("ttt_sm.ptylink",),
              "what every serial device shares: a raw pseudo-terminal behind a stable symlink (an emulator's port),"
              " an emulator's thread, the CRC-16", only=()),
    Component("charts", 1, ("ttt_sm.charts",), "the thesis' Stateflow charts", only=("runtime",)),
    Component("twin", 1, ("ttt_sm.twin",),
              "the digital twin: kinematics, plant, control, tuning, whiteboard", only=("params", "arm", "files")),
    Component("game", 1, ("ttt_sm.game",), "rules and engines of the game", only=("files",)),
    Component("smartcam", 1, ("ttt_sm.smartcam",), "the smart camera's serial line: protocol, reader, emulator",
              only=("ptylink",)),
    Component("vision", 1, ("ttt_sm.vision",), "cameras, the field's grid, detection, percent-process",
              only=("params", "files")),
    Component("sched", 2, ("ttt_sm.sched",), "clocks and the control-step scheduler, over the arm",
              only=("params", "arm", "twin")),
    Component("hardware", 2, ("ttt_sm.hardware",),
              "the real arm: the firmware's C built and loaded here, the link, the emulator, the serial Arm",
              only=("params", "arm", "twin", "ptylink", "files")),
    Component("vision staging", 2, ("ttt_sm.vision.scenes", "ttt_sm.vision.bench", "ttt_sm.vision.pictures"),
              "photos of boards drawn on the twin's whiteboard: the vision bench and docs pictures",
              only=("params", "twin", "vision", "files")),
    Component("app", 3, ("ttt_sm.app",), "the application: wires charts, scheduler, twin, camera and game"),
    Component("debug", 4, ("ttt_sm.debug",), "the step-through debugger"),
    Component("scenario", 4, ("ttt_sm.scenario",), "scenario tests of event sequences (YAML)"),
    Component("faults", 4, ("ttt_sm.faults",),
              "faults injected into the twin and the serial link; the Safety chart's fault matrices"),
    Component("lab", 5, ("ttt_sm.lab",), "the lab: exercises, a student's chart in a slot, behaviour checks"),
    Component("web", 5, ("ttt_sm.web",),
              "the browser cockpit (ttt-sm gui): a session over the debugger, its protocol, server and pages"),
    Component("bench", 6, ("ttt_sm.bench",), "the speed and quality targets",
              only=("package", "runtime", "runner", "params", "arm", "charts", "twin", "game", "smartcam", "vision",
                    "sched", "hardware",
                    "vision staging", "app", "debug", "scenario", "web", "lab")),
    Component("cli common", 4, ("ttt_sm.cli.common",), "the CLI's one-line error, options and strict JSON output",
              only=("runtime", "files")),
    Component("cli", 7, ("ttt_sm.cli",), "ttt-sm: parse, call, print; one module per command group"),
)


@dataclass(frozen=True)
class Import:
    """One import statement's target: ``source`` imports ``target`` at ``path:line``."""

    source: str
    target: str
    path: str
    line: int

    def where(self) -> str:
        return f"{self.path}:{self.line}"


@dataclass
class ImportGraph:
    """The modules of a source tree and the imports between them (within the package)."""

    modules: dict[str, Path] = field(default_factory=dict)
    imports: list[Import] = field(default_factory=list)

    def targets(self, module: str) -> set[str]:
        return {i.target for i in self.imports if i.source == module}


def _module_name(path: Path, root: Path) -> str:
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def scan(root: Path = SOURCE_ROOT) -> ImportGraph:
    """Every import between modules of the package at ``root`` (a folder named like the package).

    An ``import a.b`` or ``from a import b`` counts wherever it stands: at the
    top, in a function, under ``if TYPE_CHECKING``.  ``from pkg import name``
    is an import of the module ``pkg.name`` when there is one, else of ``pkg``.
    """
    graph = ImportGraph()
    files = sorted(root.rglob("*.py"))
    for path in files:
        graph.modules[_module_name(path, root)] = path
    package = root.name
    # paths as the repository names them (src/ttt_sm/...), else from the package's parent
    shown_from = root.parent.parent if root.parent.name == "src" else root.parent
    for path in files:
        module = _module_name(path, root)
        here = module if path.name == "__init__.py" else module.rpartition(".")[0]
        rel = path.relative_to(shown_from).as_posix()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    parts = here.split(".")
                    parts = parts[: len(parts) - (node.level - 1)]
                    target = ".".join(parts + ([node.module] if node.module else []))
                else:
                    target = node.module or ""
                targets = [f"{target}.{a.name}" if f"{target}.{a.name}" in graph.modules else target
                           for a in node.names]
            else:
                continue
            for target in dict.fromkeys(targets):
                if target == package or target.startswith(package + "."):
                    graph.imports.append(Import(module, target, rel, node.lineno))
    return graph


def component_of(module: str, contract: Sequence[Component] = CONTRACT) -> Component | None:
    """The component whose longest prefix matches ``module`` (``None``: outside the contract)."""
    best: tuple[int, Component] | None = None
    for comp in contract:
        for prefix in comp.prefixes:
            if module == prefix or (not comp.exact and module.startswith(prefix + ".")):
                if best is None or len(prefix) > best[0]:
                    best = (len(prefix), comp)
    return best[1] if best else None


def allowed(comp: Component, contract: Sequence[Component] = CONTRACT) -> list[str]:
    """Names of the components ``comp`` may import."""
    lower = [c.name for c in contract if c.tier < comp.tier or (c.base and c is not comp)]
    return lower if comp.only is None else [c for c in comp.only if c in lower]


def component_edges(graph: ImportGraph, contract: Sequence[Component] = CONTRACT) -> dict[tuple[str, str], int]:
    """(importer, imported) component names -> how many import statements, between different components."""
    counts: dict[tuple[str, str], int] = defaultdict(int)
    for imp in graph.imports:
        a, b = component_of(imp.source, contract), component_of(imp.target, contract)
        if a is not None and b is not None and a.name != b.name:
            counts[(a.name, b.name)] += 1
    return dict(counts)


def cycles(graph: ImportGraph) -> list[list[str]]:
    """The import circles among modules: each strongly connected set of two or more, sorted."""
    adjacency: Mapping[str, set[str]] = {m: graph.targets(m) & graph.modules.keys() for m in graph.modules}
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    counter = 0

    def visit(root: str) -> None:  # Tarjan's algorithm, iteratively (no recursion limit)
        nonlocal counter
        work = [(root, iter(sorted(adjacency[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            v, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter
                    counter += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(adjacency[child]))))
                elif child in on_stack:
                    low[v] = min(low[v], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                members = []
                while True:
                    w = stack.pop()
                    on_stack.discard(w)
                    members.append(w)
                    if w == v:
                        break
                if len(members) > 1:
                    found.append(sorted(members))

    for module in sorted(adjacency):
        if module not in index:
            visit(module)
    return sorted(found)


def check(graph: ImportGraph, contract: Sequence[Component] = CONTRACT,
          ignore_cycles: Iterable[frozenset[str]] = ()) -> list[str]:
    """Every breach of the contract in ``graph``, one readable line each (empty: the layers hold).

    ``ignore_cycles`` lists circles (as module sets) not to report.
    """
    problems = []
    for module in sorted(graph.modules):
        if component_of(module, contract) is None:
            problems.append(f"{module}: in no component of the layering contract; add it to CONTRACT")
    for imp in graph.imports:
        src, dst = component_of(imp.source, contract), component_of(imp.target, contract)
        if imp.target not in graph.modules:
            problems.append(f"{imp.where()}: {imp.source} imports {imp.target}, which is no module of the package")
        elif src is None or dst is None or src.name == dst.name:
            continue
        elif dst.name not in allowed(src, contract):
            if dst.tier > src.tier:
                why = f"{dst.name} ({TIERS[dst.tier]}) stands above {src.name} ({TIERS[src.tier]})"
            elif dst.tier == src.tier:
                why = f"{dst.name} stands beside {src.name} (both {TIERS[src.tier]})"
            else:
                why = f"{dst.name} is not among what {src.name} may import"
            may = ", ".join(allowed(src, contract)) or "nothing of the package"
            problems.append(f"{imp.where()}: {imp.source} imports {imp.target}, but {why}; "
                            f"{src.name} may import: {may}")
    skip = {frozenset(c) for c in ignore_cycles}
    for circle in cycles(graph):
        if frozenset(circle) in skip:
            continue
        members = set(circle)
        links = [f"{i.source} -> {i.target} ({i.where()})" for i in graph.imports
                 if i.source in members and i.target in members]
        problems.append(f"import circle among {', '.join(circle)}: {'; '.join(sorted(set(links)))}")
    return problems
