"""``ttt-sm lab`` and the global ``--chart`` option: a student's chart in the robot (docs/lab.md).

``ttt-sm --chart SLOT=path/to/file.py:ClassName COMMAND ...`` (repeatable)
builds the robot of COMMAND with that class in the slot (:mod:`ttt_sm.app.slots`);
the commands that build one honour it (:data:`HONOURED`), the others refuse it.

``ttt-sm lab list``: the exercises.  ``ttt-sm lab start EXERCISE DIR``: copy
one into DIR.  ``ttt-sm lab check DIR [--json]``: judge DIR's chart; exit
status 0 when every check passes, 1 when one fails, 2 when the chart cannot
be loaded (one line, ``file:line``).  ``ttt-sm lab grade SUBMISSIONS
--exercise E --out DIR``: every student's chart of a class, each in a process
of its own, on this machine or a Dask cluster (:mod:`ttt_sm.lab.grade`).
"""

from __future__ import annotations

import argparse
import contextlib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from .common import CliError, add_group, print_json, whole_number

#: The commands that build a robot from the chosen slots.
HONOURED = ("play", "gui", "draw", "demo", "debug", "scenario")


def add_global_options(parser: argparse.ArgumentParser) -> None:
    """Add ``--chart`` to the options that come before the subcommand."""
    from ..app.slots import SLOT_NAMES

    parser.add_argument("--chart", action="append", default=[], metavar="SLOT=FILE.py:CLASS", dest="chart_slots",
                        help=f"run your chart class in a slot ({', '.join(SLOT_NAMES)}); repeatable;"
                             f" taken by {', '.join(HONOURED)}")


@contextlib.contextmanager
def chosen_charts(args: argparse.Namespace) -> Iterator[None]:
    """Run the command with the slots ``--chart`` chose (nothing to do without it)."""
    choices = getattr(args, "chart_slots", None) or []
    if not choices:
        yield
        return
    if args.command not in HONOURED:
        raise CliError(f"--chart is not taken by {args.command}; it is taken by {', '.join(HONOURED)}")
    if getattr(args, "lab", None) is not None:
        raise CliError("--chart and gui --lab: the lab's folder names the chart it runs (docs/lab.md); give one")
    from ..app.chart_file import slots_from
    from ..app.slots import using_slots

    with using_slots(slots_from(choices)):
        yield


def register(sub: Any) -> None:
    """Add the ``lab`` command to the subcommands of ``ttt-sm``."""
    help_ = "exercises: write one of the thesis' charts, check what it does (docs/lab.md)"
    sp, actions = add_group(sub, "lab", help_)
    ls = actions.add_parser("list", help="list the exercises")
    ls.add_argument("--json", action="store_true", help="print one JSON document")
    ls.set_defaults(func=cmd_lab_list)
    st = actions.add_parser("start", help="copy an exercise (task page, skeleton, checks) into a new folder")
    st.add_argument("exercise", help="the exercise's name (ttt-sm lab list)")
    st.add_argument("dir", help="a new or empty folder")
    st.set_defaults(func=cmd_lab_start)
    ck = actions.add_parser("check", help="run the checks of the exercise in DIR on its chart")
    ck.add_argument("dir", help="the folder ttt-sm lab start made")
    ck.add_argument("--json", action="store_true", help="print one JSON document")
    ck.set_defaults(func=cmd_lab_check)
    gr = actions.add_parser("grade", help="check every student's chart of a class, each in a process of its own",
                            description="grade a folder of submissions (one sub-folder per student); reports in --out")
    gr.add_argument("submissions", help="a folder with one sub-folder per student, as ttt-sm lab start made it")
    gr.add_argument("--exercise", required=True, help="the exercise (ttt-sm lab list); its packaged checks are run")
    gr.add_argument("--out", required=True, help="the report folder: results.jsonl, grades.csv, report.json/.html")
    gr.add_argument("--workers", type=whole_number, default=None,
                    help="submissions graded at once on this machine (default: the CPU count)")
    gr.add_argument("--dask", metavar="ADDRESS", default=None,
                    help="grade on the Dask cluster whose scheduler is at ADDRESS (needs ttt_sm[cluster])")
    gr.add_argument("--timeout", type=seconds, default=120.0, metavar="S",
                    help="wall-clock seconds a submission may take (default 120)")
    gr.add_argument("--memory", type=whole_number, default=2048, metavar="MB",
                    help="address space a submission's process may map, MB (default 2048)")
    gr.add_argument("--again", action="store_true",
                    help="grade every student anew (by default a rerun grades only those not in results.jsonl)")
    gr.set_defaults(func=cmd_lab_grade)


def seconds(text: str) -> float:
    """A time limit: a number of seconds in (0, 86400]."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text[:40]!r}") from None
    if not 0 < value <= 86400:
        raise argparse.ArgumentTypeError(f"expected a number of seconds in (0, 86400], got {text[:40]}")
    return value


def cmd_lab_list(args: argparse.Namespace) -> int:
    from ..lab.exercise import exercises

    found = exercises()
    if args.json:
        print_json({"exercises": [{"name": e.name, "title": e.title, "slot": e.slot, "section": e.section}
                                  for e in found]})
    else:
        width = max(len(e.name) for e in found)
        for e in found:
            print(f"{e.name:<{width}}  {e.title} (section {e.section}, slot {e.slot})")
    return 0


def cmd_lab_start(args: argparse.Namespace) -> int:
    from ..lab.exercise import start
    from ..params import shown_path

    ex = start(args.exercise, Path(args.dir))
    where = shown_path(Path(args.dir))
    print(f"{ex.title}: read {where}/task.md, write {where}/{ex.file}, then: ttt-sm lab check {where}")
    return 0


def cmd_lab_check(args: argparse.Namespace) -> int:
    from ..lab.checks import check_folder
    from ..twin.workspace import load_arm

    report = check_folder(Path(args.dir), load_arm(args.params))
    if args.json:
        print_json(report.to_dict())
    else:
        print(report.to_text(), end="")
    return 0 if report.passed else 1


def cmd_lab_grade(args: argparse.Namespace) -> int:
    import os

    from ..lab.exercise import exercise
    from ..lab.grade import Limits, ResultsFile, grade_class, submissions
    from ..lab.grade_report import build_reports
    from ..params import shown_path
    from ..runner import dask_client
    from ..twin.workspace import load_arm
    from .common import out_dir, progress

    ex = exercise(args.exercise)
    out = out_dir(args.out)
    jobs = submissions(Path(args.submissions), ex)
    load_arm(args.params)  # a parameter file that does not load is one line now, not one per student
    client = dask_client(args.dask) if args.dask is not None else None
    limits = Limits(timeout_s=args.timeout, memory_mb=args.memory, params_file=args.params)
    results = ResultsFile(out, ex.name, again=args.again)
    say = progress(True)
    if results.done:
        say(f"{shown_path(results.path)} already holds {len(results.done)} of these students"
            " (--again grades them anew)")
    try:
        grade_class(jobs, limits, results, workers=args.workers or os.cpu_count() or 1, client=client, say=say)
    except KeyboardInterrupt:
        results.close()
        build_reports(out)
        say(f"stopped: {len(results.done)} of {len(jobs)} graded; reports in {shown_path(out)}"
            " (run again to grade the others)")
        raise
    finally:
        results.close()
        if client is not None:
            client.close()
    report = build_reports(out)
    graded = report["statuses"].get("graded", 0)
    students = f"{report['students']} student" + ("s" if report["students"] != 1 else "")
    say(f"{students}: {report['passed']} passed, {graded} graded,"
        f" {report['students'] - graded} not; reports in {shown_path(out)}/report.html, grades.csv, report.json")
    return 0
