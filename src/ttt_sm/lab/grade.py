"""``ttt-sm lab grade``: every student's chart of a class checked, each in a process of its own.

A class is a folder of submissions, one sub-folder per student (the folder's
name is the student's) holding the chart file of the exercise, as ``ttt-sm
lab start`` laid it out.  Each submission is one :class:`Job`, graded by
:func:`grade_one` in a fresh Python process (:mod:`.worker`) that limits its
own address space (``RLIMIT_AS``) and is killed, with anything it started,
when its wall-clock time is up: an endless loop in an action, a chart that
sleeps forever, one that eats all the memory or does not even parse is that
student's result line, and the grader goes on.

The jobs run on a local pool (:func:`grade_locally`, threads that each wait
on a child process) or on a Dask cluster (:func:`grade_on_dask`, the same
:func:`grade_one` as a task; the chart's text travels with the job, so the
workers need no shared folder), both through :class:`~ttt_sm.runner.Runner`,
the runner of the long sweeps too; the children and their limits are the
grader's own.  Each result is appended to
``results.jsonl`` as it arrives (:class:`ResultsFile`), and the reports are
built from that file (:mod:`.grade_report`): what was graded before a Ctrl-C
stays graded.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..params import shown_path
from ..runner import Runner, one_line
from ..runtime.recordfile import RecordFile
from .exercise import Exercise, LabError

#: The file of results, one JSON line per student, that the reports are built from.
RESULTS = "results.jsonl"
#: The largest chart file a job carries, bytes (a chart is a few kB).
MAX_CHART_BYTES = 1_000_000
#: The statuses a result can have, in the order the reports list them.
STATUSES = ("graded", "load error", "time limit", "memory limit", "crashed")
#: The child's environment beside the grader's: one thread per library, few malloc arenas, so that the
#: address space a chart may use is the chart's and not reserved by idle threads.
CHILD_ENV = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
             "NUMBA_NUM_THREADS": "1", "MALLOC_ARENA_MAX": "2", "PYTHONDONTWRITEBYTECODE": "1"}


class GradeError(LabError):
    """A class that cannot be graded (no submissions, a report folder of another exercise): one line."""


@dataclass(frozen=True)
class Limits:
    """What one submission may use: wall-clock seconds, megabytes of address space (0: no memory limit)."""

    timeout_s: float = 120.0
    memory_mb: int = 2048
    params_file: str | None = None


@dataclass(frozen=True)
class Job:
    """One student's submission: their name, the exercise, and their chart file's name and text."""

    student: str
    exercise: str
    file: str
    source: bytes | None  # None: the folder holds no chart file


def submissions(folder: Path, ex: Exercise) -> list[Job]:
    """A job per sub-folder of `folder` (by name); a :class:`GradeError` if there is none."""
    if not folder.is_dir():
        raise GradeError(f"{shown_path(folder)}: no such folder (a folder with one sub-folder per student)")
    jobs = []
    for sub in sorted(p for p in folder.iterdir() if p.is_dir() and not p.name.startswith(".")):
        chart = sub / ex.file
        source = None
        if chart.is_file():
            with chart.open("rb") as f:
                source = f.read(MAX_CHART_BYTES + 1)
        jobs.append(Job(sub.name, ex.name, ex.file, source))
    if not jobs:
        raise GradeError(f"{shown_path(folder)}: no sub-folders; put each student's folder"
                         f" (holding {ex.file}) in it")
    return jobs


def _kill(process: subprocess.Popen[bytes]) -> None:
    """Kill the child and whatever it started (it leads a session of its own)."""
    try:
        os.killpg(process.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    process.wait()


def _cpu_seconds(pid: int) -> float | None:
    """The processor time process `pid` has used, s (Linux's /proc; None elsewhere)."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError):
        return None


def _tail(text: bytes, lines: int = 1) -> str:
    last = [line for line in text.decode("utf-8", "replace").splitlines() if line.strip()][-lines:]
    return " ".join(" ".join(last).split())[:300]


def grade_one(job: Job, limits: Limits, running: Callable[[subprocess.Popen[bytes] | None], None] | None = None
              ) -> dict[str, Any]:
    """Grade `job` in a fresh child process within `limits`: the student's result line, as a dict.

    The child runs in a temporary folder holding ``<student>/<file>``, so what it
    says about the file reads ``alice/drive_init3.py:12: ...``.  `running` hears of
    the child when it starts and (with None) when it is gone (the local pool kills
    the children it hears of on Ctrl-C).  Never raises for anything the student wrote.
    """
    start = time.monotonic()
    base = {"student": job.student, "exercise": job.exercise, "status": "", "passed": False, "score": 0,
            "total": 0, "checks": [], "transitions": [], "taken": [], "error": ""}
    if job.source is None:
        return {**base, "status": "load error", "error": f"{job.student}/{job.file}: no such file", "seconds": 0.0}
    if len(job.source) > MAX_CHART_BYTES:
        return {**base, "status": "load error", "seconds": 0.0,
                "error": f"{job.student}/{job.file}: more than {MAX_CHART_BYTES} bytes: not a chart file"}
    with tempfile.TemporaryDirectory(prefix="ttt-sm-grade-") as tmp:
        home = Path(tmp) / "work"
        (home / job.student).mkdir(parents=True)
        (home / job.student / job.file).write_bytes(job.source)
        result_file = Path(tmp) / "result.json"
        argv = [sys.executable, "-m", "ttt_sm.lab.worker", job.exercise, f"{job.student}/{job.file}",
                "--result", str(result_file), "--memory", str(limits.memory_mb), "--cpu", str(limits.timeout_s)]
        if limits.params_file is not None:
            argv += ["--params", str(Path(limits.params_file).resolve())]
        with open(Path(tmp) / "stderr", "w+b") as err:
            process = subprocess.Popen(argv, cwd=home, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                                       stderr=err, env={**os.environ, **CHILD_ENV}, start_new_session=True)
            if running is not None:
                running(process)
            busy_s = None
            try:
                process.wait(timeout=limits.timeout_s)
                timed_out = False
            except subprocess.TimeoutExpired:
                timed_out = True
                busy_s = _cpu_seconds(process.pid)
            finally:
                _kill(process)
                if running is not None:
                    running(None)
            err.seek(0)
            stderr = err.read()
        seconds = round(time.monotonic() - start, 2)
        if timed_out or process.returncode == -signal.SIGXCPU:
            used = "" if busy_s is None else f" (it had used {busy_s:.1f} s of processor time)"
            return {**base, "status": "time limit", "seconds": seconds,
                    "error": f"still running after {limits.timeout_s:g} s: stopped{used}"}
        if result_file.is_file():
            try:
                found = json.loads(result_file.read_text(encoding="utf-8"))
            except ValueError:
                found = None
            if isinstance(found, dict) and found.get("status") in STATUSES:
                if found["status"] == "memory limit":
                    found["error"] += f" (limit {limits.memory_mb} MB)"
                return {**base, **found, "student": job.student, "exercise": job.exercise, "seconds": seconds}
        code = process.returncode
        why = f"killed by {signal.Signals(-code).name}" if code < 0 and -code in signal.valid_signals() \
            else f"exit status {code}"
        if b"MemoryError" in stderr or b"std::bad_alloc" in stderr or b"Cannot allocate memory" in stderr:
            return {**base, "status": "memory limit", "seconds": seconds,
                    "error": f"the chart ran out of memory: {why}"}
        tail = _tail(stderr)
        return {**base, "status": "crashed", "seconds": seconds,
                "error": f"the process ended without a result ({why})" + (f": {tail}" if tail else "")}


class ResultsFile:
    """``results.jsonl`` in the report folder: a header line naming the exercise, then a line per result.

    Each line is flushed as it is written, so a Ctrl-C (or a grader that is
    killed) leaves every result it had.  A rerun on the same folder reads the
    results there and grades only the students not yet in it.
    """

    def __init__(self, folder: Path, exercise: str, again: bool = False) -> None:
        self.path = folder / RESULTS
        self.exercise = exercise
        self.done: dict[str, dict[str, Any]] = {}
        if self.path.is_file() and not again:
            header, self.done = read_results(self.path)
            if header.get("exercise") != exercise:
                raise GradeError(f"{shown_path(self.path)} holds results of exercise {header.get('exercise')!r},"
                                 f" not {exercise!r}: choose another --out, or --again to start anew")
            self._record = RecordFile(self.path, append=True)
        else:
            self._record = RecordFile(self.path)
            self._record.add({"event": "grade", "exercise": exercise})
        self._lock = threading.Lock()

    def add(self, result: dict[str, Any]) -> None:
        with self._lock:
            self._record.add(result)
            self.done[result["student"]] = result

    def close(self) -> None:
        self._record.close()


def read_results(path: Path) -> tuple[dict[str, Any], dict[str, dict[str, Any]]]:
    """The header and the results by student (the last line of a student wins) of a ``results.jsonl``.

    A line cut short by a kill in the middle of writing it is skipped.
    """
    header: dict[str, Any] = {}
    results: dict[str, dict[str, Any]] = {}
    for line in path.read_text(encoding="utf-8").splitlines():
        try:
            doc = json.loads(line)
        except ValueError:
            continue
        if not isinstance(doc, dict):
            continue
        if doc.get("event") == "grade":
            header = doc
        elif isinstance(doc.get("student"), str) and doc.get("status") in STATUSES:
            results[doc["student"]] = doc
    if not header:
        raise GradeError(f"{shown_path(path)}: not a results file of ttt-sm lab grade (no header line)")
    return header, results


def _lost(job: Job, exc: BaseException) -> dict[str, Any]:
    """The result line of a student whose task raised or was lost (its worker died): crashed, saying why."""
    return {"student": job.student, "exercise": job.exercise, "status": "crashed", "passed": False,
            "score": 0, "total": 0, "checks": [], "transitions": [], "taken": [], "seconds": 0.0,
            "error": f"the grader lost the task: {one_line(exc)}"}


def grade_locally(jobs: list[Job], limits: Limits, workers: int) -> Iterator[dict[str, Any]]:
    """Grade `jobs` on `workers` children at a time; yield each result as it arrives.

    The pool (:class:`~ttt_sm.runner.Runner`) is of threads: each waits on the
    child that grades its submission.  Closing the generator (a Ctrl-C in the
    loop that reads it) cancels the jobs not yet started and kills the
    children that run.
    """
    children: set[subprocess.Popen[bytes]] = set()
    lock = threading.Lock()
    stopping = threading.Event()

    def run(job: Job) -> dict[str, Any]:
        mine: list[subprocess.Popen[bytes]] = []

        def track(process: subprocess.Popen[bytes] | None) -> None:
            with lock:
                if process is None:
                    children.discard(mine.pop())
                else:
                    mine.append(process)
                    children.add(process)
                    if stopping.is_set():
                        _kill(process)
        return grade_one(job, limits, track)

    def stop() -> None:
        stopping.set()
        with lock:
            for process in list(children):
                _kill(process)

    stream = Runner(workers, pool="thread").run(run, [(job,) for job in jobs], lambda i, exc: _lost(jobs[i], exc),
                                                stop=stop)
    try:
        for _, result in stream:
            yield result
    finally:
        stream.close()


def grade_on_dask(jobs: list[Job], limits: Limits, client: Any) -> Iterator[dict[str, Any]]:
    """Grade `jobs` as tasks of the Dask cluster behind `client`; yield each result as it arrives.

    Each task is :func:`grade_one`, so on the worker each submission still runs in
    a child process of its own with the same limits.  A task the cluster loses
    (its worker died) is that student's ``crashed`` line.  Closing the generator
    cancels the tasks not yet done.
    """
    stream = Runner(client=client).run(grade_one, [(job, limits) for job in jobs],
                                       lambda i, exc: _lost(jobs[i], exc), name="ttt-sm-grade")
    try:
        for _, result in stream:
            yield result
    finally:
        stream.close()


def summary_line(result: dict[str, Any]) -> str:
    """A result in one line: the student, and the score or what went wrong."""
    if result["status"] == "graded":
        verdict = "every check passed" if result["passed"] else "not yet"
        return f"{result['student']}: {result['score']}/{result['total']} {verdict} ({result['seconds']:g} s)"
    return f"{result['student']}: {result['status']}: {result['error']}"


def grade_class(jobs: Iterable[Job], limits: Limits, results: ResultsFile, workers: int = 1, client: Any = None,
                say: Callable[[str], None] | None = None) -> int:
    """Grade the `jobs` not yet in `results`, on the local pool or `client`'s cluster; the number graded now.

    Each result goes to `results` as it arrives and to `say` as ``k/N`` and
    its :func:`summary_line`.
    """
    todo = [job for job in jobs if job.student not in results.done]
    total = len(todo) + len(results.done)
    stream = grade_on_dask(todo, limits, client) if client is not None else grade_locally(todo, limits, workers)
    count = 0
    try:
        for result in stream:
            results.add(result)
            count += 1
            if say is not None:
                say(f"{len(results.done)}/{total} {summary_line(result)}")
    finally:
        close = getattr(stream, "close", None)
        if close is not None:
            close()
    return count
