"""Time per solve of the IK race's methods (``ttt-sm bench`` section ``ik_race``; docs/kinematics.md, "Lab").

Targets: points of the playing field, each solved warm, from the solution of a
neighbour 1 mm away (as the arm solves along a stroke).  Every number is the
median over the targets of one solve's wall time, in microseconds; the batch
of each target is timed as a whole (``repeat`` calls) so that the clock's own
cost does not count.  Output only: nothing asserts on these.
"""

from __future__ import annotations

import time
from dataclasses import replace
from typing import Any

import numpy as np

from ttt_sm.params import ArmParams, IKParams

from .closed_form import ik_closed_form, solve_point
from .dls import damped_least_squares
from .race import THESIS_LAMBDA, THESIS_TOLERANCE, race
from .workspace import workspace


def _per_call_us(fn: Any, args: tuple[Any, ...], repeat: int, **kw: Any) -> float:
    t0 = time.perf_counter_ns()
    for _ in range(repeat):
        fn(*args, **kw)
    return (time.perf_counter_ns() - t0) / repeat / 1000.0


def bench_ik_race(params: ArmParams, targets: int = 50, repeat: int = 200, seed: int = 0) -> dict[str, Any]:
    """Median µs per solve of each race method, warm; and the workspace's compute time (ms)."""
    rng = np.random.default_rng(seed)
    g = params.geometry
    x0, x1, y0, y1 = params.board.field_bounds()
    pts = np.column_stack([rng.uniform(x0, x1, targets), rng.uniform(y0, y1, targets),
                           np.zeros(targets), np.zeros(targets)])
    thesis = IKParams(THESIS_LAMBDA, THESIS_TOLERANCE, params.ik.max_iterations)
    adaptive = replace(params.ik)
    race(pts[0], params)  # compile the solvers
    out: dict[str, list[float]] = {k: [] for k in ("analytic", "closed_form", "lm_fixed", "dls_adaptive")}
    for t in pts:
        q_near = ik_closed_form(t + [0.001, 0.0, 0.0, 0.0], g)
        x, y, z, phi = (float(v) for v in t)
        out["analytic"].append(_per_call_us(solve_point, (x, y, z, phi, g, True), repeat))
        out["closed_form"].append(_per_call_us(ik_closed_form, (t, g), repeat))
        out["lm_fixed"].append(_per_call_us(damped_least_squares, (t, q_near, g, thesis), repeat // 4,
                                            adaptive=False))
        out["dls_adaptive"].append(_per_call_us(damped_least_squares, (t, q_near, g, adaptive), repeat // 4,
                                                adaptive=True))
    twist = []
    for t in pts[:10]:
        q_near = ik_closed_form(t + [0.001, 0.0, 0.0, 0.0], g)
        r = race(t, params, q0=q_near)
        twist.append(r[-1].seconds * 1e6)
    t0 = time.perf_counter()
    workspace(params, resolution=64)
    ws_ms = (time.perf_counter() - t0) * 1e3
    res = {f"ik_race_{k}_warm_us": round(float(np.median(v)), 2) for k, v in out.items()}
    res["ik_race_twist_warm_us"] = round(float(np.median(twist)), 1)
    res["kinematics_workspace_compute_ms"] = round(ws_ms, 1)
    res["ik_race_targets"] = targets
    return res
