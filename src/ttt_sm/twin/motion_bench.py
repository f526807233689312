"""Costs of the kinematics lab's motion views (``ttt-sm bench`` section ``motion_lab``; docs/kinematics.md).

Trajectory generation (:func:`~ttt_sm.twin.trajectories.task_targets`, per chart tick, each
method), one move on the twin (:func:`~ttt_sm.twin.trajectories.run_move`, how much
faster than real time), and one line drawn with the pen's spring and its force estimated
(:func:`~ttt_sm.twin.forces.force_run`) with the estimate's error.  Wall times are output
only: nothing asserts on them.
"""

from __future__ import annotations

import time
from typing import Any

from ..params import ArmParams
from .forces import force_run
from .trajectories import METHODS, PRESS_M, move_duration, run_move, task_targets


def bench_motion_lab(params: ArmParams, seed: int = 0, quick: bool = False) -> dict[str, Any]:
    """µs per chart tick of each method's targets; ms and real-time factor of a move; the force run's numbers."""
    b = params.board
    cx, cy = b.field_center_x, b.field_center_y
    z = b.surface_z - PRESS_M
    a, e = (cx - 0.025, cy - 0.025, z), (cx + 0.025, cy + 0.025, z)
    dt = params.control.chart_dt
    n = int(move_duration(a, e, 0.02) / dt)
    res: dict[str, Any] = {}
    repeat = 20 if quick else 200
    for m in METHODS:
        task_targets(m, a, e, 0.02, dt, n)
        t_ns = time.perf_counter_ns()
        for _ in range(repeat):
            task_targets(m, a, e, 0.02, dt, n)
        res[f"trajectory_{m}_us_per_tick"] = round((time.perf_counter_ns() - t_ns) / repeat / n / 1000.0, 4)
    run_move(params, "cubic", a, e, hold_s=0.1, seed=seed)  # compile and warm
    t0 = time.perf_counter()
    r = run_move(params, "cubic", a, e, hold_s=0.5, seed=seed)
    wall = time.perf_counter() - t0
    res["trajectory_run_move_ms"] = round(wall * 1e3, 1)
    res["trajectory_run_move_realtime_factor"] = round(float(r.t[-1]) / wall, 1)
    t0 = time.perf_counter()
    fr = force_run(params, a[:2], e[:2], seed=seed)
    res["forces_run_ms"] = round((time.perf_counter() - t0) * 1e3, 1)
    err = fr.errors()
    res["forces_estimate_mean_rel"] = None if err["mean_rel"] is None else round(err["mean_rel"], 4)
    res["forces_estimate_p95_rel"] = None if err["p95_rel"] is None else round(err["p95_rel"], 4)
    res["forces_estimate_all_mean_rel"] = None if err["all_mean_rel"] is None else round(err["all_mean_rel"], 4)
    res["forces_observable_share"] = round(err["observable_share"], 3)
    return res
