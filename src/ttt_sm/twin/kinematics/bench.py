"""How fast and how reliably :class:`~ttt_sm.twin.kinematics.IKSolver` solves.

Three workloads, each timed per solve with ``time.perf_counter_ns`` after the
JIT has compiled:

* warm: along drawing paths (lines and arcs on the field, pen down and
  lifted, and a sponge pass), each target 0.1-0.2 mm from the one before,
  warm-started from the previous tick's solution, as the control loop does;
* offset: from the elbow-up solution with every joint 0.1 rad off;
* cold: from the home pose, over random reachable targets on the board volume
  (pen vertical, z from -5 mm to +6 cm; sponge down, tool z from
  ``sponge.offset`` - 5 mm to +8 cm), with a tenth of them exactly at full reach
  (elbow straight, a singular pose) and a tenth within 0.01 rad of it.

``bench_ik(params)`` returns the numbers docs/kinematics.md quotes.
"""

from __future__ import annotations

import math
import time

import numpy as np

from ttt_sm.params import ArmParams

from .closed_form import ik_closed_form
from .errors import IKError, UnreachableTargetError
from .solver import IKSolver

PHI_SPONGE = math.pi / 2


def _within_limits(q: np.ndarray, params: ArmParams) -> bool:
    return all(params.joint_min[j] <= q[j] <= params.joint_max[j] for j in range(4))


def _drawing_paths(params: ArmParams, rng: np.random.Generator) -> list[np.ndarray]:
    """Polylines of targets, consecutive points 0.1-0.2 mm apart."""
    b = params.board
    x0, x1, y0, y1 = b.field_bounds()
    paths = []

    def densify(points: list[tuple[float, float, float, float]]) -> np.ndarray:
        out = [np.array(points[0])]
        for p, q in zip(points[:-1], points[1:], strict=True):
            p_arr, q_arr = np.array(p), np.array(q)
            length = math.dist(p[:3], q[:3])
            s = 0.0
            while True:
                s += rng.uniform(1e-4, 2e-4)
                if s >= length:
                    break
                out.append(p_arr + (q_arr - p_arr) * s / length)
            out.append(q_arr)
        return np.array(out)

    for k in range(b.cells + 1):  # the field's lines, pen down, lifted between
        x = x0 + k * b.cell_size
        paths.append(densify([(x, y0, 0.02, 0.0), (x, y0, 0.0, 0.0), (x, y1, 0.0, 0.0), (x, y1, 0.02, 0.0)]))
    centre_x, centre_y, radius = b.field_center_x, b.field_center_y, 0.4 * b.cell_size
    arc = [(centre_x + radius * math.cos(a), centre_y + radius * math.sin(a), 0.0, 0.0)
           for a in np.linspace(0.0, 2 * math.pi, 200)]
    paths.append(densify(arc))
    z_sponge = b.surface_z + params.sponge.offset
    paths.append(densify([(x0, y0, z_sponge, PHI_SPONGE), (x0, y1, z_sponge, PHI_SPONGE),
                          (x1, y1, z_sponge, PHI_SPONGE)]))
    return paths


def cold_targets(params: ArmParams, rng: np.random.Generator, count: int) -> list[np.ndarray]:
    """Reachable targets on the board volume, a fifth of them at or next to full reach."""
    g, b = params.geometry, params.board
    bx0, bx1, by0, by1 = b.board_bounds()
    z_ranges = {0.0: (b.surface_z - 0.005, b.surface_z + 0.06),
                PHI_SPONGE: (b.surface_z + params.sponge.offset - 0.005, b.surface_z + 0.08)}
    targets: list[np.ndarray] = []
    while len(targets) < count:
        phi = 0.0 if rng.random() < 0.5 else PHI_SPONGE
        x, y = rng.uniform(bx0, bx1), rng.uniform(by0, by1)
        z_lo, z_hi = z_ranges[phi]
        kind = len(targets) % 10
        if kind < 8:
            z = rng.uniform(z_lo, z_hi)
        else:  # elbow straight (q3 = 0), or bent by at most 0.01 rad
            q3 = 0.0 if kind == 8 else -rng.uniform(1e-4, 1e-2)
            reach = math.sqrt(g.L2**2 + g.L3**2 + 2 * g.L2 * g.L3 * math.cos(q3))
            r = math.sqrt((x + g.l_f) ** 2 + y**2 - g.l_f**2)
            r_w = r - g.L4 * math.sin(phi)
            if r_w >= reach:
                continue
            z = g.L1 - g.L4 * math.cos(phi) - math.sqrt(reach**2 - r_w**2)
            if not z_lo <= z <= z_hi:
                continue
        target = np.array([x, y, z, phi])
        try:
            q = ik_closed_form(target, g)
        except UnreachableTargetError:
            continue
        if _within_limits(q, params):
            targets.append(target)
    return targets


def _timed(solver: IKSolver, target: np.ndarray, q0: np.ndarray | None = None) -> tuple[float, int]:
    start = time.perf_counter_ns()
    result = solver.solve(target, q0)
    return (time.perf_counter_ns() - start) / 1000.0, result.iterations


def bench_ik(params: ArmParams, seed: int = 0, cold_count: int = 1000) -> dict[str, float | int]:
    """Time the IK solver on warm, offset and cold workloads.

    Parameters
    ----------
    params : ArmParams
        The arm.
    seed : int
        Seeds the random targets, start offsets and path spacing.
    cold_count : int
        Number of cold targets.

    Returns
    -------
    dict
        ``ik_warm_median_us``, ``ik_warm_median_iterations``,
        ``ik_offset_median_us``, ``ik_offset_median_iterations``,
        ``ik_cold_success_rate`` (0..1), ``ik_cold_median_iterations``,
        ``ik_cold_median_us``, ``ik_cold_targets``.
    """
    rng = np.random.default_rng(seed)
    solver = IKSolver(params)
    cold = cold_targets(params, rng, cold_count)
    for target in cold[:20]:  # compile and warm the caches
        solver.reset()
        solver.solve(target)

    warm_us, warm_it = [], []
    for path in _drawing_paths(params, rng):
        solver.solve(path[0], ik_closed_form(path[0], params.geometry))
        for target in path[1:]:
            us, it = _timed(solver, target)
            warm_us.append(us)
            warm_it.append(it)

    offset_us, offset_it = [], []
    for target in cold[:300]:
        q0 = ik_closed_form(target, params.geometry) + 0.1 * rng.choice([-1.0, 1.0], 4)
        us, it = _timed(solver, target, q0)
        offset_us.append(us)
        offset_it.append(it)

    cold_us, cold_it, solved = [], [], 0
    for target in cold:
        solver.reset()
        try:
            us, it = _timed(solver, target)
        except IKError:
            continue
        solved += 1
        cold_us.append(us)
        cold_it.append(it)

    return {
        "ik_warm_median_us": float(np.median(warm_us)),
        "ik_warm_median_iterations": float(np.median(warm_it)),
        "ik_offset_median_us": float(np.median(offset_us)),
        "ik_offset_median_iterations": float(np.median(offset_it)),
        "ik_cold_success_rate": solved / len(cold),
        "ik_cold_median_iterations": float(np.median(cold_it)) if cold_it else math.nan,
        "ik_cold_median_us": float(np.median(cold_us)) if cold_us else math.nan,
        "ik_cold_targets": len(cold),
    }


if __name__ == "__main__":
    from ttt_sm.params import load_params

    for key, value in bench_ik(load_params()).items():
        print(f"{key:30s} {value:.4g}")
