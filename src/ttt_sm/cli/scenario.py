"""``ttt-sm scenario``: run and check scenario files from the command line.

``ttt-sm scenario run FILES... [--json] [--coverage] [--trace DIR] [--out FILE]``
runs the scenarios (a folder means its ``*.yaml`` files) and exits with status
0 if all passed, 1 if one failed, 2 if a file could not be loaded (nothing
runs then); ``--suggest DIR`` (with ``--coverage``) writes there, for each
transition the scenarios never took, the shortest generated scenario that takes
it.  ``ttt-sm scenario check FILES...`` only loads and checks them.

``ttt-sm scenario generate CHART [--out DIR] [--strategy shortest|tour]
[--json]`` writes scenarios that together take every transition of the chart
the search reaches (:mod:`ttt_sm.scenario.generate`); ``ttt-sm scenario
mutate CHART FILES...`` runs scenarios against mutants of the chart
(:mod:`ttt_sm.scenario.mutate`).  docs/scenarios.md, "Generated scenarios".

What is streamed and what is one document: ``--out FILE`` and ``--trace DIR``
are JSON Lines written as the run goes, each line flushed, the last one
saying how the run ended; ``--json`` is one JSON document on standard output,
printed at the end, also when the run is interrupted (then with
``"complete": false`` and the ``ended`` line).
"""

from __future__ import annotations

import argparse
import os
import sys
from typing import Any

from ..files import write_atomic
from ..scenario.errors import ScenarioError
from ..scenario.generate import STRATEGIES
from ..scenario.loader import load_scenario, scenario_files
from ..scenario.model import Scenario, Step
from ..scenario.runner import ScenarioResult
from ..scenario.suite import RunReport, run_scenarios
from .common import CliError, add_group, out_dir, print_json, trace_file


def register(sub: Any) -> None:
    """Add the ``scenario`` command to the subcommands of ``ttt-sm`` (``build_parser``'s ``sub``)."""
    help_ = "run scenario tests of event sequences (YAML files; see docs/scenarios.md)"
    sp, actions = add_group(sub, "scenario", help_)

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
    run.add_argument("--suggest", metavar="DIR", default=None,
                     help="with --coverage: write to DIR, for each transition the scenarios never took, the"
                          " shortest generated scenario that takes it")
    run.set_defaults(func=cmd_scenario_run)

    gen = actions.add_parser("generate", help="generate scenarios that take every transition of a chart",
                             description="Write bare-chart scenarios that together take every transition of"
                                         " CHART the search reaches; report the others with the reason.")
    gen.add_argument("chart", metavar="CHART", help=f"a chart: {', '.join(_chart_names())}")
    gen.add_argument("--out", metavar="DIR", default=None,
                     help="folder to write the files to (default: generated/CHART)")
    gen.add_argument("--strategy", default="shortest", choices=STRATEGIES,
                     help="shortest: one scenario per transition, the shortest path found; tour: fewer,"
                          " longer scenarios (default: shortest)")
    gen.add_argument("--json", action="store_true", help="print one JSON document: what was generated")
    gen.set_defaults(func=cmd_scenario_generate)

    mut = actions.add_parser("mutate", help="run scenarios against mutants of a chart",
                             description="Run the scenarios that run CHART bare against mutants of it (a guard"
                                         " flipped, two transitions swapped, an action dropped); report how many"
                                         " the scenarios kill.")
    mut.add_argument("chart", metavar="CHART", help=f"a chart: {', '.join(_chart_names())}")
    mut.add_argument("files", nargs="+", metavar="FILE", help="scenario files, or folders of them")
    mut.add_argument("--json", action="store_true", help="print one JSON document")
    mut.set_defaults(func=cmd_scenario_mutate)

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
    if args.suggest is not None and not args.coverage:
        raise CliError("--suggest writes scenarios for the transitions the coverage misses: add --coverage")
    if args.suggest is not None:
        out_dir(args.suggest, "--suggest")
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
    suggested = _suggest(report, params, args.suggest) if args.suggest is not None else None
    if args.json:
        extra = {"suggested": suggested} if suggested is not None else {}
        print_json({**report.to_dict(), **extra, "complete": True})
    else:
        counts = report.to_dict()["counts"]
        sim = sum(r.sim_time_s for r in report.results)
        print(f"{counts['passed']} passed, {counts['failed']} failed"
              f" ({sim:.1f} s simulated in {report.wall_time_s:.1f} s)")
        if report.coverage is not None:
            print("coverage of all the scenarios together:")
            print(report.coverage.to_text(), end="")
        for item in suggested or []:
            where = item["file"] if item["file"] else f"none: {item['reason']}"
            print(f"suggested for {item['chart']} {item['transition']}: {where}")
    return 0 if report.passed else 1


def _chart_names() -> list[str]:
    from ..charts import ALL_CHARTS

    return [c.__name__ for c in ALL_CHARTS]


def _chart(name: str) -> Any:
    """The chart class named ``name``; one line naming the choices if there is none."""
    from ..charts import ALL_CHARTS

    for cls in ALL_CHARTS:
        if cls.__name__ == name:
            return cls
    raise CliError(f"unknown chart {name[:80]!r}; charts: {', '.join(_chart_names())}")


def _suggest(report: RunReport, params: Any, folder: str) -> list[dict[str, Any]]:
    """For each transition no scenario took: the shortest generated scenario that takes it, written to
    ``folder`` (or why there is none)."""
    from pathlib import Path

    from ..scenario.generate import file_name, generate, to_yaml

    assert report.coverage is not None
    out: list[dict[str, Any]] = []
    for cov in report.coverage.charts:
        missing = list(cov.missing_transitions)
        if not missing:
            continue
        generated = generate(_chart(cov.chart), params.control.chart_dt, "shortest")
        written: dict[int, str] = {}
        for label in missing:
            scenario = generated.scenario_for(label)
            if scenario is None:
                out.append({"chart": cov.chart, "transition": label, "file": None,
                            "reason": generated.reason(label)})
                continue
            key = id(scenario)
            if key not in written:
                path = Path(folder) / file_name(scenario, len(written) + 1)
                command = f"ttt-sm scenario run ... --coverage --suggest {folder}"
                write_atomic(path, to_yaml(scenario, command))
                written[key] = str(path)
            out.append({"chart": cov.chart, "transition": label, "file": written[key], "reason": None})
    return out


def cmd_scenario_generate(args: argparse.Namespace) -> int:
    """Generate a chart's scenarios into a folder; exit 0 (2: a bad chart name or folder)."""
    from pathlib import Path

    from ..scenario.generate import generate, write
    from ..twin.workspace import load_arm

    cls = _chart(args.chart)
    folder = out_dir(args.out if args.out is not None else str(Path("generated") / cls.__name__), "--out")
    params = load_arm(args.params)
    generated = generate(cls, params.control.chart_dt, args.strategy)
    command = f"ttt-sm scenario generate {cls.__name__} --strategy {args.strategy}"
    try:
        write(generated, folder, command)
    except OSError as exc:
        raise CliError(f"--out {args.out}: cannot write there ({exc.strerror or exc})") from None
    summary = generated.to_dict()
    if args.json:
        print_json({"charts": {cls.__name__: summary}})
        return 0
    for path in generated.files:
        print(path)
    print(f"{cls.__name__}: {summary['covered']} of {summary['transitions']} transitions taken by"
          f" {summary['scenarios']} scenarios ({summary['steps']} steps, {summary['chart_steps']} chart steps;"
          f" a tour takes at least {summary['tour_lower_bound']} transitions) in {summary['seconds']:.2f} s")
    for item in summary["unreachable"]:
        print(f"  not taken: {item['transition']}: {item['reason']}")
    return 0


def cmd_scenario_mutate(args: argparse.Namespace) -> int:
    """Run scenarios against a chart's mutants; exit 0 (2: a bad chart name or a file that does not load)."""
    from ..scenario.mutate import mutation_test, runs_chart, summary
    from ..twin.workspace import load_arm

    cls = _chart(args.chart)
    scenarios, errors = _load_all(args.files)
    if errors:
        return _report_errors(errors, args.json)
    runnable = [s for s in scenarios if runs_chart(s, cls.__name__)]
    if not runnable:
        raise CliError(f"no scenario of {', '.join(args.files)[:200]} runs {cls.__name__} bare ('chart:"
                       f" {cls.__name__}'): mutants are run by bare-chart scenarios only")
    params = load_arm(args.params)
    results = mutation_test(cls, runnable, params)
    counts = summary(results)
    if args.json:
        print_json({"chart": cls.__name__, "scenarios": len(runnable), "skipped": len(scenarios) - len(runnable),
                    **counts, "mutants_found": [r.to_dict() for r in results]})
        return 0
    for r in results:
        where = f"{os.path.basename(r.mutant.file)}:{r.mutant.line}" if r.mutant.file else f"line {r.mutant.line}"
        print(f"{r.status.upper():10s} {r.mutant.kind:4s} {where}: {r.mutant.description}")
        if r.status != "killed":
            print(f"           {r.detail}")
    print(f"{cls.__name__}: {counts['killed']} of {counts['killed'] + counts['survived']} mutants killed"
          f" ({100 * counts['kill_ratio']:.0f} %); {counts['equivalent']} equivalent within the search bound,"
          f" {counts['stillborn']} stillborn; {len(runnable)} scenarios"
          + (f" ({len(scenarios) - len(runnable)} not bare, not run)" if len(scenarios) > len(runnable) else ""))
    return 0


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
