"""Independent tasks run here, on a local pool or on a Dask cluster, their results yielded as they complete.

The long sweeps (``ttt-sm init --starts N``: one initialisation per power-on
pose; ``ttt-sm faults``: one cell per fault and phase) and ``ttt-sm lab
grade`` (one student per task) are made of tasks that share nothing, so each
can run anywhere.  :class:`Runner` is where they run:

- ``workers=1`` with ``pool="process"``: one after another in this process
  (what the sweeps did before they had a pool: no start-up, same results);
- a local pool of ``workers`` processes (``pool="process"``: the sweeps,
  which compute in Python and numba and would share one interpreter lock as
  threads), or of threads (``pool="thread"``: the grader, whose tasks each
  wait on a child process of their own);
- a Dask cluster (``client``: a ``dask.distributed.Client``, see
  :func:`dask_client`), each task a ``client.submit``.

:meth:`Runner.run` yields ``(index, result)`` pairs in the order the tasks
complete; the caller puts them back in order if it needs to, so a sweep's
report is the same whatever the runner.  Closing the generator (a Ctrl-C in
the loop that reads it, or a ``break``) cancels the tasks not yet started
and stops those running: the pool's processes are terminated, the
cluster's tasks cancelled.  A task that raises, or that the pool or the
cluster loses (its process died), becomes the result the caller's ``lost``
makes of the exception: one failed task never takes the run down.

The processes of a local pool are started by a fork server (a clean process
that imported the ``preload`` modules once, so each worker starts with them
imported: ``ttt_sm`` and numba take ~3 s to import) and ignore Ctrl-C: the
terminal sends it to every process of the command, and it is the parent's to
handle (it stops the workers).  Each worker still loads numba's compiled
kernels from the on-disk cache on its first task (~1 s).
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import time
from collections.abc import Callable, Generator, Sequence
from concurrent.futures import FIRST_COMPLETED, Executor, Future, ProcessPoolExecutor, ThreadPoolExecutor, wait
from typing import Any, Literal, TypeVar

R = TypeVar("R")

#: How long the local pool waits for a result before it looks again (a Ctrl-C lands between two waits), s.
_POLL_S = 0.5


class RunnerError(ValueError):
    """A runner that cannot run: Dask missing, a scheduler out of reach, a pool of no workers."""


def dask_client(address: str) -> Any:
    """A Dask client connected to the scheduler at `address`; a :class:`RunnerError` when Dask is missing
    or the scheduler cannot be reached."""
    try:
        from dask.distributed import Client
    except ImportError:
        raise RunnerError("--dask needs Dask: pip install 'ttt_sm[cluster]' (or 'dask[distributed]')") from None
    try:
        return Client(address, timeout="5s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise RunnerError(f"--dask {address}: cannot reach a Dask scheduler there ({' '.join(str(exc).split())})"
                          ) from None


def one_line(exc: BaseException) -> str:
    """An exception as one line: its type and message."""
    return f"{type(exc).__name__}: {' '.join(str(exc).split())}"


def _ignore_interrupts() -> None:
    """A pool process's start: Ctrl-C (sent to the whole process group by a terminal) is the parent's."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _pool_processes(pool: Executor) -> list[Any]:
    """The worker processes of a process pool (none for threads), taken before a shutdown forgets them."""
    # the pool's own table (Python 3.14's terminate_workers() reads it too); the pool drops it on shutdown
    return list((getattr(pool, "_processes", None) or {}).values())


def _terminate(processes: list[Any]) -> None:
    """Terminate a pool's worker processes: their tasks are pure computation, nothing to tidy up."""
    for process in processes:
        try:
            process.terminate()
        except (OSError, AttributeError, ValueError):  # gone already, or closed
            pass


class Runner:
    """Where independent tasks run: here, on `workers` local processes or threads, or on Dask's `client`.

    `preload`: modules the fork server of a process pool imports once, so that
    every worker starts with them (see the module's docstring).
    """

    def __init__(self, workers: int = 1, client: Any = None, pool: Literal["process", "thread"] = "process",
                 preload: Sequence[str] = ()) -> None:
        if client is None and workers < 1:
            raise RunnerError(f"--workers must be at least 1, got {workers}")
        self.client = client
        self.pool = pool
        self.preload = tuple(preload)
        self._workers = workers

    @property
    def backend(self) -> str:
        """``"dask"`` on a cluster, ``"local"`` on this machine."""
        return "local" if self.client is None else "dask"

    @property
    def workers(self) -> int:
        """How many tasks run at once: the local workers, or the cluster's worker threads now."""
        if self.client is None:
            return self._workers
        info = self.client.scheduler_info()
        return max(1, sum(int(w.get("nthreads", 1)) for w in info.get("workers", {}).values()))

    def describe(self) -> str:
        """The runner in a few words, for a progress line."""
        if self.client is None:
            return "in this process" if self._workers == 1 and self.pool == "process" \
                else f"on {self._workers} local {self.pool}es" if self.pool == "process" \
                else f"on {self._workers} local threads"
        return f"on the Dask cluster at {self.client.scheduler.address} ({self.workers} worker threads)"

    def run(self, fn: Callable[..., R], tasks: Sequence[tuple[Any, ...]],
            lost: Callable[[int, BaseException], R], stop: Callable[[], None] | None = None,
            name: str = "ttt-sm") -> Generator[tuple[int, R], None, None]:
        """``fn(*tasks[i])`` for every i: yield ``(i, result)`` as each completes.

        A task that raises, or that the pool or cluster loses, yields ``lost(i,
        exception)`` instead.  Closing the generator cancels what has not run
        and stops what runs; `stop` is then called after the tasks not yet
        started are cancelled and before the runner waits for those running
        (a task that waits on something of the caller's, as the grader's
        threads wait on their children, is released by it).  `name` prefixes
        the Dask task keys.
        """
        if self.client is not None:
            return self._on_dask(fn, tasks, lost, name)
        if self._workers == 1 and self.pool == "process":
            return self._here(fn, tasks, lost)
        return self._on_pool(fn, tasks, lost, stop)

    def sweep(self, fn: Callable[..., R], tasks: Sequence[tuple[Any, ...]], lost: Callable[[int, BaseException], R],
              report: Callable[[list[R], bool], dict[str, Any]], name: str,
              status: Callable[[str], None] | None = None,
              said: Callable[[R, list[R]], str] = lambda result, done: "done") -> dict[str, Any]:
        """:meth:`run` the tasks, and the `report` of their results in the tasks' order (False: not interrupted).

        `status` hears ``k/N name: said(result, results so far)`` as each
        completes.  A Ctrl-C (or SIGTERM) stops what runs and raises
        :class:`SweepInterrupted` holding the report of those done (True).
        """
        done: dict[int, R] = {}
        if status is not None:
            status(f"0/{len(tasks)} {name}: starting {self.describe()}")
        stream = self.run(fn, tasks, lost, name=f"ttt-sm-{name}")
        try:
            for i, result in stream:
                done[i] = result
                if status is not None:
                    status(f"{len(done)}/{len(tasks)} {name}: {said(result, list(done.values()))}")
        except KeyboardInterrupt as exc:
            stream.close()
            raise SweepInterrupted(report([done[i] for i in sorted(done)], True), exc) from None
        finally:
            stream.close()
        return report([done[i] for i in sorted(done)], False)

    @staticmethod
    def _here(fn: Callable[..., R], tasks: Sequence[tuple[Any, ...]],
              lost: Callable[[int, BaseException], R]) -> Generator[tuple[int, R], None, None]:
        for i, args in enumerate(tasks):
            try:
                result = fn(*args)
            except Exception as exc:
                result = lost(i, exc)
            yield i, result

    def _executor(self) -> Executor:
        if self.pool == "thread":
            return ThreadPoolExecutor(max_workers=self._workers, thread_name_prefix="ttt-sm-runner")
        methods = multiprocessing.get_all_start_methods()
        context = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
        if self.preload and context.get_start_method() == "forkserver":
            context.set_forkserver_preload(list(self.preload))  # (no effect once this process's server runs)
        return ProcessPoolExecutor(max_workers=self._workers, mp_context=context, initializer=_ignore_interrupts)

    def _on_pool(self, fn: Callable[..., R], tasks: Sequence[tuple[Any, ...]],
                 lost: Callable[[int, BaseException], R], stop: Callable[[], None] | None
                 ) -> Generator[tuple[int, R], None, None]:
        pool = self._executor()
        finished_all = False
        try:
            index: dict[Future[R], int] = {pool.submit(fn, *args): i for i, args in enumerate(tasks)}
            pending = set(index)
            while pending:
                done, pending = wait(pending, timeout=_POLL_S, return_when=FIRST_COMPLETED)
                for future in sorted(done, key=index.__getitem__):
                    try:
                        result = future.result()
                    except Exception as exc:  # the task raised, or its process died (BrokenProcessPool)
                        result = lost(index[future], exc)
                    yield index[future], result
            finished_all = True
        finally:
            if finished_all:
                pool.shutdown(wait=True)
            else:
                processes = _pool_processes(pool)
                pool.shutdown(wait=False, cancel_futures=True)
                if stop is not None:
                    stop()
                _terminate(processes)
                pool.shutdown(wait=True)

    def _on_dask(self, fn: Callable[..., R], tasks: Sequence[tuple[Any, ...]],
                 lost: Callable[[int, BaseException], R], name: str) -> Generator[tuple[int, R], None, None]:
        from dask.distributed import as_completed

        stamp = f"{os.getpid()}-{time.time_ns()}"
        futures = [self.client.submit(fn, *args, key=f"{name}-{i}-{stamp}", pure=False, retries=0)
                   for i, args in enumerate(tasks)]
        index = {f.key: i for i, f in enumerate(futures)}
        try:
            for future in as_completed(futures):
                try:
                    result = future.result()
                except Exception as exc:  # the task raised, or the cluster lost it (its worker died)
                    result = lost(index[future.key], exc)
                yield index[future.key], result
        finally:
            self.client.cancel([f for f in futures if not f.done()])


class SweepInterrupted(KeyboardInterrupt):
    """A Ctrl-C (or SIGTERM) stopped a sweep: `report` is what the runs done so far measured.

    It is still the interrupt (``signal`` names it, as the CLI's own
    interrupt does), so the command exits with 130 (143) after it has
    printed the partial report.
    """

    def __init__(self, report: dict[str, Any], cause: KeyboardInterrupt) -> None:
        super().__init__(str(getattr(cause, "signal", "SIGINT")))
        self.report = report
        self.signal = str(getattr(cause, "signal", "SIGINT"))


def throughput(runs: int, wall_s: float, workers: int) -> float:
    """Runs per second per worker, on the wall clock (0 when nothing ran)."""
    return round(runs / wall_s / workers, 4) if runs and wall_s > 0 else 0.0
