"""Several scenarios run together: one report, with their joint coverage of the charts."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..params import ArmParams
from ..runtime.listeners import Coverage, CoverageReport, Trace
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
                  step_progress: StepProgress | None = None) -> RunReport:
    """Run scenarios one after another; with ``coverage``, one report for them all.

    ``trace_dir`` writes each scenario's transitions as JSON Lines,
    ``<file stem>.jsonl``, to see what the charts did.  ``progress`` hears of
    each finished scenario, ``step_progress`` of a long step on its way
    (see :func:`~.runner.run_scenario`).
    """
    wall0 = time.perf_counter()
    cov = Coverage() if coverage else None
    results = []
    for scenario in scenarios:
        trace = Trace() if trace_dir is not None else None
        result = run_scenario(scenario, params, coverage=cov, listeners=[trace] if trace else [],
                              progress=step_progress)
        if trace is not None and trace_dir is not None:
            trace.write_jsonl(Path(trace_dir) / f"{Path(scenario.file).stem}.jsonl")
        results.append(result)
        if progress is not None:
            progress(result)
    return RunReport(tuple(results), cov.report() if cov is not None else None,
                     time.perf_counter() - wall0)
