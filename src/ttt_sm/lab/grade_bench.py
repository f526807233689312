"""``ttt-sm bench --only lab_grade``: a class of 30 graded with one worker, with two, and on a Dask LocalCluster.

The class is the algorithm_activator exercise (the quickest to check) handed
in 30 times: half the thesis' chart under the student's class name, half the
skeleton.  What is measured is the wall clock of :func:`~.grade.grade_class`,
each submission in a process of its own, as ``ttt-sm lab grade`` runs it.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path
from typing import Any

from .exercise import exercise
from .grade import Limits, ResultsFile, grade_class, submissions

EXERCISE = "algorithm_activator"
REFERENCE = "from ttt_sm.charts.game import AlgorithmActivator as MyActivator  # noqa: F401\n"


def _class(folder: Path, students: int) -> Path:
    ex = exercise(EXERCISE)
    skeleton = ex.chart_file.read_text(encoding="utf-8")
    for n in range(students):
        sub = folder / f"student_{n + 1:02d}"
        sub.mkdir(parents=True)
        (sub / ex.file).write_text(REFERENCE if n % 2 == 0 else skeleton, encoding="utf-8")
    return folder


def _timed(subs: Path, out: Path, workers: int = 1, client: Any = None) -> tuple[float, int]:
    """Seconds to grade the class in `subs` into `out`, and how many passed."""
    out.mkdir(parents=True)
    jobs = submissions(subs, exercise(EXERCISE))
    results = ResultsFile(out, EXERCISE)
    start = time.perf_counter()
    try:
        grade_class(jobs, Limits(timeout_s=300.0), results, workers=workers, client=client)
    finally:
        results.close()
    return time.perf_counter() - start, sum(bool(r["passed"]) for r in results.done.values())


def bench_lab_grade(students: int = 30) -> dict[str, Any]:
    """Wall-clock seconds to grade `students` submissions with 1 and 2 local workers (and on a 2-worker
    Dask LocalCluster when Dask is installed), the speed-up, and how many passed (half, each time)."""
    with tempfile.TemporaryDirectory(prefix="ttt-sm-bench-grade-") as tmp:
        subs = _class(Path(tmp) / "class", students)
        one, passed_1 = _timed(subs, Path(tmp) / "w1", workers=1)
        two, passed_2 = _timed(subs, Path(tmp) / "w2", workers=2)
        result: dict[str, Any] = {"lab_grade_students": students, "lab_grade_1_worker_s": round(one, 2),
                                  "lab_grade_2_workers_s": round(two, 2), "lab_grade_speedup": round(one / two, 2),
                                  "lab_grade_passed": [passed_1, passed_2]}
        try:
            from dask.distributed import Client, LocalCluster
        except ImportError:
            return result
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster, \
                Client(cluster) as client:
            on_dask, passed_d = _timed(subs, Path(tmp) / "dask", client=client)
        result["lab_grade_dask_2_workers_s"] = round(on_dask, 2)
        result["lab_grade_passed"].append(passed_d)
        return result
