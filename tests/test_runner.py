"""The runner of independent tasks (ttt_sm.runner): every task's result once, whatever the pool; a task that
raises or whose process dies is its `lost` result; closing the stream stops what runs.

The tasks are functions of the standard library (a pool's process imports them by name), cheap and quick.
"""

from __future__ import annotations

import operator
import os
import time

import pytest

from ttt_sm.runner import Runner, RunnerError, throughput


def _lost(i: int, exc: BaseException) -> tuple[str, str]:
    return "lost", type(exc).__name__


@pytest.mark.parametrize("runner", [Runner(), Runner(2), Runner(3, pool="thread")],
                         ids=["here", "two processes", "three threads"])
def test_every_task_yields_its_own_result_once_and_a_raising_task_is_lost(runner: Runner) -> None:
    tasks = [(k, 2) for k in range(7)] + [(1, 0)]  # the last divides by zero
    got = list(runner.run(operator.truediv, tasks, _lost))
    assert sorted(i for i, _ in got) == list(range(len(tasks)))
    results = dict(got)
    assert [results[k] for k in range(7)] == [k / 2 for k in range(7)]
    assert results[7] == ("lost", "ZeroDivisionError")


def test_a_worker_process_that_dies_loses_its_task_not_the_run() -> None:
    got = dict(Runner(2).run(os.abort, [()], _lost))
    assert got == {0: ("lost", "BrokenProcessPool")}


def test_closing_the_stream_stops_the_tasks_that_run_and_cancels_the_rest() -> None:
    import psutil

    me = psutil.Process()
    before = {p.pid for p in me.children(recursive=True)}
    start = time.monotonic()
    stream = Runner(2).run(time.sleep, [(0.0,)] + [(60.0,)] * 6, _lost)
    assert next(stream) == (0, None)
    # the pool's processes are the fork server's children (the server and the resource tracker are ours)
    ours = {p.pid for p in me.children()}
    workers = [p for p in me.children(recursive=True) if p.pid not in before and p.pid not in ours]
    assert len(workers) == 2
    stream.close()
    assert time.monotonic() - start < 30  # not the minute a sleeping task takes
    _, alive = psutil.wait_procs(workers, timeout=10)
    assert alive == []


def test_a_pool_of_no_workers_is_refused() -> None:
    with pytest.raises(RunnerError, match="--workers must be at least 1, got 0"):
        Runner(0)


def test_throughput_is_runs_per_second_per_worker() -> None:
    assert throughput(10, 5.0, 2) == 1.0
    assert throughput(0, 0.0, 2) == 0.0
