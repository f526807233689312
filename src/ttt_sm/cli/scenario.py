"""``ttt-sm scenario``: run and check scenario files from the command line.

``ttt-sm scenario run FILES... [--json] [--coverage] [--trace DIR] [--out FILE]``
runs the scenarios (a folder means its ``*.yaml`` files) and exits with status
0 if all passed, 1 if one failed, 2 if a file could not be loaded (nothing
runs then).  ``ttt-sm scenario check FILES...`` only loads and checks them.

What is streamed and what is one document: ``--out FILE`` and ``--trace DIR``
are JSON Lines written as the run goes, each line flushed, the last one
saying how the run ended; ``--json`` is one JSON document on standard output,
printed at the end, also when the run is interrupted (then with
``"complete": false`` and the ``ended`` line).
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from ..scenario.errors import ScenarioError
from ..scenario.loader import load_scenario, scenario_files
from ..scenario.model import Scenario, Step
from ..scenario.runner import ScenarioResult
from ..scenario.suite import RunReport, run_scenarios
from .common import out_dir, print_json, trace_file


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
                     help="write each scenario's chart transitions to DIR/<file>.jsonl as they happen")
    run.add_argument("--out", metavar="FILE", default=None,
                     help="write the report to FILE as the run goes (JSON Lines: a line per scenario as it ends,"
                          " the coverage, the counts; the last line says how the run ended)")
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
    from ..runtime.recordfile import RecordFile, ending_of
    from ..twin.workspace import load_arm

    scenarios, errors = _load_all(args.files)
    if errors:
        return _report_errors(errors, args.json)
    params = load_arm(args.params)
    # what will be written is checked before anything runs
    if args.trace is not None:
        out_dir(args.trace, "--trace")
    report_path = trace_file(args.out, "--out") if args.out is not None else None
    stream = sys.stderr if args.json else sys.stdout
    done: list[ScenarioResult] = []

    live = sys.stderr.isatty()  # a long step shows where it is, on a terminal only

    def progress(result: ScenarioResult) -> None:
        done.append(result)
        if live:
            print("\r\033[K", end="", file=sys.stderr, flush=True)
        print(_line(result), file=stream, flush=True)

    def step_progress(scenario: Scenario, step: Step, t: float, end: float) -> None:
        print(f"\r\033[K  {scenario.name}: {step.kind} at line {step.where.line}, {t:.0f} s of at most"
              f" {end:.0f} s simulated", end="", file=sys.stderr, flush=True)

    report_file = None
    if report_path is not None:
        report_file = RecordFile(report_path)
        report_file.add({"event": "run", "files": args.files, "scenarios": [s.name for s in scenarios],
                         "coverage": args.coverage})
    try:
        report = run_scenarios(scenarios, params, coverage=args.coverage, trace_dir=args.trace, progress=progress,
                               step_progress=step_progress if live else None, report_file=report_file)
    except BaseException as exc:
        if report_file is not None and report_file.ended is None:
            how, data = ending_of(exc)
            report_file.end(how, **data)
        if args.json:  # one document still: what ran, and how the run ended
            how, data = ending_of(exc)
            partial = RunReport(tuple(done)).to_dict()
            print_json({**partial, "passed": False, "complete": False,
                        "ended": {"event": how, **data, "scenarios_done": len(done),
                                  "scenarios_total": len(scenarios)}})
        raise
    if args.json:
        print_json({**report.to_dict(), "complete": True})
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
