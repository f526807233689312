"""The long sweeps on a pool or a cluster: ``ttt-sm init --workers/--dask`` and ``ttt-sm faults --workers``
report what the serial run reports for the same seed; a Ctrl-C prints the runs done so far and exits with 130.

Few starts and few cells keep each run short; what is compared is everything the runs measured (the wall
times and the runner's own keys aside), never a number written here.
"""

from __future__ import annotations

import json
import os
import pty
import select
import signal
import subprocess
import sys
import time
from typing import Any

import pytest

from ttt_sm.cli import main

#: What a report holds that depends on where and how fast it ran, not on what the runs did.
RUNNER_KEYS = {"wall_time_s", "workers", "backend", "throughput_per_worker", "runner", "load_average"}


def _run_json(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, dict[str, Any]]:
    status = main([*argv, "--json"])
    return status, json.loads(capsys.readouterr().out)


def _measured(report: dict[str, Any]) -> dict[str, Any]:
    """What the runs measured: the report without its runner's keys and wall times (a cell's too)."""
    kept = {k: v for k, v in report.items() if k not in RUNNER_KEYS}
    if "cells" in kept:
        kept["cells"] = [{k: v for k, v in c.items() if k != "wall_s"} for c in kept["cells"]]
    return kept


INIT = ("init", "--starts", "3", "--seed", "11")


@pytest.fixture(scope="module")
def serial_init() -> dict[str, Any]:
    """``ttt-sm init --starts 3 --seed 11`` in this process, one start after another."""
    import contextlib
    import io

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        status = main([*INIT, "--json"])
    report = json.loads(out.getvalue())
    assert status == 0 and report["runs"] == 3 and report["workers"] == 1 and report["backend"] == "local"
    return report


def test_init_on_two_workers_reports_what_one_does(serial_init: dict[str, Any],
                                                   capsys: pytest.CaptureFixture[str]) -> None:
    status, pooled = _run_json(capsys, *INIT, "--workers", "2")
    assert status == 0
    assert pooled["workers"] == 2 and pooled["backend"] == "local" and pooled["interrupted"] is False
    assert pooled["throughput_per_worker"] == pytest.approx(3 / pooled["wall_time_s"] / 2, rel=0.05)
    assert _measured(pooled) == _measured(serial_init)


@pytest.mark.soak  # starts a LocalCluster
def test_init_on_a_dask_cluster_reports_what_one_worker_does(serial_init: dict[str, Any],
                                                             capsys: pytest.CaptureFixture[str]) -> None:
    distributed = pytest.importorskip("dask.distributed", reason="Dask is not installed (the cluster extra)")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=":0") as cluster:
        status, on_dask = _run_json(capsys, *INIT, "--dask", cluster.scheduler_address)
    assert status == 0
    assert on_dask["workers"] == 2 and on_dask["backend"] == "dask"
    assert _measured(on_dask) == _measured(serial_init)


def test_faults_on_two_workers_give_the_cells_of_the_serial_run(capsys: pytest.CaptureFixture[str]) -> None:
    argv = ("faults", "--only", "encoder_jump,current_spike", "--phases", "init")
    status_1, serial = _run_json(capsys, *argv)
    status_2, pooled = _run_json(capsys, *argv, "--workers", "2")
    assert (status_1, status_2) == (0, 0)
    assert [(c["fault"], c["phase"]) for c in pooled["cells"]] == [("encoder_jump", "initialising"),
                                                                  ("current_spike", "initialising")]
    assert _measured(pooled) == _measured(serial)
    assert serial["runner"] == pooled["runner"] == "local" and (serial["workers"], pooled["workers"]) == (1, 2)
    assert pooled["backend"] == serial["backend"]  # the arm's, as before


def _one_line(capsys: pytest.CaptureFixture[str], argv: list[str]) -> str:
    status = main(argv)
    err = capsys.readouterr().err
    assert status == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    return err


def test_the_link_faults_refuse_a_pool_saying_why(capsys: pytest.CaptureFixture[str]) -> None:
    err = _one_line(capsys, ["faults", "--link", "--workers", "2"])
    assert "--workers 2: the link's faults run in real time, one after another" in err


def test_an_arm_behind_a_link_refuses_a_pool(capsys: pytest.CaptureFixture[str]) -> None:
    err = _one_line(capsys, ["init", "--arm", "serial:/dev/null", "--starts", "1", "--workers", "2"])
    assert "--workers 2: an arm behind a serial link initialises once" in err


def test_init_accepts_ten_thousand_starts_and_no_more(capsys: pytest.CaptureFixture[str]) -> None:
    err = _one_line(capsys, ["init", "--starts", "10001"])
    assert "--starts must lie in 1..10000, got 10001" in err


def _descendants(pid: int) -> list[Any]:
    import psutil

    try:
        return psutil.Process(pid).children(recursive=True)
    except psutil.NoSuchProcess:
        return []


def test_ctrl_c_prints_the_starts_done_so_far_and_exits_130(tmp_path) -> None:
    """SIGINT once the first start is done (the k/N status line, shown on a terminal: stderr is a pty)."""
    import psutil

    master, slave = pty.openpty()
    argv = [sys.executable, "-m", "ttt_sm.cli", "init", "--starts", "50", "--workers", "2", "--json"]
    proc = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=slave, cwd=tmp_path,
                            env={**os.environ, "PYTHONDONTWRITEBYTECODE": "1"})
    os.close(slave)
    terminal = ""
    children: list[Any] = []
    deadline = time.monotonic() + 180
    try:
        while "1/50 init" not in terminal and time.monotonic() < deadline and proc.poll() is None:
            ready, _, _ = select.select([master], [], [], 1.0)
            if ready:
                terminal += os.read(master, 65536).decode(errors="replace")
            children = _descendants(proc.pid) or children
        assert "1/50 init" in terminal, terminal
        assert len(children) >= 2  # the pool's workers (and its fork server)
        proc.send_signal(signal.SIGINT)
        out, _ = proc.communicate(timeout=60)
        while select.select([master], [], [], 0.2)[0]:
            try:
                chunk = os.read(master, 65536)
            except OSError:  # the last writer closed the terminal
                break
            if not chunk:
                break
            terminal += chunk.decode(errors="replace")
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        os.close(master)
    assert proc.returncode == 130, terminal
    assert "Traceback" not in terminal and "ttt-sm init: interrupted" in terminal
    report = json.loads(out)
    assert report["interrupted"] is True and 0 < report["runs"] < 50
    assert report["successes"] == report["runs"] and report["workers"] == 2
    _, alive = psutil.wait_procs(children, timeout=15)
    assert alive == [], [p.cmdline() for p in alive]


def test_the_init_sweep_bench_times_each_runner_on_the_same_starts(params, monkeypatch) -> None:
    from ttt_sm.bench import OPT_IN, bench_init_sweep

    assert "init_sweep" in OPT_IN  # minutes long at its default: run only when named
    monkeypatch.setitem(sys.modules, "dask.distributed", None)  # the LocalCluster part is the Dask test's above
    result = bench_init_sweep(params, starts=2, seed=4)
    assert result["init_sweep_successes"] == [2, 2] and result["init_sweep_same_report"] is True
    for name in ("1_worker", "2_workers"):
        wall = result[f"init_sweep_{name}_wall_s"]
        workers = 1 if name == "1_worker" else 2
        assert result[f"init_sweep_{name}_starts_per_s_per_worker"] == pytest.approx(2 / wall / workers, rel=0.05)
    assert "init_sweep_dask_2_workers_wall_s" not in result


@pytest.mark.parametrize(("argv", "why"), [
    (("faults", "--link", "--workers", "2"), "--workers 2: the link's faults run in real time"),
    (("faults", "--link", "--dask", "tcp://127.0.0.1:1"), "--dask: the link's faults run in real time"),
    (("init", "--starts", "1", "--arm", "serial:/dev/ttt-sm-no-such-port", "--workers", "2"),
     "--workers 2: an arm behind a serial link initialises once, in this process; drop --workers 2"),
])
def test_runs_that_must_stay_in_this_process_refuse_a_pool_or_a_cluster(capsys: pytest.CaptureFixture[str],
                                                                         argv: tuple[str, ...], why: str) -> None:
    assert main(list(argv)) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and why in err[0], err
