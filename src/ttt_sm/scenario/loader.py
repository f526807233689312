"""Read a scenario file and check it against the format and the charts it names.

Every mistake is a :class:`~.errors.ScenarioError` naming the file and the line:
an unknown step kind, chart, state, datum, event or signal (with the names
there are, and a guess at what was meant), a value of the wrong type, a missing
``timeout_s``, a condition that does not parse.  As a compiler does, the loader
reads the whole file and reports every mistake in one pass
(:class:`~.errors.ScenarioErrors`, one ``FILE:LINE: message`` each): a mistake
in one step does not hide those of the next; a mistake within a step stops
only that part of it (one key, one name of a list).  Only a mistake the rest
cannot be read without stops the reading: YAML that does not parse, a file
that is no mapping, ``chart:``/``charts:`` naming no chart.  Nothing runs before
the whole file is known to be right.

A scenario with ``chart: Name`` or ``charts: [A, B]`` (or ``charts: {a: A, b: A}``,
instances named by the scenario) runs those charts alone
(bare-chart mode): its steps may name only them, read only ``t`` of the
signals, and neither pose an arm (``start``) nor force inputs (nothing feeds
them).

The checker comes in three layers, one module each: :mod:`.names` (the names
and values a file may use, and how a mistake is named), :mod:`.steps` (one
method per step kind) and this module (the file as a whole: its top keys,
bare charts and ``start``).
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Any

from ..runtime import TickChart
from ..runtime.conditions import KEYWORDS
from ..runtime.errors import suggest
from .errors import ScenarioErrors
from .model import BareCharts, Catalog, Scenario, Start, Where
from .names import is_number, short_repr, type_name
from .source import MarkedDict, MarkedList, load_yaml, load_yaml_file
from .steps import StepReader

TOP_KEYS = ("name", "description", "chart", "charts", "seed", "max_step_s", "start", "steps")


class _Checker(StepReader):
    """Turns the YAML data of one file into a :class:`Scenario`, or raises with every mistake in it."""

    # -- top level -------------------------------------------------------------------

    def scenario(self, doc: Any) -> Scenario:
        """The scenario, or :class:`ScenarioError` (one mistake) / :class:`ScenarioErrors` (several)."""
        scenario: Scenario | None = None
        with self.going_on():  # a mistake that stops the reading is the last one noted
            scenario = self.whole(doc)
        if self.mistakes or scenario is None:
            raise ScenarioErrors.of(self.mistakes)
        return scenario

    def whole(self, doc: Any) -> Scenario | None:
        if not isinstance(doc, MarkedDict):
            line = getattr(doc, "line", 1)
            raise self.error(line, "a scenario file is a mapping with name: and steps: (got "
                                   f"{type_name(doc)})")
        unknown = [k for k in doc if k not in TOP_KEYS]
        with self.going_on():
            self.keys(doc, TOP_KEYS, "scenario")
        for key in ("name", "steps"):
            if key not in doc and not any(suggest(k, (key,)) for k in unknown):  # 'step:' is told once
                self.mistakes.append(self.error(doc.line, f"missing {key}:"))
        name, description, seed, start = "", "", 0, Start()
        with self.going_on():
            name = self.text(doc, "name") if "name" in doc else ""
        with self.going_on():
            description = self.text(doc, "description") if "description" in doc else ""
        with self.going_on():
            seed = doc.get("seed", 0)
            if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
                raise self.error(doc.line_of("seed"),
                                 f"seed: expected a whole number >= 0, got {type_name(seed)}")
        with self.going_on():
            if "max_step_s" in doc:
                self.max_step_s = self.number(doc, "max_step_s", "max_step_s", bounded=False)
        self.bare = self.bare_charts(doc)  # the steps cannot be checked without knowing their charts
        with self.going_on():
            if self.bare is not None:
                self.charts = self.bare.charts
                if "start" in doc:
                    raise self.error(doc.line_of("start"), f"start: {self.bare_mode}, without the arm: there"
                                                           " is no pose to start from")
            start = self.start(doc["start"], doc.line_of("start")) if "start" in doc else Start()
        if "steps" not in doc:
            return None
        steps_data = doc["steps"]
        if not isinstance(steps_data, MarkedList) or not steps_data:
            raise self.error(doc.line_of("steps"), "steps: expected a list of steps, each starting with '- '")
        steps = []
        for item, line in zip(steps_data, steps_data.item_lines, strict=True):
            with self.going_on():  # each step on its own: a mistake in one does not hide the next's
                steps.append(self.step(item, line))
        if self.mistakes:
            return None
        return Scenario(name=name, file=self.file, steps=tuple(steps), description=description, seed=seed,
                        start=start, where=Where(self.file, doc.line), bare=self.bare, max_step_s=self.max_step_s)

    def bare_charts(self, doc: MarkedDict) -> BareCharts | None:
        """The charts to run alone, or None for the robot.

        ``chart: Game``; ``charts: [AlgorithmActivator, Game]``; or, for several
        instances of one chart, names of one's own: ``charts: {early: Game, late: Game}``.
        """
        given = [k for k in ("chart", "charts") if k in doc]
        if not given:
            return None
        if len(given) == 2:
            raise self.error(doc.line_of("charts"), "chart: and charts: exclude each other: one chart is"
                                                    " chart: Name, several are charts: [A, B]")
        key = given[0]
        value, line = doc[key], doc.line_of(key)
        pairs: list[tuple[Any, Any, int]]  # (name in the steps, chart class name, line)
        if key == "chart" and isinstance(value, str):
            pairs = [(value, value, line)]
        elif key == "charts" and isinstance(value, MarkedList) and value:
            pairs = [(n, n, n_line) for n, n_line in zip(value, value.item_lines, strict=True)]
        elif key == "charts" and isinstance(value, MarkedDict) and value:
            pairs = [(n, c, value.line_of(n)) for n, c in value.items()]
        else:
            raise self.error(line, f"{key}: expected a chart name like chart: Game, a list like charts:"
                                   " [AlgorithmActivator, Game], or names of one's own like charts:"
                                   f" {{early: Game, late: Game}}; got {type_name(value)}")
        known = self.catalog.charts
        charts: dict[str, type[TickChart]] = {}
        for name, chart, n_line in pairs:
            if not isinstance(chart, str) or chart not in known:
                raise self.error(n_line, f"{key}: unknown chart {short_repr(chart)}{suggest(chart, known)};"
                                         f" charts: {', '.join(known)}")
            if not isinstance(name, str) or not name.isidentifier() or name in KEYWORDS:
                raise self.error(n_line, f"charts: {short_repr(name)} cannot name a chart in a condition: use letters,"
                                         " digits and _")
            if name in known and name != chart:
                raise self.error(n_line, f"charts: {name} is the name of a chart: name the {chart} otherwise")
            if name in charts:
                raise self.error(n_line, f"charts: {name} is listed twice")
            charts[name] = known[chart]
        return BareCharts(charts, Where(self.file, line))
    def start(self, data: Any, line: int) -> Start:
        if not isinstance(data, MarkedDict):
            raise self.error(line, "start: expected a mapping with q_deg: and settle_s:,"
                                   f" got {type_name(data)}")
        self.keys(data, ("q_deg", "settle_s"), "start")
        q_deg: tuple[float, ...] | None = None
        if "q_deg" in data:
            q = data["q_deg"]
            if not isinstance(q, list) or len(q) not in (3, 4) or not all(is_number(v) for v in q):
                raise self.error(data.line_of("q_deg"), "start: q_deg expected a list of 3 or 4 joint"
                                                        f" angles in degrees (q1, q2, q3[, q4]), got {short_repr(q)}")
            q_deg = tuple(float(v) for v in q) + ((0.0,) if len(q) == 3 else ())
        settle = self.number(data, "settle_s", "start", positive=False) if "settle_s" in data else 0.0
        return Start(q_deg=q_deg, settle_s=settle, where=Where(self.file, data.line))

    # -- steps -------------------------------------------------------------------------


def load_scenario_text(text: str, file: str = "<scenario>", catalog: Catalog | None = None) -> Scenario:
    """Load a scenario from YAML text (``file`` names it in errors)."""
    return _Checker(file, catalog or Catalog.default()).scenario(load_yaml(text, file))


def load_scenario(path: str | Path, catalog: Catalog | None = None) -> Scenario:
    """Load and check a scenario file; raise :class:`ScenarioError` naming the file and line."""
    return _Checker(str(path), catalog or Catalog.default()).scenario(load_yaml_file(path))


def scenario_files(paths: Iterable[str | Path]) -> list[Path]:
    """The scenario files named: files as given, folders as their ``*.yaml``/``*.yml`` files, sorted."""
    out: list[Path] = []
    for p in map(Path, paths):
        try:
            folder = p.is_dir()
        except OSError:  # a name too long: reading it as a file says so
            folder = False
        if folder:
            out += sorted(f for f in p.iterdir() if f.suffix in (".yaml", ".yml") and f.is_file())
        else:
            out.append(p)
    return out
