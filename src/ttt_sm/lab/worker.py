"""One submission graded in a process of its own: ``python -m ttt_sm.lab.worker`` (what ``ttt-sm lab grade`` runs).

The grader (:mod:`.grade`) starts one of these per student, in a fresh
process, and kills it when its time is up.  Here the process first limits
itself (``RLIMIT_AS``: the memory it may map; ``RLIMIT_CPU``: a backstop for
the wall-clock kill, should the grader itself die), then loads the student's
chart and runs the exercise's checks (:func:`~ttt_sm.lab.checks.run_checks`),
and writes one JSON document to the ``--result`` file, never to standard
output, which the student's code may print to.

The checks are the packaged exercise's, not the copy in the student's folder:
a student who edits their ``checks/*.yaml`` changes nothing.
"""

from __future__ import annotations

import argparse
import resource
import sys
from pathlib import Path
from typing import Any

#: Megabytes set aside before the checks run and freed when memory runs out, so the report can still be written.
_RESERVE_MB = 8


#: The largest file the process may write, bytes (its result is a few kB; a student's code may write more).
MAX_FILE_BYTES = 64 * 2**20


def limit(memory_mb: int, cpu_s: float) -> None:
    """Limit this process to `memory_mb` of address space, `cpu_s` seconds of processor time and files of
    :data:`MAX_FILE_BYTES`."""
    resource.setrlimit(resource.RLIMIT_FSIZE, (MAX_FILE_BYTES, MAX_FILE_BYTES))
    if memory_mb > 0:
        size = memory_mb * 2**20
        resource.setrlimit(resource.RLIMIT_AS, (size, size))
    if cpu_s > 0:
        soft = int(cpu_s) + 1
        resource.setrlimit(resource.RLIMIT_CPU, (soft, soft + 5))


def grade(exercise_name: str, chart_file: Path, params_file: str | None) -> dict[str, Any]:
    """Load `chart_file` and run exercise `exercise_name`'s checks on it: the result as a JSON-ready dict."""
    from ..app.chart_file import ChartFileError, load_chart
    from ..app.slots import ChartSlots, SlotError
    from ..runtime.listeners import Coverage
    from ..twin.workspace import load_arm
    from .checks import run_checks
    from .exercise import exercise

    ex = exercise(exercise_name)
    params = load_arm(params_file)
    try:
        cls, where = load_chart(chart_file, ex.class_name)
        ChartSlots().with_chart(ex.slot, cls, where)  # a class that does not fit the slot is a load error too
    except (ChartFileError, SlotError) as exc:
        return {"status": "load error", "error": " ".join(str(exc).split())}
    coverage = Coverage().include(cls)
    report = run_checks(ex, cls, where, params, coverage=coverage)
    [chart] = [c for c in coverage.report().charts if c.chart == cls.__name__]
    done, total = report.score
    # the scenario runner reports an exception in an action as that step's failure; a MemoryError
    # under RLIMIT_AS is the memory limit, whichever step it struck
    memory = [c for c in report.checks if "MemoryError" in c.reason]
    status, error = "graded", ""
    if memory:
        status, error = "memory limit", f"the chart ran out of memory in the check {memory[0].name!r}"
    return {"status": status, "passed": report.passed, "score": done, "total": total,
            "checks": [c.to_dict() for c in report.checks],
            "transitions": list(chart.transitions), "taken": list(chart.taken), "error": error}


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m ttt_sm.lab.worker", description=__doc__.splitlines()[0])
    parser.add_argument("exercise")
    parser.add_argument("chart_file", type=Path)
    parser.add_argument("--result", type=Path, required=True, help="where the JSON result is written")
    parser.add_argument("--memory", type=int, default=0, help="address space limit, MB (0: none)")
    parser.add_argument("--cpu", type=float, default=0.0, help="processor time limit, s (0: none)")
    parser.add_argument("--params", default=None, help="the arm's parameter file (default: the packaged one)")
    args = parser.parse_args(argv)
    # imported before the limit: the libraries' own mappings are not the student's to pay for
    from ..files import write_atomic
    from ..runtime.jsonable import dumps
    from . import checks  # noqa: F401

    limit(args.memory, args.cpu)
    reserve: bytearray | None = bytearray(_RESERVE_MB * 2**20)
    try:
        result = grade(args.exercise, args.chart_file, args.params)
    except MemoryError:  # raised outside a scenario step (loading the file, the twin check)
        reserve = None
        result = {"status": "memory limit", "error": "the chart ran out of memory"}
    except RecursionError as exc:
        result = {"status": "crashed", "error": f"RecursionError: {' '.join(str(exc).split())}"}
    except Exception as exc:  # the student's code: whatever it raises is their result, in one line
        result = {"status": "crashed", "error": f"{type(exc).__name__}: {' '.join(str(exc).split())[:500]}"}
    del reserve
    write_atomic(args.result, dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
