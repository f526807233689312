"""Forces and velocities at the pen: the Jacobian, the manipulability ellipse, the contact force from the currents.

The kinematics lab's "Forces and velocities" view (docs/kinematics.md, "Lab:
trajectories and forces").

* :func:`velocity_ellipse`: the Jacobian (eq. 3.30) at a pose and the ellipse of
  pen-tip velocities on the board that unit joint speeds of drives 1-3 give
  (the x-y block of ``J J^T``), with the manipulability ``|det J|``;
  :func:`ellipses_over_board` lays a grid of them over the board.
* :class:`PenSpring` and :class:`ContactLoad`: the pen's spring pushing back on the
  arm.  The game's twin treats the pen kinematically (the whiteboard only
  measures how far the pen slides into its holder); here the spring's force
  acts on the plant.  With the pen vertical, an upward force ``F`` at the tip
  loads joints 2 and 3 exactly as a tool weight of ``-F`` at the end of ``L3``
  would: the plant's gravity coefficients (``plant.gravity_coefficients``)
  become ``g2 - F L2`` and ``g23 - F L3`` for the next control step.
* :func:`estimate_contact_force`: what a controller can tell from its sensors:
  the motor currents through the gears give the joint torques; the arm's
  gravity (``plant.gravity_torques``, the project's one formula) and the
  drives' friction (the parameter file's Coulomb and viscous terms, signed by
  the cascades' speed estimate) are taken out; the rest is the contact's, and
  ``F = J^-T tau`` (*RBE 3001 Lab 5 Final Project*, WPI, section II.C "Force
  Vector Calculation"), smoothed with a rolling average as that report does.
* :func:`force_run`: the pen lowered, a line drawn and the pen lifted on the
  twin with the spring acting; the estimate against the true force.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..params import ArmParams
from . import layout
from .kinematics import IKSolver, arm_chain_py, fk, jacobian
from .plant import gravity_coefficients, gravity_torques
from .sim import ArmSim
from .trajectories import DRAW_SPEED_M_S, PRESS_M, drive_twin, start_arm, task_targets

#: The pen's spring: force per metre it is pushed into its holder (N/m) ...
PEN_SPRING_N_PER_M = 1000.0
#: ... on top of its preload (N): a whiteboard marker presses with about 2 N at 1 mm.
PEN_PRELOAD_N = 1.0
#: The rolling average of the estimate (s), as the WPI report smooths its strain gauges.
ESTIMATE_WINDOW_S = 0.2
#: Samples this long after the pen touches down or before it lifts are left out of the comparison (s).
EDGE_S = 0.15


@dataclass(frozen=True)
class PenSpring:
    """The pen's spring: no force off the board, ``preload + k depth`` once the tip is `depth` below it."""

    stiffness_n_per_m: float = PEN_SPRING_N_PER_M
    preload_n: float = PEN_PRELOAD_N

    def force(self, depth_m: float) -> float:
        """Normal force of the board on the pen tip (N) with the nominal tip `depth_m` below the surface."""
        return 0.0 if depth_m <= 0.0 else self.preload_n + self.stiffness_n_per_m * depth_m


class ContactLoad:
    """The pen's contact force on the plant, set before each control step (a hook of ``drive_twin``).

    It reads the plant's true joint angles, puts the nominal tip through the arm as
    built, and writes the plant's gravity coefficients less the force's share
    (``g2 - F L2``, ``g23 - F L3``: exact with the pen vertical).  ``forces_n`` keeps
    the force of every control step.
    """

    def __init__(self, params: ArmParams, spring: PenSpring | None = None) -> None:
        self.spring = spring or PenSpring()
        self._g2, self._g23 = gravity_coefficients(params)
        g = params.true_geometry
        self._geom = (g.L1, g.L2, g.L3, g.L4, g.l_f)
        self._surface = params.board.surface_z
        self.forces_n: list[float] = []

    def __call__(self, sim: ArmSim) -> None:
        q1, q2, q3, q4 = sim.truth.angles()
        z = arm_chain_py(q1, q2, q3, q4, *self._geom)[2]
        f = self.spring.force(self._surface - z)
        _, L2, L3, _, _ = self._geom
        pg = sim.plant.pg
        pg[layout.PG_GRAV2] = self._g2 - f * L2
        pg[layout.PG_GRAV23] = self._g23 - f * L3
        self.forces_n.append(f)


def joint_torques_from_currents(params: ArmParams, current_a: np.ndarray, speed_rad_s: np.ndarray) -> np.ndarray:
    """Torque the gears pass to the links (N m), drives 1-3, from the motor currents and the load speeds.

    ``N (kt i - Tc sign(N w) - bm N w)`` per drive: the motor's torque less its Coulomb
    and viscous friction, through the gear ratio ``N``; the rotor's inertia is neglected
    (the pen moves at a steady speed while it draws).
    """
    i, w = np.atleast_2d(current_a), np.atleast_2d(speed_rad_s)
    out = np.empty_like(i)
    for d, p in enumerate(params.drives):
        wm = p.gear_ratio * w[:, d]
        out[:, d] = p.gear_ratio * (p.torque_constant * i[:, d] - p.motor_coulomb * np.sign(wm)
                                    - p.motor_viscous * wm)
    return out


#: A pitch drive's friction counts as known while its motor turns faster than this (rad/s, averaged).
MOVING_MOTOR_RAD_S = 1.0


@dataclass(frozen=True)
class ForceEstimate:
    """The contact force as the controller can tell it, per sample.

    ``vector_n`` is ``J^-T tau`` (N; x, y, z), the WPI report's formula; ``normal_n`` its
    z, the board's push on the pen; ``observable`` is True where both pitch drives
    turned throughout the averaging window: where one sticks, its Coulomb friction
    can be anything within +-Tc and the estimate carries that unknown.
    """

    vector_n: np.ndarray
    normal_n: np.ndarray
    observable: np.ndarray


def _rolling(a: np.ndarray, window: int) -> np.ndarray:
    """The mean of the last `window` samples (fewer at the start), along axis 0."""
    if window <= 1:
        return a
    c = np.cumsum(np.vstack([np.zeros((1, a.shape[1])), a]), axis=0)
    k = np.arange(1, len(a) + 1)
    lo = np.maximum(k - window, 0)
    return np.asarray((c[k] - c[lo]) / (k - lo)[:, None])


def estimate_contact_force(params: ArmParams, q: np.ndarray, current_a: np.ndarray, speed_rad_s: np.ndarray,
                           window: int = 1) -> ForceEstimate:
    """The contact force on the pen tip from what the controller measures.

    Parameters
    ----------
    q : (n, 3) array
        Joint angles of drives 1-3 as the encoders give them, rad (the pen taken vertical).
    current_a : (n, 3) array
        The measured motor currents, A.
    speed_rad_s : (n, 3) array
        The cascades' speed estimate, load side, rad/s.
    window : int
        Rolling average of the torques and speeds over this many samples (1: none).

    The link's balance, quasi-static, is ``0 = tau_gear + tau_gravity + tau_contact -
    b_L w``: so ``tau_contact = -tau_gear - tau_gravity + b_L w``, and with ``J`` the
    position rows of eq. 3.30 for drives 1-3, ``F = J^-T tau_contact``.
    """
    q = np.atleast_2d(q)
    tau_gear = joint_torques_from_currents(params, current_a, speed_rad_s)
    b_l = np.array([p.load_viscous for p in params.drives])
    n_gear = np.array([p.gear_ratio for p in params.drives])
    g = params.geometry
    tau = np.empty((len(q), 3))
    jac = np.empty((len(q), 3, 3))
    for k, (q1, q2, q3) in enumerate(q):
        qq = (q1, q2, q3, -(q2 + q3))  # the pen vertical: phi = q2 + q3 + q4 = 0
        tau[k] = -tau_gear[k] - gravity_torques(params, qq) + b_l * speed_rad_s[k]
        jac[k] = jacobian(qq, g)[:3, :3]
    tau = _rolling(tau, window)
    # a drive's friction is known where its motor turned throughout the window
    moving = _rolling((np.abs(np.asarray(speed_rad_s, float) * n_gear) > MOVING_MOTOR_RAD_S).astype(float),
                      window) > 0.999
    vector = np.linalg.solve(np.transpose(jac, (0, 2, 1)), tau[..., None])[..., 0]
    # the board pushes up: its normal force is the estimate's z; it is observable where the
    # friction of both pitch drives is known because they turn
    observable = moving[:, 1] & moving[:, 2]
    normal = vector[:, 2].copy()
    return ForceEstimate(vector, normal, observable)


def velocity_ellipse(q: Any, params: ArmParams) -> dict[str, Any]:
    """The Jacobian at `q` and the ellipse of tip velocities on the board for unit joint speeds of drives 1-3.

    The semi-axes (m/s per rad/s) are the square roots of the eigenvalues of the x-y
    block of ``J J^T`` (``J`` the position rows, drives 1-3), along its eigenvectors;
    ``manipulability`` is ``|det J|`` of those rows (m^3/rad^3).
    """
    J = jacobian(q, params.geometry)
    jp = J[:3, :3]
    m = (jp @ jp.T)[:2, :2]
    vals, vecs = np.linalg.eigh(m)
    vals = np.maximum(vals, 0.0)
    big = int(np.argmax(vals))
    return {"jacobian": [[float(v) for v in row] for row in J],
            "manipulability": float(abs(np.linalg.det(jp))),
            "axes_m_per_rad": [float(math.sqrt(vals[big])), float(math.sqrt(vals[1 - big]))],
            "angle_rad": float(math.atan2(vecs[1, big], vecs[0, big]))}


def ellipses_over_board(params: ArmParams, n: int = 5) -> list[dict[str, Any]]:
    """:func:`velocity_ellipse` on an `n` x `n` grid over the field, the pen vertical on the surface.

    Points the arm cannot reach within its limits are left out.
    """
    x0, x1, y0, y1 = params.board.field_bounds()
    ik = IKSolver(params)
    out = []
    for y in np.linspace(y0, y1, n):
        for x in np.linspace(x0, x1, n):
            try:
                q = ik.solve([x, y, params.board.surface_z, 0.0]).q
            except ValueError:
                continue
            out.append({"x_m": float(x), "y_m": float(y), "q_rad": [float(v) for v in q],
                        **velocity_ellipse(q, params)})
    return out


@dataclass(frozen=True)
class ForceRun:
    """A line drawn with the spring acting, per chart tick: time (s), true tip (m), true normal force (N),
    the estimate (:class:`ForceEstimate`), and where the pen draws (touching, away from touch-down and lift)."""

    t: np.ndarray
    tip_m: np.ndarray
    true_n: np.ndarray
    estimate: ForceEstimate
    drawing: np.ndarray

    def errors(self) -> dict[str, Any]:
        """The normal force estimate against the truth while the pen draws.

        Relative errors (mean, 95th percentile, max) over the drawing samples where the
        estimate is observable, and ``all_*`` over every drawing sample; the share
        observable; the mean forces there (N).  None where there are no such samples.
        """
        est, true = self.estimate.normal_n, self.true_n
        out: dict[str, Any] = {}
        for prefix, m in (("", self.drawing & self.estimate.observable), ("all_", self.drawing)):
            rel = np.abs(est[m] - true[m]) / true[m]
            some = bool(len(rel))
            out[prefix + "mean_rel"] = float(np.mean(rel)) if some else None
            out[prefix + "p95_rel"] = float(np.percentile(rel, 95)) if some else None
            out[prefix + "max_rel"] = float(np.max(rel)) if some else None
        m = self.drawing & self.estimate.observable
        out["mean_true_n"] = float(np.mean(true[m])) if m.any() else None
        out["mean_estimate_n"] = float(np.mean(est[m])) if m.any() else None
        out["observable_share"] = float(np.count_nonzero(m)) / max(1, int(np.count_nonzero(self.drawing)))
        out["samples"] = int(np.count_nonzero(m))
        return out


def force_run(params: ArmParams, a: Any, b: Any, speed: float = DRAW_SPEED_M_S, press_m: float = PRESS_M,
              lift_m: float = 0.005, spring: PenSpring | None = None, seed: int = 0) -> ForceRun:
    """Lower the pen at `a` (x, y on the board, m), draw to `b`, lift it; the contact force true and estimated.

    Every move goes by the thesis' constant increments (eq. 3.36) at `speed`; the pen
    is pushed `press_m` into its holder while it draws.
    """
    if not (math.isfinite(speed) and speed > 0.0):
        raise ValueError(f"speed must be a positive number (m/s), got {speed!r}")
    c = params.control
    dt = c.chart_dt
    zs = params.board.surface_z
    up, down = zs + lift_m, zs - press_m
    pa, pb = (a[0], a[1], up), (b[0], b[1], up)
    legs = [((a[0], a[1], up), (a[0], a[1], down), 0.3), ((a[0], a[1], down), (b[0], b[1], down), 0.3),
            ((b[0], b[1], down), pb, 0.3)]
    targets, drawing = [], []
    for leg, (p, q, hold) in enumerate(legs):
        length = float(np.linalg.norm(np.subtract(q, p)))
        n_move = int(math.ceil(length / speed / dt))
        n = int(math.ceil((length / speed + hold) / dt))
        targets.append(task_targets("increment", p, q, speed, dt, n))
        # drawing: the pen moving along the line, once the start's acceleration is over
        drawing.append(np.arange(n) >= int(round(EDGE_S / dt)) if leg == 1 else np.zeros(n, bool))
        drawing[-1][n_move:] = False
    sim, ik = start_arm(params, pa, seed)
    load = ContactLoad(params, spring)
    rec = drive_twin(sim, ik, np.vstack(targets), False, hook=load)
    div = c.chart_divider
    true_n = np.asarray(load.forces_n)[div - 1::div]
    window = max(1, int(round(ESTIMATE_WINDOW_S / dt)))
    est = estimate_contact_force(params, rec["encoder"], rec["current_meas_a"], rec["speed_rad_s"], window)
    g = params.true_geometry
    tip = np.array([fk(qq, g)[:3] for qq in rec["q_true"]])
    t = rec["t"] - rec["t"][0]
    return ForceRun(t, tip, true_n, est, np.concatenate(drawing) & (true_n > 0.0))


__all__ = ["ContactLoad", "EDGE_S", "ESTIMATE_WINDOW_S", "ForceEstimate", "ForceRun", "MOVING_MOTOR_RAD_S",
           "PEN_PRELOAD_N", "PEN_SPRING_N_PER_M", "PenSpring", "ellipses_over_board", "estimate_contact_force",
           "force_run", "joint_torques_from_currents", "velocity_ellipse"]
