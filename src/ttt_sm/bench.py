"""`ttt-sm bench`: the project's speed and quality targets, measured.

Tests never assert on wall-clock time; this command measures it and the
notes on each issue report what it printed.  Sections can be chosen with
`--only`; every section returns flat JSON-ready numbers.
"""

from __future__ import annotations

import os
import platform
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from .params import ArmParams
from .sched.clock import WallClock
from .sched.scheduler import PathStage, Scheduler
from .sched.trajectory import Waypoint, sample_polyline, square_path
from .twin.kinematics import HOME_Q, IKSolver
from .twin.sim import ArmSim


def _drawing_samples(params: ArmParams, seconds: float, speed: float = 0.03) -> np.ndarray:
    """Chart-rate poses of squares drawn over and over for about `seconds`."""
    one = sample_polyline(square_path(params.board, side=0.06), speed, params.control.chart_dt)
    reps = int(np.ceil(seconds / (len(one) * params.control.chart_dt))) + 1
    return np.vstack([one] * reps)


def _ready_sim(params: ArmParams, samples: np.ndarray, seed: int) -> tuple[ArmSim, Scheduler, PathStage]:
    """A twin standing at the path's first pose, drives homed, path loaded."""
    ik = IKSolver(params)
    q0 = ik.solve(samples[0], q0=np.asarray(HOME_Q)).q
    sim = ArmSim(params, seed=seed, q0=q0)
    sched = Scheduler(params, sim, ik=ik)
    sim.assume_initialised()  # simulation only: the true offsets, no init charts
    sched.mark_all_homed()
    path = PathStage(samples)
    sched.task_stages = [path]
    return sim, sched, path


def bench_loop(params: ArmParams, seconds: float = 20.0, seed: int = 0) -> dict[str, float]:
    """Closed loop on virtual time: plant + controllers + IK at the chart rate, no charts."""
    samples = _drawing_samples(params, seconds)
    sim, sched, _ = _ready_sim(params, samples, seed)
    sched.run_for(0.2)  # JIT warm-up and settling, not timed
    t_sim0 = sim.t
    wall0 = time.perf_counter()
    sched.run_for(seconds)
    wall = time.perf_counter() - wall0
    sim_s = sim.t - t_sim0
    steps = sim_s * params.control.rate_hz
    return {
        "loop_realtime_factor": round(sim_s / wall, 1),
        "loop_us_per_control_step": round(wall / steps * 1e6, 3),
        "loop_sim_seconds": round(sim_s, 3),
        "loop_ik_failures": sched.ik_failures,
    }


def bench_pacing(params: ArmParams, seconds: float = 10.0, seed: int = 0) -> dict[str, float]:
    """The same loop paced to the wall clock at the control rate."""
    samples = _drawing_samples(params, seconds)
    sim, sched, _ = _ready_sim(params, samples, seed)
    sched.run_for(0.1)  # warm-up on virtual time
    clock = WallClock(period_s=params.control.dt)
    sched.set_clock(clock)
    sched.run_for(seconds)
    st = clock.stats()
    return {
        "pacing_rate_hz": params.control.rate_hz,
        "pacing_seconds": seconds,
        "pacing_periods": st.periods,
        "pacing_deadline_misses": st.deadline_misses,
        "pacing_lateness_p50_us": round(st.lateness_p50_us, 1),
        "pacing_lateness_p99_us": round(st.lateness_p99_us, 1),
        "pacing_lateness_max_us": round(st.lateness_max_us, 1),
    }


def bench_ik_section(params: ArmParams, seed: int = 0) -> dict[str, Any]:
    """IK speed and robustness (see twin/kinematics/bench.py)."""
    from .twin.kinematics.bench import bench_ik

    return bench_ik(params, seed=seed)


def bench_ik_race_section(params: ArmParams, seed: int = 0, quick: bool = False) -> dict[str, Any]:
    """Time per solve of the IK race's methods (see twin/kinematics/race_bench.py)."""
    from .twin.kinematics.race_bench import bench_ik_race

    return bench_ik_race(params, targets=10 if quick else 50, seed=seed)


def bench_motion_lab_section(params: ArmParams, seed: int = 0, quick: bool = False) -> dict[str, Any]:
    """The kinematics lab's trajectories and forces (see twin/motion_bench.py)."""
    from .twin.motion_bench import bench_motion_lab

    return bench_motion_lab(params, seed=seed, quick=quick)


def bench_steps(params: ArmParams, out_dir: Path) -> dict[str, Any]:
    """Step responses of the three drives on the nonlinear plant (as `ttt-sm tune`)."""
    from .twin.step_response import tune_report

    rows = tune_report(params, out_dir)
    return {"step_responses": rows}


def bench_charts(params: ArmParams) -> dict[str, float]:
    """Cost of a quiet chart tick against the same tick through send() (runtime)."""
    from .runtime.bench import bench_quiet_tick

    result = dict(bench_quiet_tick())
    if "speedup" in result:
        result["chart_quiet_tick_speedup"] = result.pop("speedup")
    return result


def bench_init(params: ArmParams, starts: int, seed: int = 0) -> dict[str, Any]:
    """`ttt-sm init --starts N`: the init charts from random power-on poses."""
    from .app.init_wiring import init_report

    report = init_report(params, starts, seed=seed)
    return {f"init_{k}": v for k, v in report.items()}


def bench_game_motion(params: ArmParams, seed: int = 0) -> dict[str, Any]:
    """The field, 12 symbols and erasing through the Control chart, on virtual time."""
    from .app.play import game_motion

    return game_motion(params, seed=seed)


def bench_vision_section(params: ArmParams, seed: int = 0) -> dict[str, Any]:
    """Camera vision: accuracy on 200 simulated photos and the detection time per frame."""
    from .vision.bench import bench_vision

    return bench_vision(seed)


def bench_ai_section(params: ArmParams, seed: int = 0) -> dict[str, Any]:
    """The game engines' move times and the strong engine's start-up."""
    from .game.bench import bench_ai

    return bench_ai(seed)


def bench_game(params: ArmParams, seed: int = 0, games: int = 3) -> dict[str, Any]:
    """Whole simulated games (seeds `seed`, `seed` + 1, ...), the camera behind the pty serial emulator.

    ``game_realtime_factor`` is the games' simulated time over their wall
    time together; ``game_realtime_factor_min`` the slowest game's.
    """
    from .app.game import GameSession

    reports = []
    for k in range(games):
        session = GameSession(params, seed=seed + k, camera="serial", record_trace=False)
        try:
            reports.append(session.play())
        finally:
            session.close()
    sim = sum(r["sim_time_s"] for r in reports)
    wall = sum(r["wall_time_s"] for r in reports)
    return {
        "game_games": games,
        "game_winners": [r["winner"] for r in reports],
        "game_detections_correct": sum(r["detections_correct"] for r in reports),
        "game_detections_wrong": sum(r["detections_wrong"] for r in reports),
        "game_sim_time_s": round(sim, 3),
        "game_wall_time_s": round(wall, 3),
        "game_realtime_factor": round(sim / wall, 1),
        "game_realtime_factor_min": min(r["realtime_factor"] for r in reports),
        "game_setup_wall_s": max(r["setup_wall_s"] for r in reports),
        "game_camera_wall_s": round(sum(r["camera_wall_s"] for r in reports), 3),
        "game_erased": all(r["erased"] for r in reports),
    }


def bench_gui_section(params: ArmParams, seed: int = 0, quick: bool = False, soak_min: float = 0.0) -> dict[str, Any]:
    """The browser cockpit in Chromium: frame latency at x1, speed with a page attached, frame size
    (see ttt_sm/web/bench.py); ``soak_min`` adds the memory after 1 and after that many minutes at x10."""
    from .web.bench import bench_gui

    return bench_gui(params, seed=seed, x1_s=10.0 if quick else 60.0, max_s=3.0 if quick else 15.0,
                     soak_min=soak_min, plot_s=5.0 if quick else 30.0)


def bench_lab_grade_section(quick: bool = False) -> dict[str, Any]:
    """``ttt-sm lab grade``: a class of 30 (6 when `quick`) with 1 and 2 workers, and on a Dask LocalCluster."""
    from .lab.grade_bench import bench_lab_grade

    return bench_lab_grade(6 if quick else 30)


#: What the init_sweep section compares between its runners: the report without wall times and the runner's keys.
_RUNNER_KEYS = ("wall_time_s", "workers", "backend", "throughput_per_worker")


def bench_init_sweep(params: ArmParams, starts: int = 40, seed: int = 0) -> dict[str, Any]:
    """``ttt-sm init --starts N`` on the runner (ttt_sm/runner.py): in this process, on a local pool of 2
    processes, and on a 2-worker Dask LocalCluster (when Dask is installed), side by side.

    Reports each one's wall time and starts per second per worker (the pool's
    and the cluster's include their workers' start-up: importing ttt_sm and
    loading numba's cached kernels), and whether the three reports agree on
    everything the runs measured (they must: the runner changes the wall time only).
    """
    from .app.init_wiring import INIT_PRELOAD, init_report
    from .runner import Runner
    from .twin.gains_cache import kept_gains

    def measured(report: dict[str, Any]) -> dict[str, Any]:
        return {k: v for k, v in report.items() if k not in _RUNNER_KEYS}

    result: dict[str, Any] = {"init_sweep_starts": starts, "init_sweep_cpus": os.cpu_count()}
    kept_gains(params)  # designed (or read) once per process whatever the runner: not in the first runner's time
    reports = {}
    for name, runner in (("1_worker", Runner(1)), ("2_workers", Runner(2, preload=INIT_PRELOAD))):
        reports[name] = init_report(params, starts, seed=seed, runner=runner)
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        pass
    else:
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster, \
                Client(cluster) as client:
            reports["dask_2_workers"] = init_report(params, starts, seed=seed, runner=Runner(client=client))
    for name, report in reports.items():
        result[f"init_sweep_{name}_wall_s"] = report["wall_time_s"]
        result[f"init_sweep_{name}_starts_per_s_per_worker"] = report["throughput_per_worker"]
    result["init_sweep_successes"] = [r["successes"] for r in reports.values()]
    first = measured(reports["1_worker"])
    result["init_sweep_same_report"] = all(measured(r) == first for r in reports.values())
    return result


def bench_link_section(params: ArmParams, seconds: float, seed: int = 0) -> dict[str, Any]:
    """The serial link at the chart rate against the emulator in real time (ttt_sm/hardware/linkbench.py)."""
    from .hardware.linkbench import bench_link

    return bench_link(params, seconds=seconds, seed=seed)


SECTIONS: dict[str, Callable[..., dict[str, Any]]] = {
    "steps": lambda p, a: bench_steps(p, a["out"]),
    "ik": lambda p, a: bench_ik_section(p, a["seed"]),
    "ik_race": lambda p, a: bench_ik_race_section(p, a["seed"], a["quick"]),
    "motion_lab": lambda p, a: bench_motion_lab_section(p, a["seed"], a["quick"]),
    "loop": lambda p, a: bench_loop(p, a["loop_seconds"], a["seed"]),
    "pacing": lambda p, a: bench_pacing(p, a["pacing_seconds"], a["seed"]),
    "charts": lambda p, a: bench_charts(p),
    "init": lambda p, a: bench_init(p, a["init_starts"], a["seed"]),
    "motion": lambda p, a: bench_game_motion(p, a["seed"]),
    "vision": lambda p, a: bench_vision_section(p, a["seed"]),
    "ai": lambda p, a: bench_ai_section(p, a["seed"]),
    "game": lambda p, a: bench_game(p, a["seed"], a["games"]),
    "gui": lambda p, a: bench_gui_section(p, a["seed"], a["quick"], a["gui_soak_min"]),
    "link": lambda p, a: bench_link_section(p, a["link_seconds"], a["seed"]),
    "lab_grade": lambda p, a: bench_lab_grade_section(a["quick"]),
    "init_sweep": lambda p, a: bench_init_sweep(p, a["sweep_starts"], a["seed"]),
}
#: Sections run only when ``--only`` names them (minutes long, and not a target of the robot's speed).
OPT_IN = ("lab_grade", "init_sweep")


def run_bench(params: ArmParams, only: list[str] | None = None, seed: int = 0, quick: bool = False,
              out: Path = Path("out/bench"), progress: Callable[[str], None] | None = None,
              gui_soak_min: float = 0.0,
              on_section: Callable[[str, dict[str, Any] | None], None] | None = None,
              link_minutes: float | None = None, sweep_starts: int | None = None) -> dict[str, Any]:
    """Run the chosen sections (all by default) and return one flat result dict.

    `quick` shortens the timed runs (for tests of the command, not for the
    numbers reported on issues).  ``on_section(name, None)`` hears of a
    section starting, ``on_section(name, values)`` of its results (the
    command line writes them to ``bench.jsonl`` as they come).
    `link_minutes`: how long the link section streams (default 10 minutes,
    as issue 13 asks; 5 s when `quick`).  `sweep_starts`: the init_sweep
    section's starts on each runner (default 40; 6 when `quick`).
    """
    names = only or [n for n in SECTIONS if n not in OPT_IN]
    unknown = [n for n in names if n not in SECTIONS]
    if unknown:
        raise ValueError(f"unknown bench section(s) {', '.join(unknown)}; choose from {', '.join(SECTIONS)}")
    args = {"seed": seed, "out": out, "loop_seconds": 2.0 if quick else 20.0,
            "pacing_seconds": 1.0 if quick else 10.0, "init_starts": 5 if quick else 200,
            "games": 1 if quick else 3, "quick": quick, "gui_soak_min": gui_soak_min,
            "link_seconds": 60.0 * link_minutes if link_minutes is not None else 5.0 if quick else 600.0,
            "sweep_starts": sweep_starts if sweep_starts is not None else 6 if quick else 40}
    result: dict[str, Any] = {
        "machine": {"python": platform.python_version(), "cpus": os.cpu_count(),
                    "load_avg_before": [round(x, 2) for x in os.getloadavg()],
                    "numba_jit": os.environ.get("NUMBA_DISABLE_JIT", "0") != "1"},
        "quick": quick,
    }
    for name in names:
        if progress:
            progress(f"bench: {name} ...")
        if on_section is not None:
            on_section(name, None)
        values = SECTIONS[name](params, args)
        result.update(values)
        if on_section is not None:
            on_section(name, values)
    if "gui_realtime_factor_max" in result and "game_motion_realtime_factor" in result:
        # the target: as fast as it goes with a page attached, against the same run's motion
        result["gui_realtime_ratio_to_motion"] = round(
            result["gui_realtime_factor_max"] / result["game_motion_realtime_factor"], 2)
    if "gui_game_realtime_factor" in result and "game_realtime_factor" in result:
        # a whole game with the /game page attached, beside the same run's headless games
        result["gui_game_ratio_to_game"] = round(result["gui_game_realtime_factor"] / result["game_realtime_factor"], 2)
    result["machine"]["load_avg_after"] = [round(x, 2) for x in os.getloadavg()]
    return result


__all__ = ["Waypoint", "run_bench", "bench_loop", "bench_pacing"]
