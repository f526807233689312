"""The main job for now: the simulated arm draws a short path with the tuned loop.

Power-on, drives assumed initialised (the drive-initialisation charts come
with the chart runtime), a joint-space move from the power-on pose to a pose
above the board, a square drawn around the field's centre with the pen
pressed lightly into its spring, the pen lifted, and a report of how well the
true tool followed the desired path.  Later issues grow this into a game.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..params import ArmParams
from ..sched.scheduler import PathStage, Scheduler, tool_path
from ..sched.stages import JointMoveStage
from ..sched.trajectory import Waypoint, distance_to_path, sample_polyline, square_path
from ..twin.kinematics import HOME_Q, fk
from ..twin.plant import ArmSim


@dataclass(frozen=True)
class DrawDemoResult:
    """What the arm did while drawing the demo square."""

    seed: int
    square_side_mm: float
    speed_mm_s: float
    sim_time_s: float
    wall_time_s: float
    realtime_factor: float
    chart_ticks: int
    ik_failures: int
    limit_clamps: int
    drawing_rms_error_mm: float
    drawing_max_error_mm: float
    drawing_max_lag_mm: float
    final_tool_mm: tuple[float, float, float]


def run_draw_demo(params: ArmParams, seed: int = 0, speed: float = 0.02, side: float = 0.03,
                  progress: Callable[[str], None] | None = None) -> DrawDemoResult:
    """Bring the simulated arm through the demo path and measure it.

    Parameters
    ----------
    params : ArmParams
        The arm.
    seed : int
        Seeds the twin (power-on offsets, noise).
    speed : float
        Drawing speed, m/s.
    side : float
        Side of the square, m.
    progress : callable, optional
        Receives one line per phase.
    """
    say = progress or (lambda _msg: None)
    wall0 = time.perf_counter()
    sim = ArmSim(params, seed=seed)
    sched = Scheduler(params, sim, record=True)
    sched.assume_homed()
    chart_dt = params.control.chart_dt
    say(f"power-on pose q = {np.round(np.degrees(sim.q_true), 1).tolist()} deg; "
        "drives taken as initialised (init charts: see the chart runtime)")

    waypoints = square_path(params.board, side=side)
    first = waypoints[0]
    q_ready = sched.ik.solve(np.array([first.x, first.y, first.z, first.phi]),
                             q0=np.asarray(HOME_Q)).q
    q_start = np.array(sim.q_encoder.tolist() + [sim.q_true[3]])
    move = JointMoveStage(q_start, q_ready, chart_dt)
    sched.joint_stages = [move]
    say(f"moving above the board to q = {np.round(np.degrees(q_ready), 1).tolist()} deg")
    sched.run_until(lambda: move.done, timeout_s=30.0)
    sched.run_for(0.5)
    sched.joint_stages = []

    samples = sample_polyline(waypoints, speed=speed, dt=chart_dt)
    path = PathStage(samples)
    sched.task_stages = [path]
    sched.ik.solve(samples[0], q0=q_ready)
    n_before = len(sched.record.t) if sched.record else 0
    say(f"drawing a {side * 1000:.0f} mm square at {speed * 1000:.0f} mm/s, pen pressed 1 mm")
    sched.run_until(lambda: path.done, timeout_s=120.0)
    sched.run_for(0.5)

    rec = sched.record.arrays() if sched.record else {}
    task = rec["task"][n_before:]
    true_tool = tool_path(params, rec["q_true"][n_before:])
    drawing = task[:, 2] <= params.board.surface_z
    # Path error: how far the true tool (forward kinematics of the true joint
    # angles) strays from the desired square while the pen is down.  Lag: how
    # far it trails the desired point of the same instant (setpoint filters).
    square = samples[samples[:, 2] <= params.board.surface_z, :2]
    err = distance_to_path(true_tool[drawing, :2], square) * 1000
    lag = np.linalg.norm(true_tool[drawing, :2] - task[drawing, :2], axis=1) * 1000
    wall = time.perf_counter() - wall0
    tip = fk(sim.q_true, params.geometry)
    result = DrawDemoResult(
        seed=seed, square_side_mm=side * 1000, speed_mm_s=speed * 1000,
        sim_time_s=round(sim.t, 4), wall_time_s=round(wall, 3),
        realtime_factor=round(sim.t / wall, 1), chart_ticks=sched.chart_ticks,
        ik_failures=sched.ik_failures, limit_clamps=sched.limit_clamps,
        drawing_rms_error_mm=round(float(np.sqrt(np.mean(err**2))), 4),
        drawing_max_error_mm=round(float(err.max()), 4),
        drawing_max_lag_mm=round(float(lag.max()), 4),
        final_tool_mm=(round(float(tip[0]) * 1000, 2), round(float(tip[1]) * 1000, 2),
                       round(float(tip[2]) * 1000, 2)),
    )
    say(f"done: {result.sim_time_s:.1f} s simulated in {result.wall_time_s:.1f} s "
        f"({result.realtime_factor:.0f}x real time); drawing error rms {result.drawing_rms_error_mm:.3f} mm, "
        f"max {result.drawing_max_error_mm:.3f} mm (trailing the setpoint by up to "
        f"{result.drawing_max_lag_mm:.2f} mm)")
    return result


__all__ = ["DrawDemoResult", "Waypoint", "run_draw_demo"]
