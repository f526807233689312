"""Coverage colouring: which states were entered and which transitions taken, per chart of the session.

Two sources, one result: scenario files run from the page (the scenario
runner's :class:`~ttt_sm.runtime.listeners.Coverage`, as ``ttt-sm scenario
run --coverage``), or a report that command wrote with ``--json``.  A report
names charts by class, states by id and transitions by their stable label
(``"off -> on: tick [sw]"``); :func:`colouring` turns it into the session's
chart names, state ids and transition indices, the numbers its diagram edges
carry, and refuses a report that names a state or transition the charts do not
have (a report of other charts, or of an older version of them).

:class:`CoverageRuns` runs the scenarios a page asks for on a worker thread of
its own, one run at a time, beside the simulation (a run takes seconds), and
keeps the colouring the pages show.  On the same worker it answers a page that
asks for a transition never taken (:meth:`CoverageRuns.suggest`): the shortest
generated scenario that takes it, as ``ttt-sm scenario run --coverage
--suggest`` writes it (:func:`~ttt_sm.scenario.generate.generate`, searched
once per chart and kept), or the generator's reason why none does.
"""

from __future__ import annotations

import contextlib
import logging
import queue
import re
import threading
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from ..params import ArmParams
from ..runtime import TickChart
from ..scenario.errors import ScenarioError
from ..scenario.generate import Generated, generate, to_yaml
from ..scenario.loader import load_scenario, load_scenario_text
from ..scenario.model import Scenario
from ..scenario.runner import ScenarioResult
from ..scenario.suite import coverage_dict, run_scenarios

log = logging.getLogger(__name__)

#: Wall time one coverage run (its scenarios) or one suggestion search may take; past it the run stops and
#: the page is told.  A stop of the session ends it too, within a few simulated seconds of its run.
COVERAGE_LIMIT_S = 300.0


class CoverageError(ValueError):
    """A coverage report that does not fit the session's charts, or scenarios that cannot run."""


class CoverageStopped(BaseException):
    """A coverage run ended from outside: the session stops, or the run had its :data:`COVERAGE_LIMIT_S`.

    A ``BaseException``, so the scenario runner, which reports a step's ``Exception`` as the step's
    failure and goes on, lets it through."""


def colouring(report: Mapping[str, Any], charts: Mapping[str, type[TickChart]]) -> dict[str, Any]:
    """Per chart of the session: the states entered and the transitions taken, and what was never.

    ``report`` is the ``coverage`` object of ``ttt-sm scenario run --coverage
    --json`` (or that whole document).  Returns ``{"charts": {name: {"entered":
    [ids], "missing_states": [ids], "taken": [indices], "missing_transitions":
    [indices], "states": "n/m", "transitions": "n/m"}}, "ignored": [class names]}``.
    """
    if "coverage" in report and isinstance(report["coverage"], dict):
        report = report["coverage"]
    by_class = {cls.__name__: name for name, cls in charts.items()}
    out: dict[str, Any] = {}
    ignored = []
    for cls_name, entry in report.items():
        if cls_name not in by_class:
            ignored.append(str(cls_name))
            continue
        if not isinstance(entry, dict):
            raise CoverageError(f"coverage report: {cls_name} must be an object with 'entered' and 'taken'"
                                " (or 'missing_states' and 'missing_transitions')")
        name = by_class[cls_name]
        structure = charts[name].structure()
        states = [s.id for s in structure.states if not s.history]
        labels: dict[str, list[int]] = {}
        for t in structure.transitions:
            labels.setdefault(t.label, []).append(t.index)
        entered = _names(entry, cls_name, "entered", "missing_states", states)
        taken_labels = _names(entry, cls_name, "taken", "missing_transitions", list(labels))
        taken = sorted(i for label in taken_labels for i in labels[label])
        out[name] = {
            "entered": [s for s in states if s in entered],
            "missing_states": [s for s in states if s not in entered],
            "taken": taken,
            "missing_transitions": [t.index for t in structure.transitions if t.index not in set(taken)],
            "states": f"{len(entered)}/{len(states)}",
            "transitions": f"{len(set(taken_labels))}/{len(labels)}",
        }
    if not out:
        raise CoverageError("coverage report: it covers none of this session's charts"
                            f" ({', '.join(charts)}); it names {', '.join(map(str, report)) or 'nothing'}")
    return {"charts": out, "ignored": ignored}


def _names(entry: dict[str, Any], chart: str, key: str, missing_key: str, known: Sequence[str]) -> set[str]:
    """The names a report lists under ``key``, or all ``known`` but those under ``missing_key``."""
    if key in entry:
        listed, invert = entry[key], False
    elif missing_key in entry:
        listed, invert = entry[missing_key], True
    else:
        raise CoverageError(f"coverage report: {chart} has neither {key!r} nor {missing_key!r}")
    if not isinstance(listed, list) or not all(isinstance(x, str) for x in listed):
        raise CoverageError(f"coverage report: {chart}.{key if not invert else missing_key} must be a list of names")
    unknown = [x for x in listed if x not in known]
    if unknown:
        raise CoverageError(f"coverage report: {chart} has no {'state' if 'state' in missing_key else 'transition'}"
                            f" {unknown[0]!r} (a report of other charts, or of an older version of them?)")
    return set(known) - set(listed) if invert else set(listed)


def load_scenarios(files: Sequence[str], available: Mapping[str, Path]) -> list[Scenario]:
    """The scenario files a page picked, by name among the session's ``available`` ones."""
    scenarios = []
    for name in files:
        path = available.get(name)
        if path is None:
            raise CoverageError(f"no scenario file {name!r} in this session; files: {', '.join(available) or 'none'}"
                                " (start ttt-sm gui with --scenarios DIR)")
        try:
            scenarios.append(load_scenario(path))
        except ScenarioError as exc:
            raise CoverageError(str(exc)) from None
    return scenarios


def scenario_from_text(name: str, text: str) -> Scenario:
    """A scenario sent as text from the page (a file the person picked)."""
    try:
        return load_scenario_text(text, file=name)
    except ScenarioError as exc:
        raise CoverageError(str(exc)) from None


def run_for_coverage(scenarios: Sequence[Scenario], params: ArmParams, charts: Mapping[str, type[TickChart]],
                     progress: Callable[[ScenarioResult], None] | None = None,
                     check: Callable[[], None] | None = None) -> dict[str, Any]:
    """Run scenarios with coverage, as ``ttt-sm scenario run --coverage``; the colouring and the verdicts.

    ``check()`` is called between scenarios and every few simulated seconds of a long step; it raises
    (:class:`CoverageStopped`) to end the run."""
    def each(result: ScenarioResult) -> None:
        if check is not None:
            check()
        if progress is not None:
            progress(result)

    report = run_scenarios(scenarios, params, coverage=True, progress=each,
                           step_progress=None if check is None else lambda *_: check())
    assert report.coverage is not None
    result = colouring(coverage_dict(report.coverage), charts)
    result["scenarios"] = [{"name": r.name, "file": r.file, "passed": r.passed,
                            "failures": [str(f) for f in r.failures]} for r in report.results]
    return result


def suggestion(generated: Generated, chart: str, index: int) -> dict[str, Any]:
    """A ``coverage_suggestion`` message: the generated scenario that takes transition ``index`` of ``chart``
    (its YAML and the file name to save it as), or ``yaml`` None and the generator's ``reason``."""
    cls_name = generated.chart
    label = generated.transitions[index]
    scenario = generated.scenario_for(label)
    head = label.split(":")[0].replace("->", "to").replace("(none)", "none")
    slug = re.sub(r"[^A-Za-z0-9]+", "_", head).strip("_")
    out: dict[str, Any] = {"type": "coverage_suggestion", "chart": chart, "index": index, "transition": label,
                           "file": f"{chart}_{index}_{slug}.yaml", "yaml": None, "reason": None}
    if scenario is None:
        out["reason"] = generated.reason(label)
    else:
        out["yaml"] = to_yaml(scenario, f"ttt-sm gui: suggested for {cls_name} {label}")
    return out


def scenario_dir_files(folder: Path | None) -> dict[str, Path]:
    """The ``*.yaml`` scenario files of a folder, by file name."""
    if folder is None or not folder.is_dir():
        return {}
    return {p.name: p for p in sorted(folder.glob("*.yaml"))}


class CoverageRuns:
    """A session's coverage: scenario runs on a worker thread, one at a time, and the colouring its pages show.

    Parameters
    ----------
    params, charts
        The session's parameters and chart classes (the scenarios run on robots of their own).
    scenarios : mapping of name to Path
        Scenario files the pages may run.
    send_to, broadcast
        ``send_to(cid, message)``: to one page; ``broadcast(message)``: to every page that joined.
    """

    def __init__(self, params: ArmParams, charts: Mapping[str, type[TickChart]], scenarios: Mapping[str, Path],
                 send_to: Callable[[int, dict[str, Any]], None],
                 broadcast: Callable[[dict[str, Any]], None]) -> None:
        self.params = params
        self.charts = charts
        self.scenarios = dict(scenarios)
        #: The colouring shown (a ``coverage`` message's fields), or None.
        self.shown: dict[str, Any] | None = None
        self._send_to = send_to
        self._broadcast = broadcast
        self._busy = False
        self._generated: dict[str, Generated] = {}  # by chart name; read and written on the worker only
        #: The limit of one run, wall seconds (:data:`COVERAGE_LIMIT_S`).
        self.limit_s = COVERAGE_LIMIT_S
        #: Whether a job runs on the worker now.
        self.running = False
        self._jobs: queue.Queue[Callable[[], None] | None] = queue.Queue(maxsize=8)
        self._closing = threading.Event()
        self._deadline = 0.0
        # a daemon thread: a run under way never keeps the process alive after a stop (SIGTERM)
        self._worker = threading.Thread(target=self._serve, name="ttt-sm-coverage", daemon=True)
        self._worker.start()

    def _serve(self) -> None:
        while True:
            job = self._jobs.get()
            if job is None or self._closing.is_set():
                return
            self._deadline = time.perf_counter() + self.limit_s
            self.running = True
            try:
                job()
            except BaseException:  # a job reports its own errors; nothing ends the worker but close()
                log.exception("coverage job failed")
            finally:
                self.running = False

    def check(self) -> None:
        """Raise :class:`CoverageStopped` if the session stops or the run has had its time (on the worker)."""
        if self._closing.is_set():
            raise CoverageStopped("the session stopped")
        if time.perf_counter() > self._deadline:
            raise CoverageStopped(f"stopped after {self.limit_s:g} s of wall time, the most one coverage run may"
                                  " take; run fewer scenarios, or shorter ones (ttt-sm scenario run --coverage"
                                  " has no such limit)")

    def _submit(self, work: Callable[[], None]) -> None:
        try:
            self._jobs.put_nowait(work)
        except queue.Full:
            raise CoverageError("the coverage worker has 8 jobs waiting already; wait for them") from None

    def start(self, cid: int, cmd: str, job: Callable[[Callable[[], None]], dict[str, Any]]) -> dict[str, Any]:
        """Run ``job(check)`` (scenarios, for their colouring; it calls ``check()`` as it goes, which ends it at a
        stop or past the limit) on the worker; its end is sent to every page, or its error to page ``cid``.
        The reply to command ``cmd`` now."""
        if self._busy:
            raise CoverageError("scenarios are running already; wait for their coverage")
        self._busy = True

        def work() -> None:
            try:
                result = job(self.check)
            except CoverageStopped as exc:
                self._send_to(cid, {"type": "error", "id": None, "command": cmd, "error": f"{cmd}: {exc}"})
            except (CoverageError, ValueError) as exc:
                self._send_to(cid, {"type": "error", "id": None, "command": cmd, "error": f"{cmd}: {exc}"})
            except Exception:  # a scenario run that broke: say so, keep the session
                log.exception("coverage run failed")
                self._send_to(cid, {"type": "error", "id": None, "command": cmd,
                                    "error": f"{cmd}: the scenarios could not be run (a bug of ttt_sm, written to"
                                             " the server's log); the session goes on"})
            else:
                self.show(result)
            finally:
                self._busy = False

        try:
            self._submit(work)
        except CoverageError:
            self._busy = False
            raise
        return {"text": "running the scenarios; the diagrams are coloured when they are done"}

    def suggest(self, cid: int, chart: str, index: int) -> dict[str, Any]:
        """Search chart ``chart`` on the worker (once: the search is kept) for the shortest scenario that takes
        its transition ``index``; page ``cid`` gets it as a ``coverage_suggestion`` message.  The reply now."""
        cls = self.charts.get(chart)
        if cls is None:
            raise CoverageError(f"no chart {chart!r} in this session; charts: {', '.join(self.charts)}")
        transitions = cls.structure().transitions
        if not 0 <= index < len(transitions):
            raise CoverageError(f"{chart} has no transition {index}: its transitions are 0 to {len(transitions) - 1}")
        dt = self.params.control.chart_dt

        def work() -> None:
            try:
                generated = self._generated.get(chart)
                if generated is None:
                    generated = self._generated[chart] = generate(cls, dt, "shortest")
                self._send_to(cid, suggestion(generated, chart, index))
            except Exception:  # a search that broke: say so, keep the session
                log.exception("coverage suggestion failed")
                self._send_to(cid, {"type": "error", "id": None, "command": "coverage_suggest",
                                    "error": "coverage_suggest: the search failed (a bug of ttt_sm, written to the"
                                             " server's log); the session goes on"})

        self._submit(work)
        return {"text": f"searching {chart} for the shortest scenario that takes {transitions[index].label}"}

    def show(self, colouring: dict[str, Any]) -> None:
        """Colour every page's diagrams (and those of a page that joins later)."""
        self.shown = colouring
        self._broadcast({"type": "coverage", **colouring})

    def clear(self) -> None:
        """Colour no coverage."""
        self.shown = None
        self._broadcast({"type": "coverage", "charts": {}, "ignored": [], "cleared": True})

    def close(self, timeout_s: float = 5.0) -> None:
        """Stop the worker: a run under way ends at its next check (a few simulated seconds of its run), one
        waiting is dropped; waits ``timeout_s`` at most (the thread is a daemon: it never holds the process)."""
        self._closing.set()
        while True:
            try:
                self._jobs.get_nowait()
            except queue.Empty:
                break
        with contextlib.suppress(queue.Full):
            self._jobs.put_nowait(None)
        self._worker.join(timeout_s)
