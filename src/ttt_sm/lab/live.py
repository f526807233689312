"""The checks of a student's folder, one at a time, as they finish: what ``ttt-sm gui --lab`` shows while they run.

:func:`iter_checks` runs what :func:`~.checks.run_checks` runs, in the same
order with the same results, but hands each check over as soon as it is
decided (a scenario file each, then the twin's checks, then coverage), so a
page can show the first results while the twin still runs.

``python -m ttt_sm.lab.live DIR [--params FILE]`` prints them as JSON Lines
on standard output: the cockpit runs it as a process of its own, so the
checks never hold up the simulation it serves, and a save that comes while
they run simply ends them.  Each line is one object::

    {"type": "check", "name": ..., "kind": ..., "passed": ..., "reason": ...}
    {"type": "done", "score": {"passed": 9, "total": 9}, "passed": true}
    {"type": "error", "error": "my_init3/drive_init3.py:12: syntax error: ..."}

A chart that cannot be judged (it does not load, it does not fit the slot,
the folder is no exercise) is one ``error`` line, and exit status 2.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Iterator
from pathlib import Path

from ..app.chart_file import ChartFileError, load_chart
from ..app.slots import ChartSlots, SlotError, using_slots
from ..params import ArmParams
from ..runner import one_line
from ..runtime import TickChart
from ..runtime.jsonable import dumps
from ..runtime.listeners import Coverage
from ..scenario.loader import load_scenario
from ..scenario.runner import run_scenario
from ..twin.workspace import load_arm
from .checks import CheckResult, _coverage, _init_on_twin, _x_on_twin
from .exercise import Exercise, LabError, read_exercise


def iter_checks(ex: Exercise, cls: type[TickChart], where: str, params: ArmParams) -> Iterator[CheckResult]:
    """Every check of exercise `ex` with `cls` in its slot, each as soon as it is decided (as ``run_checks``)."""
    slots = ChartSlots().with_chart(ex.slot, cls, where)
    cov = Coverage().include(cls)
    with using_slots(slots):
        for path in ex.scenario_files():
            scenario = load_scenario(path)
            result = run_scenario(scenario, params, coverage=cov)
            yield CheckResult(scenario.name, "scenario", result.passed, "\n".join(str(f) for f in result.failures))
        if ex.twin == "init":
            yield from _init_on_twin(ex, slots, params, cov)
        elif ex.twin == "draw_x":
            yield from _x_on_twin(ex, slots, params, cov)
    if ex.coverage > 0:
        yield _coverage(ex, cls, cov)


def _line(message: dict[str, object]) -> None:
    print(dumps(message), flush=True)


def main(argv: list[str] | None = None) -> int:
    """Run the checks of the folder on its chart, one JSON line per check (see the module's docstring)."""
    parser = argparse.ArgumentParser(prog="python -m ttt_sm.lab.live",
                                     description="the lab's checks as JSON Lines, one per check as it finishes")
    parser.add_argument("dir", help="the folder ttt-sm lab start made")
    parser.add_argument("--params", metavar="FILE", default=None, help="the arm's parameter file")
    parser.add_argument("--nice", type=int, default=0, help="lower this process's priority by this much first")
    args = parser.parse_args(argv)
    if args.nice:
        os.nice(args.nice)  # the cockpit's simulation comes first
    try:
        ex = read_exercise(Path(args.dir))
        cls, where = load_chart(ex.chart_file, ex.class_name)
        params = load_arm(args.params)
        passed = total = 0
        for check in iter_checks(ex, cls, where, params):
            _line({"type": "check", **check.to_dict()})
            passed, total = passed + check.passed, total + 1
    except (ChartFileError, SlotError, LabError) as exc:
        _line({"type": "error", "error": str(exc)})
        return 2
    except Exception as exc:  # the student's chart raised while it ran: one line, the run is over
        _line({"type": "error", "error": f"the checks stopped: {one_line(exc)}"})
        return 2
    _line({"type": "done", "score": {"passed": passed, "total": total}, "passed": passed == total})
    return 0


if __name__ == "__main__":
    sys.exit(main())
