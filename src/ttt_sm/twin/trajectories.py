"""Trajectories compared on the twin: the thesis' constant increments against cubic and quintic polynomials.

The kinematics lab's "Trajectories" view (docs/kinematics.md, "Lab: trajectories and
forces").  One straight move of the pen tip from ``a`` to ``b`` (m), four ways to
turn it into setpoints, one per chart tick:

* ``increment``: the thesis' drawing, eq. 3.36 (``X_out = X_out_p + inc``, section
  3.6.1): the target moves by a constant increment every chart tick, with the
  normal setpoint filters;
* ``step_fr_sw``: the thesis' other move (section 3.6.1, the ``wait_1`` block): the
  target jumps to ``b`` at once and the Control chart's ``fr_sw`` switches the
  cascade's setpoint filters to their slow cut-off, which shapes the motion;
* ``cubic``: a cubic polynomial in time along the line, zero speed at both ends
  (*RBE 3001 Lab 5 Final Project*, WPI, section II.D "Trajectory Planning");
* ``quintic``: a quintic, zero speed and zero acceleration at both ends.

The polynomials take the time the increments take (the line's length over the
drawing speed).  Each target goes through the arm's inverse kinematics
(:class:`~ttt_sm.twin.kinematics.IKSolver`, warm-started like the control loop) and
becomes the joint setpoints of the real cascade controllers on the real plant
(:class:`~ttt_sm.twin.sim.ArmSim`); the whiteboard (:class:`~ttt_sm.twin.whiteboard.Whiteboard`)
lays the ink from the true joint angles.  :func:`run_move` returns what happened:
following error, motor currents, the time to arrive, the ink.

The gear-play feed-forward of the application (docs/kinematics.md) is not in this
loop: the lab shows the cascade and the plant alone.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..params import ArmParams
from .kinematics import IKSolver, fk
from .sim import ArmSim
from .whiteboard import Whiteboard

#: The four ways to move, in the order the lab shows them.
METHODS = ("increment", "step_fr_sw", "cubic", "quintic")

#: How each method's setpoint filter is switched: True selects the slow one (``fr_sw``).
FR_SW = {"increment": False, "step_fr_sw": True, "cubic": False, "quintic": False}

#: Default drawing speed of the increments, m/s.
DRAW_SPEED_M_S = 0.02
#: How deep the pen is pushed into its holder while it draws, m (as the thesis' paths do).
PRESS_M = 0.001
#: Within this distance of ``b`` (m) the tip counts as arrived.
ARRIVE_TOL_M = 0.0005


def cubic_profile(tau: Any) -> np.ndarray:
    """Fraction of the way at normalised time `tau` in [0, 1]: ``3 tau^2 - 2 tau^3`` (zero speed at both ends)."""
    t = np.clip(np.asarray(tau, float), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def quintic_profile(tau: Any) -> np.ndarray:
    """``10 tau^3 - 15 tau^4 + 6 tau^5``: zero speed and zero acceleration at both ends."""
    t = np.clip(np.asarray(tau, float), 0.0, 1.0)
    return t * t * t * (10.0 + t * (-15.0 + 6.0 * t))


def move_duration(a: Any, b: Any, speed: float) -> float:
    """The time the constant increments take from `a` to `b` at `speed` (m/s), s."""
    return float(np.linalg.norm(np.asarray(b, float) - np.asarray(a, float))) / speed


def task_targets(method: str, a: Any, b: Any, speed: float, dt: float, n_ticks: int) -> np.ndarray:
    """The pen tip's target at each of `n_ticks` chart ticks of `dt` seconds, shape (n_ticks, 3), m.

    ``increment`` adds ``speed * dt`` along the line every tick (eq. 3.36), the last
    increment shortened so it stops on `b`; ``step_fr_sw`` is `b` at every tick;
    ``cubic`` and ``quintic`` follow their profile over :func:`move_duration`.
    After the move every method holds `b`.
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    if not (speed > 0.0 and dt > 0.0):
        raise ValueError(f"speed and dt must be positive, got speed={speed!r}, dt={dt!r}")
    pa, pb = np.asarray(a, float), np.asarray(b, float)
    length = float(np.linalg.norm(pb - pa))
    k = np.arange(1, n_ticks + 1, dtype=float)
    if method == "step_fr_sw" or length == 0.0:
        s = np.ones(n_ticks)
    elif method == "increment":
        s = np.minimum(k * speed * dt, length) / length
    else:
        profile: Callable[[Any], np.ndarray] = cubic_profile if method == "cubic" else quintic_profile
        s = profile(k * dt / (length / speed))
    return pa + s[:, None] * (pb - pa)


@dataclass(frozen=True)
class MoveRun:
    """One move on the twin, sampled at every chart tick.

    ``t`` (s) from the move's start; ``target_m`` the commanded tip; ``tip_m`` the true
    tip (the plant's load angles through the arm as built); ``following_rad`` the
    cascades' following error, filtered setpoint minus encoder angle, drives 1-3;
    ``current_a`` the true motor currents, drives 1-3; ``ink_m`` the strokes the
    whiteboard holds afterwards (lists of (x, y) in m).
    """

    method: str
    t: np.ndarray
    target_m: np.ndarray
    tip_m: np.ndarray
    following_rad: np.ndarray
    current_a: np.ndarray
    ink_m: list[np.ndarray]
    move_s: float
    arrive_s: float | None

    def summary(self, a: Any, b: Any) -> dict[str, Any]:
        """The numbers of the run: path deviation of the ink, errors, currents, times."""
        pa, pb = np.asarray(a, float)[:2], np.asarray(b, float)[:2]
        ink = np.vstack(self.ink_m) if self.ink_m else np.zeros((0, 2))
        return {"method": self.method, "fr_sw": FR_SW[self.method], "move_s": self.move_s,
                "arrive_s": self.arrive_s,
                "max_following_rad": float(np.max(np.abs(self.following_rad))),
                "max_tip_lag_m": float(np.max(np.linalg.norm(self.tip_m - self.target_m, axis=1))),
                "max_current_a": float(np.max(np.abs(self.current_a))),
                "rms_current_a": float(np.sqrt(np.mean(self.current_a ** 2))),
                "ink_max_off_line_m": float(np.max(_off_line(ink, pa, pb))) if len(ink) else None,
                "ink_length_m": float(sum(np.sum(np.linalg.norm(np.diff(s, axis=0), axis=1))
                                          for s in self.ink_m))}


def _off_line(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of points `p` (n, 2) from the segment a-b, m."""
    ab = b - a
    den = float(ab @ ab) or 1.0
    s = np.clip((p - a) @ ab / den, 0.0, 1.0)
    return np.asarray(np.linalg.norm(p - (a + s[:, None] * ab), axis=1))


def start_arm(params: ArmParams, start_m: Any, seed: int = 0, settle_s: float = 0.3) -> tuple[ArmSim, IKSolver]:
    """A twin powered on with the pen at `start_m` (x, y, z; pen vertical), initialised and settled.

    The arm powers on at the inverse kinematics of the start (the drives' offsets the
    true ones, as :meth:`ArmSim.assume_initialised`), holds it for `settle_s` so the
    gears take up their play, and is ready for :func:`run_move`.
    """
    ik = IKSolver(params)
    q0 = np.array(ik.solve([*np.asarray(start_m, float), 0.0]).q)
    sim = ArmSim(params, seed=seed, q0=q0)
    sim.assume_initialised()
    sim.set_setpoints(q0)
    sim.run_for(settle_s, record=False)
    return sim, ik


#: Called before each control step with the simulated arm: the force lab's contact spring.
StepHook = Callable[[ArmSim], None]


def drive_twin(sim: ArmSim, ik: IKSolver, targets: np.ndarray, fr_sw: bool,
               hook: StepHook | None = None, board: Whiteboard | None = None) -> dict[str, np.ndarray]:
    """Feed the tip `targets` (one row (x, y, z) per chart tick, pen vertical) to the twin.

    Per chart tick: inverse kinematics of the target, the setpoints (with `fr_sw`), then
    the control steps of the tick (``chart_divider`` of them), each after `hook` if given.
    Returns arrays per chart tick: ``t`` (s, the arm's clock), ``setpoint`` and ``encoder``
    (filtered setpoint and encoder angle of drives 1-3, rad), ``q_true`` (load angles, rad),
    ``current_a`` (true), ``current_meas_a`` (the sensors'), ``speed_rad_s`` (the cascades'
    speed estimate, load side).
    """
    p = sim.params
    div = p.control.chart_divider
    n = len(targets)
    widths = (("setpoint", 3), ("encoder", 3), ("q_true", 4), ("current_a", 3), ("current_meas_a", 3),
              ("speed_rad_s", 3))
    out: dict[str, np.ndarray] = {k: np.empty((n, w)) for k, w in widths}
    out["t"] = np.empty(n)
    for k in range(n):
        x, y, z = targets[k]
        q, _ = ik.solve_pose(float(x), float(y), float(z), 0.0)
        sim.set_setpoints(q, fr_sw)
        if hook is None:
            tr = sim.run(div)
        else:
            for _ in range(div):
                hook(sim)
                tr = sim.run(1)
        out["t"][k] = tr.t[-1]
        out["setpoint"][k] = tr.setpoint_filtered[-1, :3]
        out["encoder"][k] = tr.q_encoder[-1]
        out["q_true"][k] = tr.q_true[-1]
        out["current_a"][k] = tr.current_a[-1]
        out["speed_rad_s"][k] = tr.speed_meas[-1]
        out["current_meas_a"][k] = sim.sensors().current_a
        if board is not None:
            board.update(float(tr.t[-1]), tr.q_true[-1])
    return out


def run_move(params: ArmParams, method: str, a: Any, b: Any, speed: float = DRAW_SPEED_M_S,
             hold_s: float = 2.5, seed: int = 0) -> MoveRun:
    """One move of the pen from `a` to `b` (x, y, z in m; z below the surface draws) by `method`.

    The move lasts :func:`move_duration` plus `hold_s` of holding `b`; the run starts
    with the arm settled at `a`.  The arrival time is when the true tip comes within
    :data:`ARRIVE_TOL_M` of `b` for good.
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    if not (math.isfinite(speed) and speed > 0.0):
        raise ValueError(f"speed must be a positive number (m/s), got {speed!r}")
    dt = params.control.chart_dt
    move_s = move_duration(a, b, speed)
    n = int(math.ceil((move_s + hold_s) / dt))
    targets = task_targets(method, a, b, speed, dt, n)
    sim, ik = start_arm(params, a, seed)
    board = Whiteboard(params)
    t0 = sim.t
    board.update(t0, sim.truth.q)
    rec = drive_twin(sim, ik, targets, FR_SW[method], board=board)
    g = params.true_geometry
    tip = np.array([fk(q, g)[:3] for q in rec["q_true"]])
    t = rec["t"] - t0
    off = np.linalg.norm(tip - np.asarray(b, float), axis=1) > ARRIVE_TOL_M
    arrive = None if off[-1] else float(t[int(np.flatnonzero(off)[-1]) + 1] if off.any() else t[0])
    ink = [np.array(s.points) for s in board.strokes]
    return MoveRun(method, t, targets, tip, rec["setpoint"] - rec["encoder"], rec["current_a"], ink,
                   move_s, arrive)


def compare(params: ArmParams, a: Any, b: Any, speed: float = DRAW_SPEED_M_S, hold_s: float = 2.5,
            methods: tuple[str, ...] = METHODS, seed: int = 0) -> list[MoveRun]:
    """:func:`run_move` for each of `methods` between the same points."""
    return [run_move(params, m, a, b, speed, hold_s, seed) for m in methods]


__all__ = ["ARRIVE_TOL_M", "DRAW_SPEED_M_S", "FR_SW", "METHODS", "MoveRun", "PRESS_M", "StepHook", "compare",
           "cubic_profile", "drive_twin", "move_duration", "quintic_profile", "run_move", "start_arm",
           "task_targets"]
