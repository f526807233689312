"""Several scenarios run together: one report, with their joint coverage of the charts.

The report and the traces can be written as the run goes
(:class:`~ttt_sm.runtime.recordfile.RecordFile`: each line flushed, the last
one saying how the run ended), so a run that is interrupted keeps what it did:
``ttt-sm scenario run --out FILE --trace DIR`` (docs/scenarios.md).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..params import ArmParams
from ..runtime.listeners import Coverage, CoverageReport, Trace
from ..runtime.recordfile import RecordFile, ending_of
from .model import Scenario
from .runner import ScenarioResult, StepProgress, run_scenario


@dataclass(frozen=True)
class RunReport:
    """Several scenarios run together, with their joint coverage if asked for."""

    results: tuple[ScenarioResult, ...]
    coverage: CoverageReport | None = None
    wall_time_s: float = 0.0

    @property
    def passed(self) -> bool:
        return all(r.passed for r in self.results)

    def to_dict(self) -> dict[str, Any]:
        """What ``ttt-sm scenario run --json`` prints."""
        out: dict[str, Any] = {
            "passed": self.passed,
            "scenarios": [r.to_dict() for r in self.results],
            "counts": {"passed": sum(r.passed for r in self.results),
                       "failed": sum(not r.passed for r in self.results)},
            "sim_time_s": round(sum(r.sim_time_s for r in self.results), 3),
            "wall_time_s": round(self.wall_time_s, 3),
        }
        if self.coverage is not None:
            out["coverage"] = coverage_dict(self.coverage)
        return out


def coverage_dict(report: CoverageReport) -> dict[str, Any]:
    """Per chart: states entered, transitions taken, and the missing ones."""
    return {
        c.chart: {
            "states": f"{len(c.entered)}/{len(c.states)}",
            "transitions": f"{len(c.taken)}/{len(c.transitions)}",
            "complete": c.complete,
            "entered": list(c.entered),
            "taken": list(c.taken),
            "missing_states": list(c.missing_states),
            "missing_transitions": list(c.missing_transitions),
        }
        for c in report.charts
    }


def run_scenarios(scenarios: Iterable[Scenario], params: ArmParams, *, coverage: bool = False,
                  trace_dir: str | Path | None = None,
                  progress: Callable[[ScenarioResult], None] | None = None,
                  step_progress: StepProgress | None = None,
                  report_file: RecordFile | None = None) -> RunReport:
    """Run scenarios one after another; with ``coverage``, one report for them all.

    ``trace_dir`` writes each scenario's transitions as JSON Lines,
    ``<file stem>.jsonl``, as they happen, then an ending line naming the
    scenario.  ``report_file`` gets a line per
    scenario as it finishes, then the coverage and the counts; both end with
    ``interrupted`` or ``error`` (and where: the scenario, its transitions so
    far, the chart time of the last; ``scenario`` null between two scenarios;
    the report also ``scenarios_done``) if the run is stopped.  ``progress``
    hears of each finished scenario, ``step_progress`` of a long step on its
    way (see :func:`~.runner.run_scenario`).
    """
    wall0 = time.perf_counter()
    cov = Coverage() if coverage else None
    results: list[ScenarioResult] = []
    where: dict[str, object] = {"scenario": None}  # between scenarios (a signal may come there too)
    try:
        for scenario in scenarios:
            trace_file = None
            if trace_dir is not None:
                trace_file = RecordFile(Path(trace_dir) / f"{Path(scenario.file).stem}.jsonl")
            trace = Trace(sink=trace_file, limit=1)  # the last transition: where a stopped run stood
            try:
                result = run_scenario(scenario, params, coverage=cov, listeners=[trace], progress=step_progress)
            except BaseException as exc:
                how, data = ending_of(exc)
                last = trace.records[-1] if trace.records else None
                where = {"scenario": scenario.name, "file": scenario.file, "transitions": trace.count,
                         "last_transition_time_s": None if last is None else last.time_s}
                if trace_file is not None:
                    trace_file.end(how, **data, **where)
                raise
            if trace_file is not None:
                trace_file.end("finished", scenario=scenario.name, passed=result.passed,
                               transitions=trace.count, sim_time_s=result.sim_time_s)
            results.append(result)
            if report_file is not None:
                report_file.add({"event": "scenario", **result.to_dict()})
            if progress is not None:
                progress(result)
        run = RunReport(tuple(results), cov.report() if cov is not None else None, time.perf_counter() - wall0)
        if report_file is not None:
            summary = run.to_dict()
            if "coverage" in summary:
                report_file.add({"event": "coverage", "coverage": summary["coverage"]})
            report_file.end("finished", passed=summary["passed"], counts=summary["counts"],
                            sim_time_s=summary["sim_time_s"], wall_time_s=summary["wall_time_s"])
    except BaseException as exc:
        if report_file is not None and not report_file.ended:
            how, data = ending_of(exc)
            report_file.end(how, **data, **where, scenarios_done=len(results))
        raise
    return run
