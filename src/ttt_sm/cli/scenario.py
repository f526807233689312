"""``ttt-sm scenario``: run and check scenario files from the command line.

``ttt-sm scenario run FILES... [--json] [--coverage] [--trace DIR]`` runs the
scenarios (a folder means its ``*.yaml`` files) and exits with status 0 if all
passed, 1 if one failed, 2 if a file could not be loaded (nothing runs then).
``ttt-sm scenario check FILES...`` only loads and checks them.
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from ..scenario.errors import ScenarioError
from ..scenario.loader import load_scenario, scenario_files
from ..scenario.model import Scenario, Step
from ..scenario.runner import ScenarioResult
from ..scenario.suite import run_scenarios
from .common import print_json


def register(sub: Any) -> None:
    """Add the ``scenario`` command to the subcommands of ``ttt-sm`` (``build_parser``'s ``sub``)."""
    help_ = "run scenario tests of event sequences (YAML files; see docs/scenarios.md)"
    sp = sub.add_parser("scenario", help=help_, description=help_)
    actions = sp.add_subparsers(dest="scenario_command", required=True)

    run = actions.add_parser("run", help="run scenario files", description="Run scenario files; exit"
                             " status 0 if all pass, 1 if one fails, 2 if a file cannot be loaded.")
    run.add_argument("files", nargs="+", metavar="FILE", help="scenario files, or folders of them")
    run.add_argument("--json", action="store_true", help="print one JSON document")
    run.add_argument("--coverage", action="store_true",
                     help="report the states entered and transitions taken by all the scenarios together")
    run.add_argument("--trace", metavar="DIR", default=None,
                     help="write each scenario's chart transitions to DIR/<file>.jsonl")
    run.set_defaults(func=cmd_scenario_run)

    check = actions.add_parser("check", help="load and check scenario files without running them")
    check.add_argument("files", nargs="+", metavar="FILE", help="scenario files, or folders of them")
    check.add_argument("--json", action="store_true", help="print one JSON document")
    check.set_defaults(func=cmd_scenario_check)


def _load_all(files: list[str]) -> tuple[list[Scenario], list[ScenarioError]]:
    scenarios, errors = [], []
    paths = scenario_files(files)
    if not paths:
        errors.append(ScenarioError(", ".join(files), 0, "no scenario files (*.yaml) there"))
    for path in paths:
        try:
            scenarios.append(load_scenario(path))
        except ScenarioError as exc:
            errors.extend(exc.errors)  # every mistake of the file, one line each
    return scenarios, errors


def _report_errors(errors: list[ScenarioError], as_json: bool) -> int:
    for e in errors:
        print(f"ttt-sm scenario: error: {e}", file=sys.stderr)
    if as_json:
        print_json({"passed": False, "errors": [str(e) for e in errors], "scenarios": []})
    return 2


def _line(result: ScenarioResult) -> str:
    verdict = "PASS" if result.passed else "FAIL"
    head = (f"{verdict} {result.name}  ({result.file}; {result.sim_time_s:.3f} s simulated"
            f" in {result.wall_time_s:.2f} s)")
    return "\n".join([head, *(f"  {f}" for f in result.failures)])


def cmd_scenario_run(args: argparse.Namespace) -> int:
    """Load every file first, then run them; exit 0 / 1 (a scenario failed) / 2 (a file is wrong)."""
    from ..twin.workspace import load_arm

    scenarios, errors = _load_all(args.files)
    if errors:
        return _report_errors(errors, args.json)
    params = load_arm(args.params)
    stream = sys.stderr if args.json else sys.stdout

    live = sys.stderr.isatty()  # a long step shows where it is, on a terminal only

    def progress(result: ScenarioResult) -> None:
        if live:
            print("\r\033[K", end="", file=sys.stderr, flush=True)
        print(_line(result), file=stream, flush=True)

    def step_progress(scenario: Scenario, step: Step, t: float, end: float) -> None:
        print(f"\r\033[K  {scenario.name}: {step.kind} at line {step.where.line}, {t:.0f} s of at most"
              f" {end:.0f} s simulated", end="", file=sys.stderr, flush=True)

    report = run_scenarios(scenarios, params, coverage=args.coverage, trace_dir=args.trace, progress=progress,
                           step_progress=step_progress if live else None)
    if args.json:
        print_json(report.to_dict())
    else:
        counts = report.to_dict()["counts"]
        sim = sum(r.sim_time_s for r in report.results)
        print(f"{counts['passed']} passed, {counts['failed']} failed"
              f" ({sim:.1f} s simulated in {report.wall_time_s:.1f} s)")
        if report.coverage is not None:
            print("coverage of all the scenarios together:")
            print(report.coverage.to_text(), end="")
    return 0 if report.passed else 1


def cmd_scenario_check(args: argparse.Namespace) -> int:
    """Load and check files; exit 0 if all are right, 2 if not."""
    scenarios, errors = _load_all(args.files)
    if errors:
        return _report_errors(errors, args.json)
    data = [{"name": s.name, "file": s.file, "steps": len(s.steps)} for s in scenarios]
    if args.json:
        print_json({"passed": True, "errors": [], "scenarios": data})
    else:
        for s in scenarios:
            print(f"ok {s.name}  ({s.file}; {len(s.steps)} steps)")
    return 0
