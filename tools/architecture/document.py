"""``docs/architecture.md``: how the package is put together, generated from the code.

The page is a list of *sections* (:data:`SECTIONS`), each a function that
returns its Markdown and may add Graphviz pictures through the
:class:`Pictures` it is given.  To add a section, write such a function
(anywhere the layering contract lets this module import) and add it to
:data:`SECTIONS`; ``make docs`` writes the page and its pictures,
and ``tests/docs/test_architecture_doc.py`` fails when they are stale.

The pictures are SVG files in ``docs/img/``, stamped with the hash of the
DOT source they were drawn from (:func:`ttt_sm.runtime.export.svg_from_dot`),
so the staleness check needs no Graphviz and does not trip over another
Graphviz version.
"""

from __future__ import annotations

import ast
import functools
import inspect
import re
import textwrap
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from ttt_sm.runtime.export import dot_sha256, svg_dot_sha256, svg_from_dot

from .layers import CONTRACT, TIERS, ImportGraph, allowed, component_edges, component_of, cycles, scan

PAGE = Path("docs") / "architecture.md"
"""Where the page lives in the repository."""
IMAGE_DIR = Path("docs") / "img"
"""Where its pictures live."""
IMAGE_PREFIX = "architecture_"


@dataclass
class Pictures:
    """The Graphviz pictures of the page: file name -> DOT source."""

    dot: dict[str, str] = field(default_factory=dict)

    def add(self, name: str, dot_source: str, alt: str) -> str:
        """Register ``docs/img/architecture_<name>.svg``; return the Markdown that shows it."""
        filename = f"{IMAGE_PREFIX}{name}.svg"
        if filename in self.dot:
            raise ValueError(f"two pictures named {filename}")
        self.dot[filename] = dot_source
        return f"![{alt}](img/{filename})"


Section = Callable[[Pictures], str]
"""A section of the page: Markdown (starting with its ``##`` heading), given the page's pictures."""


def _quote(text: str) -> str:
    """A DOT string; a ``\\n`` in ``text`` stays DOT's line break."""
    return '"' + text.replace('"', '\\"') + '"'


def layers_dot(graph: ImportGraph) -> str:
    """The components in their tiers (top: the command line) and the imports between them, as DOT.

    The command line's arrows are left out (it imports nearly every component;
    the table lists them); every other import between components is an arrow.
    """
    edges = component_edges(graph)
    lines = ["digraph layers {", "  rankdir=TB; newrank=true; nodesep=0.3; ranksep=0.55;",
             '  node [shape=box, style="rounded,filled", fillcolor="#f4f4f4", fontname="Helvetica", fontsize=11];',
             '  edge [color="#556b8d", arrowsize=0.6];']
    tiers = [[c for c in CONTRACT if c.tier == t] for t in range(len(TIERS))]
    for tier in reversed(range(len(TIERS))):
        lines.append(f"  subgraph cluster_tier{tier} {{")
        lines.append(f'    label={_quote(f"{tier} {TIERS[tier]}")}; labeljust=l; fontname="Helvetica"; '
                     'fontsize=10; style=dashed; color="#aaaaaa";')
        lines.append("    rank=same; " + " ".join(_quote(c.name) + ";" for c in tiers[tier]))
        lines.append("  }")
    for upper, lower in zip(tiers[1:], tiers[:-1], strict=False):  # keep the tiers stacked in order
        lines.append(f"  {_quote(upper[0].name)} -> {_quote(lower[0].name)} [style=invis];")
    for (a, b), n in sorted(edges.items()):
        if a == "cli":
            continue
        width = 1.0 + min(n, 12) / 6
        lines.append(f"  {_quote(a)} -> {_quote(b)} [penwidth={width:.2f}, tooltip={_quote(f'{n} imports')}];")
    lines.append("}")
    return "\n".join(lines) + "\n"


def layers_section(pictures: Pictures) -> str:
    """The layering contract: the picture drawn from the real imports, the table, the circles."""
    graph = scan()
    edges = component_edges(graph)
    picture = pictures.add("layers", layers_dot(graph), "components in tiers and the imports between them")
    rows = ["| tier | component | modules | may import | imports now | what it is |", "|---|---|---|---|---|---|"]
    for comp in sorted(CONTRACT, key=lambda c: (-c.tier, CONTRACT.index(c))):
        may = allowed(comp)
        may_text = ("everything below" if comp.only is None else ", ".join(may)) if may else "nothing of the package"
        now = sorted(b for (a, b) in edges if a == comp.name)
        mods = ", ".join(f"`{p}`" for p in comp.prefixes)
        rows.append(f"| {comp.tier} {TIERS[comp.tier]} | **{comp.name}** | {mods} | {may_text} | "
                    f"{', '.join(now) or '—'} | {comp.role} |")
    found = cycles(graph)
    circles = ("None: no module imports, even for type checking or inside a function, a module that "
               "imports it back." if not found else
               "Known, to be removed (the layering test names each):\n\n"
               + "\n".join(f"- {' <-> '.join(f'`{m}`' for m in c)}" for c in found))
    return f"""## The layers

The package is cut into components stacked in tiers. A component may import
components of lower tiers only: never one beside it in its own tier, never
one above; where the table lists what it may import, only those. One
exception: `files` (how anything is written to disk, so that a full disk
leaves whole lines and whole pictures) imports nothing and may be imported
from every tier, its own too. The rule
is code, `tools.architecture.layers.CONTRACT` (a development tool of the repository,
not in the installed package), and `tests/test_layers.py`
holds the source to it with an `ast` scan of every `import` statement
(top-level, in functions and under `TYPE_CHECKING` alike); it also feeds the
checker a copy of the package with a wrong import, to show that it fails and
names the file and line. A module belongs to the component with the longest
prefix that names it (so `ttt_sm.vision.scenes` is vision staging, not
vision).

{picture}

*Drawn from the imports in the source: an arrow is "imports", its width the
number of import statements. The command line's arrows are left out: it
imports nearly every component (the table lists them).*

{chr(10).join(rows)}

In words: the runtime is generic and imports no robot code; the charts use
only the runtime; the twin uses the parameters and the `Arm` protocol, never
the charts, the scheduler or the application; the game and the serial link
stand alone; vision's camera and detection use only the parameters (the
simulated camera photographs any `Photographable` board, which the twin's
whiteboard is), while the vision bench's staging modules use the twin to draw
the boards they photograph. The application wires them; the debugger,
scenarios and benches are tools over it; the command line sits on top, its
subcommand modules importing only `cli.common` from it.

**Import circles.** {circles}
"""


@dataclass(frozen=True)
class StageFacts:
    """What one stage of the control step is and touches, read from its class."""

    name: str
    kind: str  # "task" or "joint"
    doc: str
    reads: tuple[str, ...]  # Signals fields
    writes: tuple[str, ...]
    arm: tuple[str, ...]  # Arm members
    truth: bool  # reads the simulation's ground truth


def _first_line(obj: object) -> str:
    return (inspect.getdoc(obj) or "").strip().splitlines()[0] if inspect.getdoc(obj) else ""


def arm_members() -> list[str]:
    """The members of the :class:`~ttt_sm.arm.Arm` protocol, in declaration order."""
    from ttt_sm.arm import Arm

    names = list(getattr(Arm, "__annotations__", {}))
    names += [n for n in vars(Arm) if not n.startswith("_") and n not in names]
    return names


def _arm_uses(tree: ast.AST, members: set[str]) -> set[str]:
    """Arm members used as ``arm.<m>`` or ``<x>.arm.<m>``."""
    used = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Attribute) and node.attr in members:
            owner = node.value
            name = owner.id if isinstance(owner, ast.Name) else owner.attr if isinstance(owner, ast.Attribute) else ""
            if name == "arm":
                used.add(node.attr)
    return used


def _stage_facts(stage: object, kind: str, members: set[str]) -> StageFacts:
    cls = type(stage)
    owner = next(c for c in cls.__mro__ if "tick" in vars(c))  # the class that defines tick
    tree = ast.parse(textwrap.dedent(inspect.getsource(owner)))
    reads: set[str] = set()
    writes: set[str] = set()
    tick = next(n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef) and n.name == "tick")
    signals = tick.args.args[1].arg
    for node in ast.walk(tick):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == signals:
            (writes if isinstance(node.ctx, ast.Store) else reads).add(node.attr)
    truth = any(isinstance(n, ast.Attribute) and n.attr == "truth" for n in ast.walk(tree))
    order = {m: k for k, m in enumerate(sorted(members))}
    return StageFacts(cls.__name__, kind, _first_line(cls), tuple(sorted(reads)), tuple(sorted(writes)),
                      tuple(sorted(_arm_uses(tree, members), key=order.__getitem__)), truth)


@functools.cache
def control_step_facts() -> tuple[int, tuple[StageFacts, ...], dict[str, tuple[str, ...]]]:
    """The default robot's chart divider, its stages in order, and who uses each Arm member.

    Built from a real :class:`~ttt_sm.app.robot.Robot` (the stages the
    application plugs into the scheduler) and an ``ast`` scan of the modules
    that import the Arm protocol.
    """
    from ttt_sm.app.robot import Robot
    from ttt_sm.params import load_params

    members = set(arm_members())
    robot = Robot(load_params())
    stages = tuple([_stage_facts(s, "task", members) for s in robot.sched.task_stages]
                   + [_stage_facts(s, "joint", members) for s in robot.sched.joint_stages])
    graph = scan()
    users: dict[str, set[str]] = {m: set() for m in members}
    for module in sorted(graph.modules):
        if any(t == "ttt_sm.arm" or t.startswith("ttt_sm.arm.") for t in graph.targets(module)):
            tree = ast.parse(graph.modules[module].read_text(encoding="utf-8"))
            for m in _arm_uses(tree, members):
                users[m].add(module.removeprefix("ttt_sm."))
    return robot.sched.divider, stages, {m: tuple(sorted(u)) for m, u in users.items()}


def control_step_dot(divider: int, stages: Sequence[StageFacts]) -> str:
    """One control step as a flow: the scheduler's fixed parts around the stages the application plugs in."""
    def node(name: str, label: str, fill: str) -> str:
        return f'  {_quote(name)} [label={_quote(label)}, fillcolor="{fill}"];'

    def stage_label(st: StageFacts) -> str:
        arm = "\\n".join(f"arm.{m}" for m in st.arm)
        out = f"\\nsets {', '.join(st.writes)}" if st.writes else ""
        extra = "\\nreads ground truth\\n(simulation only)" if st.truth else ""
        return f"{st.name}\\n({st.kind} stage){out}" + (f"\\n{arm}" if arm else "") + extra

    lines = ["digraph step {", "  rankdir=LR; nodesep=0.3; ranksep=0.35;",
             '  node [shape=box, style="rounded,filled", fontname="Helvetica", fontsize=10];',
             '  edge [color="#556b8d", arrowsize=0.6, fontname="Helvetica", fontsize=9];']
    chain = ["start"]
    lines.append(node("start", f"chart step\\n(1 control step in {divider})\\nsignals.t = arm.t", "#e8eef7"))
    for st in [s for s in stages if s.kind == "task"]:
        lines.append(node(st.name, stage_label(st), "#fdf3dc"))
        chain.append(st.name)
    lines.append(node("ik", "inverse kinematics\\ntask -> q_des\\n(IKSolver.solve_pose;\\nholds on failure)",
                      "#e8eef7"))
    chain.append("ik")
    for st in [s for s in stages if s.kind == "joint"]:
        lines.append(node(st.name, stage_label(st), "#fdf3dc"))
        chain.append(st.name)
    lines.append(node("clamp", "clamp q_set to the\\njoint limits of\\nhomed drives", "#e8eef7"))
    lines.append(node("set", "arm.set_setpoints\\n(q_set, fr_sw)", "#e3f1e3"))
    lines.append(node("step", f"arm.step(1) x {divider}\\nfilters, cascade control,\\nplant (or the hardware)",
                      "#e3f1e3"))
    chain += ["clamp", "set", "step"]
    for a, b in zip(chain, chain[1:], strict=False):
        lines.append(f"  {_quote(a)} -> {_quote(b)};")
    lines.append('  "step" -> "start" [style=dashed, label="next chart step", constraint=false];')
    lines.append("}")
    return "\n".join(lines) + "\n"


def control_step_section(pictures: Pictures) -> str:
    """One control step through the ``Arm`` interface: the scheduler's stages and the protocol's members."""
    from ttt_sm.arm import Arm

    divider, stages, users = control_step_facts()
    picture = pictures.add("control_step", control_step_dot(divider, stages), "one control step")
    stage_rows = ["| order | stage | kind | reads | sets | Arm members | what it is |", "|---|---|---|---|---|---|---|"]
    for k, st in enumerate(stages, 1):
        arm = ", ".join(f"`{m}`" for m in st.arm) or "—"
        if st.truth:
            arm += " (and the simulation's ground truth)"
        stage_rows.append(f"| {k} | `{st.name}` | {st.kind} | {', '.join(st.reads) or '—'} | "
                          f"{', '.join(st.writes) or '—'} | {arm} | {st.doc} |")
    arm_rows = ["| member | what it is | used by |", "|---|---|---|"]
    for m in arm_members():
        doc = _first_line(getattr(Arm, m)) if m in vars(Arm) else "The control step, s."
        who = ", ".join(f"`{u}`" for u in users.get(m, ())) or "— (not called by the package's code)"
        arm_rows.append(f"| `{m}` | {doc} | {who} |")
    return f"""## One control step

The scheduler (`ttt_sm.sched.scheduler.Scheduler`) drives an arm through
the `Arm` protocol (`ttt_sm.arm`): the simulated arm (`ArmSim`) or, one
day, a hardware backend. It never reads the simulation's ground truth; a
stage that needs it (the whiteboard's ink) gets it from the application,
apart from the protocol. Every `chart_divider`-th control step is a chart
step: the task stages produce the tool pose, inverse kinematics turns it into
joint setpoints, the joint stages pass or replace them, the setpoints are
clamped to the joint limits and go to the arm; then the arm advances one
control step (its setpoint filters, cascade controllers and plant, or the
microcontroller).

{picture}

*Drawn from the stages the application plugs into the scheduler (a default
`ttt_sm.app.robot.Robot`) and what their code reads and sets of the
signals and calls of the arm.*

{chr(10).join(stage_rows)}

The `Arm` protocol, and which modules use each member:

{chr(10).join(arm_rows)}
"""


def conventions_section(pictures: Pictures) -> str:
    """What every part keeps to at its edges: errors and JSON."""
    del pictures
    return """## Conventions at the edges

- **Errors.** Bad input raises an exception that names what and where
  (`ParameterError`, `ScenarioError`, `DebugError`, `VisionError`, ...); the
  command line prints it as one line, `ttt-sm <command>: error: ...`, and
  exits with status 2 (`ttt_sm.cli.common.CliError` for its own checks).
  Names that are near a known one get a "did you mean" from
  `ttt_sm.runtime.errors.suggest`, the one helper for it.
- **Strict JSON.** Every `--json` document, trace line and game record is
  written by `ttt_sm.runtime.jsonable.dumps`: NaN and infinity become `null`
  and `allow_nan=False` makes any that slipped through an error. JSON has no
  NaN: Python would write a bare `NaN`, which `jq`, browsers and most JSON
  libraries refuse, so one unset datum (a chart output that is NaN until the
  arm is initialised) would make a whole document unreadable.
  `tests/test_strict_json.py` fails on any `json.dumps` in the package that
  does not pass `allow_nan=False`.
"""


def wiring_section(pictures: Pictures) -> str:
    """How the charts are wired: the table of ``ttt_sm.app.wires``, drawn (the picture of charts/)."""
    del pictures  # the pictures are charts/wiring_<part>.svg, written and checked with the charts' diagrams
    from ttt_sm.app.wiring_diagram import wiring_section as section

    return section("../charts/")


#: Thesis figure or section -> where it lives: the parts a reader looks for first (docs/thesis_map.md has
#: every figure and equation).  Each module named here is checked to exist when the page is drawn.
THESIS_MODULES: tuple[tuple[str, str, str], ...] = (
    ("§3.1.2, figs. 3.2-3.4", "the drive-initialisation charts", "ttt_sm.charts.drive_init"),
    ("§3.6.1, figs. 3.23-3.25", "the Control chart: its sub-charts, start_stop, wait_1", "ttt_sm.charts.control"),
    ("§3.6.1, figs. 3.26-3.27", "its drawing sub-charts: the field, the X, the four-arc O (and the sine)",
     "ttt_sm.charts.control_drawing"),
    ("§3.6.1 (Erase)", "its erasing and finishing sub-charts", "ttt_sm.charts.control_erase"),
    ("eqs. 3.36-3.51", "the geometry of the field, the X and the O", "ttt_sm.charts.geometry"),
    ("§3.6.2, fig. 3.30", "the algorithm activator and the game flow", "ttt_sm.charts.game"),
    ("(Stateflow)", "how every chart runs: one wake-up, junctions, local events, temporal logic",
     "ttt_sm.runtime.engine"),
    ("eqs. 3.17-3.21, 3.25", "forward kinematics", "ttt_sm.twin.kinematics.chain"),
    ("§3.4", "inverse kinematics (damped least squares)", "ttt_sm.twin.kinematics.dls"),
    ("§3.2, figs. 3.5-3.6", "the cascade per drive: position PID, speed PID, filtered encoder derivative",
     "ttt_sm.twin._cascade"),
    ("§3.2 (gains)", "the gains, designed with python-control, and their margins", "ttt_sm.twin.tuning"),
    ("figs. 3.7-3.9", "step responses of drives 1-3", "ttt_sm.twin.step_response"),
    ("fig. 3.25 (fr_sw)", "the setpoint filters and their cut-off switch", "ttt_sm.twin.gains"),
    ("§3.3", "the pen servo's duty and angle", "ttt_sm.params.values"),
    ("(the loop's memory)", "the layouts of the controller's and the plant's flat arrays", "ttt_sm.twin.layout"),
    ("§3.1.2 note (1 kHz, charts at half rate)", "controller and plant fused in one compiled loop",
     "ttt_sm.twin._kernel"),
    ("(beyond the thesis)", "the firmware's C step loaded on the PC; the firmware on the twin's plant",
     "ttt_sm.hardware.emulator"),
    ("§3.5, figs. 3.14-3.19", "drawing precision", "ttt_sm.app.drawing"),
    ("§3.7, figs. 3.35-3.36", "the Tic-tac-toe GUI and the Operational GUI", "ttt_sm.web"),
)


def thesis_section(pictures: Pictures) -> str:
    """From the thesis to the modules, and the files generated from a single definition."""
    import importlib

    del pictures
    rows = ["| thesis | what | module |", "|---|---|---|"]
    for where, what, module in THESIS_MODULES:
        importlib.import_module(module)  # a renamed module fails here, not on the page
        rows.append(f"| {where} | {what} | `{module}` |")
    from ttt_sm.hardware import generate

    generated = "\n".join(f"- `firmware/{path}` from `{tables}` (`ttt_sm.hardware.generate`)"
                          for path, _, tables in generate.FILES)
    return f"""## From the thesis to the modules

Where the thesis' parts live (docs/thesis_map.md maps every figure and
equation). The cascade loop spans several modules on purpose: one
definition of each formula (`ttt_sm.twin._cascade` for the controller step and
the setpoint filter, `ttt_sm.twin._plant` for gravity, `ttt_sm.params.values` for the
servo), one table of each memory layout (`ttt_sm.twin.layout`) and of the
serial link's protocol (`ttt_sm.hardware.link.protocol`), the design of
the gains apart from the step that uses them (`ttt_sm.twin.tuning`,
`ttt_sm.twin.gains`), and the loop that fuses controller and plant
(`ttt_sm.twin._kernel`).

{chr(10).join(rows)}

### Generated files

Written from one definition, and checked by `make docs CHECK=1` (and a test)
so that a stale copy fails rather than drifts:

- `charts/`: every chart's diagrams and page, from the chart classes (`ttt_sm.runtime.export`)
- `docs/architecture.md` and its pictures: this page, from the code (`tools.architecture.document`)
{generated}
"""


#: Above this many lines a module is flagged in the module map: a file that grows past a few hundred lines
#: usually holds two ideas.
LONG_MODULE = 500
#: A full stop that ends a sentence: not the one of "figs.", "eq.", "e.g." or "i.e.".
_SENTENCE_END = re.compile(r"(?<!\bfigs)(?<!\bfig)(?<!\beqs)(?<!\beq)(?<!\be\.g)(?<!\bi\.e)\.\s")


def _module_summary(path: Path) -> tuple[int, str]:
    """A module's length in lines and the first sentence of its docstring (read with ``ast``, not imported)."""
    text = path.read_text(encoding="utf-8")
    doc = ast.get_docstring(ast.parse(text)) or ""
    first = " ".join(doc.strip().split("\n\n")[0].split())
    end = _SENTENCE_END.search(first)
    return len(text.splitlines()), (first[:end.start() + 1] if end else first).replace("|", "\\|")


def modules_section(pictures: Pictures) -> str:
    """Every module of the package by component, with its length and what it holds (its docstring's first
    sentence): the layout of the code, a module per idea."""
    del pictures
    graph = scan()
    by_component: dict[str, list[str]] = {}
    for module in sorted(graph.modules):
        comp = component_of(module)
        by_component.setdefault(comp.name if comp else "(outside the contract)", []).append(module)
    blocks = []
    for comp in sorted(CONTRACT, key=lambda c: (-c.tier, CONTRACT.index(c))):
        modules = by_component.get(comp.name, [])
        if not modules:
            continue
        rows = ["| module | lines | what it holds |", "|---|---|---|"]
        for module in modules:
            lines, what = _module_summary(graph.modules[module])
            flag = f"**{lines}**" if lines > LONG_MODULE else str(lines)
            rows.append(f"| `{module}` | {flag} | {what or '—'} |")
        count = f"{len(modules)} module{'s' * (len(modules) > 1)}"
        blocks.append(f"<details><summary><b>{comp.name}</b>: {count}</summary>\n\n" + "\n".join(rows)
                      + "\n\n</details>")
    longest = max(_module_summary(path)[0] for path in graph.modules.values())
    return f"""## The modules

Each component's modules, with their length and the first sentence of their
docstring, read from the source (a module per idea: a length over
{LONG_MODULE} lines is in bold; the longest now has {longest}).

{(chr(10) * 2).join(blocks)}
"""


#: The sections of docs/architecture.md, in order.  Add yours here.
SECTIONS: list[Section] = [layers_section, control_step_section, wiring_section, thesis_section, modules_section,
                           conventions_section]


def render() -> tuple[str, dict[str, str]]:
    """The page's Markdown and its pictures (file name -> DOT source)."""
    pictures = Pictures()
    body = "\n".join(section(pictures) for section in SECTIONS)
    head = """# Architecture

<!-- generated by tools.architecture.document (`make docs`); do not edit -->

How `ttt_sm` is put together, drawn from the code: which part may use which,
and how the parts meet. The parts themselves have their own pages in this
folder; the thesis' charts are in [charts/](../charts/index.md).

"""
    return head + body, pictures.dot


def export(root: Path | str = ".") -> list[Path]:
    """Write ``docs/architecture.md`` and its pictures under the repository ``root``; return the paths."""
    root = Path(root)
    text, dots = render()
    page = root / PAGE
    page.parent.mkdir(parents=True, exist_ok=True)
    (root / IMAGE_DIR).mkdir(parents=True, exist_ok=True)
    page.write_text(text, encoding="utf-8")
    written = [page]
    for name, dot in dots.items():
        path = root / IMAGE_DIR / name
        path.write_text(svg_from_dot(dot), encoding="utf-8")
        written.append(path)
    return written


def stale(root: Path | str = ".") -> list[str]:
    """Files :func:`export` would write differently (pictures: by the hash of their DOT source)."""
    root = Path(root)
    text, dots = render()
    page = root / PAGE
    out = [] if page.is_file() and page.read_text(encoding="utf-8") == text else [str(page)]
    for name, dot in dots.items():
        path = root / IMAGE_DIR / name
        if not path.is_file() or svg_dot_sha256(path.read_text(encoding="utf-8")) != dot_sha256(dot):
            out.append(str(path))
    return out
