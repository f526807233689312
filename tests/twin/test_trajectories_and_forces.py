"""The kinematics lab's motion views on the twin: trajectories compared, the pen's force estimated from currents.

docs/kinematics.md, "Lab: trajectories and forces".  Every run is the real cascade on the real
plant, in simulated time.
"""

import math

import numpy as np
import pytest

from ttt_sm.params import load_params
from ttt_sm.twin import forces as F
from ttt_sm.twin.kinematics import jacobian
from ttt_sm.twin.plant import gravity_torques
from ttt_sm.twin.trajectories import (
    METHODS,
    PRESS_M,
    MoveRun,
    cubic_profile,
    move_duration,
    quintic_profile,
    run_move,
    task_targets,
)

P = load_params()
B = P.board
CX, CY = B.field_center_x, B.field_center_y
Z = B.surface_z - PRESS_M
# one stroke of an X (the thesis' 45-degree lines, section 3.6.1), 7 cm long
A_XY, B_XY = (CX - 0.025, CY - 0.025), (CX + 0.025, CY + 0.025)


def test_profiles_start_and_stop_at_rest() -> None:
    tau = np.linspace(0.0, 1.0, 2001)
    h = tau[1]
    for profile, still_accel in ((cubic_profile, False), (quintic_profile, True)):
        s = profile(tau)
        assert s[0] == 0.0 and s[-1] == pytest.approx(1.0)
        v = np.gradient(s, h)
        assert abs(v[0]) < 1e-2 and abs(v[-1]) < 1e-2  # zero speed at both ends
        a = np.gradient(v, h)
        assert bool(abs(a[2]) < 0.1) is still_accel  # the quintic starts with zero acceleration, the cubic with 6
    assert np.all(np.diff(cubic_profile(tau)) >= 0) and np.all(np.diff(quintic_profile(tau)) >= 0)


def test_increments_are_constant_and_stop_on_the_end_point() -> None:
    dt, speed = 0.002, 0.02
    a, b = (0.0, 0.2, 0.0), (0.03, 0.24, 0.0)  # 5 cm: 1250 increments of 0.04 mm
    n = int(math.ceil(move_duration(a, b, speed) / dt)) + 10
    x = task_targets("increment", a, b, speed, dt, n)
    steps = np.linalg.norm(np.diff(np.vstack([a, x]), axis=0), axis=1)
    assert np.allclose(steps[:1250], speed * dt)  # eq. 3.36: X_out = X_out_p + inc
    assert np.allclose(x[-11:], b) and np.allclose(steps[1251:], 0.0)
    assert np.allclose(task_targets("step_fr_sw", a, b, speed, dt, 3), b)
    with pytest.raises(ValueError, match="method must be one of"):
        task_targets("spline", a, b, speed, dt, 3)


def test_the_four_moves_on_the_twin_draw_and_differ_as_their_shapes_say() -> None:
    a, b = (*A_XY, Z), (*B_XY, Z)
    runs = {m: run_move(P, m, a, b, hold_s=1.6) for m in METHODS}
    s = {m: r.summary(a, b) for m, r in runs.items()}
    for m in ("increment", "cubic", "quintic"):
        # interpolated in the task space: the ink lies on the line within half a millimetre
        assert s[m]["ink_max_off_line_m"] < 0.5e-3, (m, s[m])
        assert s[m]["ink_length_m"] == pytest.approx(math.dist(A_XY, B_XY), abs=2e-3)
        assert s[m]["arrive_s"] is not None and s[m]["arrive_s"] < s[m]["move_s"] + 0.5
    # the step through the slow filters moves in joint space: its ink bows off the line by millimetres
    assert s["step_fr_sw"]["ink_max_off_line_m"] > 3e-3
    assert s["step_fr_sw"]["arrive_s"] is not None
    # the increments start at full speed: early on their pen trails its target more than the polynomials',
    # which start from rest; at the end the polynomials, already slowing down, arrive first
    def early_lag(r: MoveRun) -> float:
        k = r.t <= 0.3
        return float(np.mean(np.linalg.norm(r.tip_m[k] - r.target_m[k], axis=1)))

    assert early_lag(runs["cubic"]) < early_lag(runs["increment"]) / 2
    assert early_lag(runs["quintic"]) < early_lag(runs["increment"]) / 2
    assert s["quintic"]["arrive_s"] < s["cubic"]["arrive_s"] < s["increment"]["arrive_s"]
    for m in ("increment", "cubic", "quintic"):
        assert s[m]["max_tip_lag_m"] < 2.5e-3, (m, s[m])
    assert all(s[m]["max_current_a"] < 3.0 for m in METHODS)
    assert s["step_fr_sw"]["max_current_a"] > s["increment"]["max_current_a"]


def test_velocity_ellipse_is_the_jacobian_s() -> None:
    q = [0.2, 0.9, 1.1, -2.0]
    e = F.velocity_ellipse(q, P)
    jp = jacobian(q, P.geometry)[:3, :3]
    assert e["manipulability"] == pytest.approx(abs(np.linalg.det(jp)))
    # a unit joint speed along the right singular direction gives the big axis' speed
    vals = np.linalg.eigvalsh((jp @ jp.T)[:2, :2])
    assert sorted(e["axes_m_per_rad"]) == pytest.approx(np.sqrt(vals))
    grid = F.ellipses_over_board(P, n=3)
    assert len(grid) == 9 and all(g["manipulability"] > 0 for g in grid)


@pytest.mark.parametrize("a, b", [(A_XY, B_XY), ((CX, CY - 0.06), (CX, CY + 0.06))], ids=["X stroke", "radial"])
def test_contact_force_from_the_currents_is_within_10_percent_while_the_pen_draws(a: tuple, b: tuple) -> None:
    run = F.force_run(P, a, b)
    err = run.errors()
    d = run.drawing
    assert d.sum() > 500 and np.all(run.true_n[d] > 1.5)  # the spring presses ~2 N while drawing
    assert err["mean_true_n"] == pytest.approx(2.0, abs=0.1)
    assert err["observable_share"] > 0.3
    assert err["mean_rel"] < 0.10 and err["p95_rel"] < 0.10, err
    assert err["all_mean_rel"] < 0.10, err
    assert np.count_nonzero(run.true_n == 0.0) > 100  # before touch-down and after the lift: no force


def test_gravity_and_friction_must_come_out_of_the_currents() -> None:
    """Left in, gravity or friction spoils the estimate: what the docs say is removed is removed."""
    run = F.force_run(P, A_XY, B_XY, spring=F.PenSpring(0.0, 0.0))  # a pen that does not push
    d = np.zeros_like(run.drawing)
    d[len(d) // 3:2 * len(d) // 3] = True
    assert np.all(run.true_n == 0.0)
    assert np.median(np.abs(run.estimate.normal_n[d])) < 0.3
    # the same currents without the gravity term: the arm's weight appears as a force of newtons
    q = np.array([[0.0, 1.0, 1.2]])
    g = gravity_torques(P, (0.0, 1.0, 1.2, -2.2))
    kt = np.array([p.torque_constant * p.gear_ratio for p in P.drives])
    hold = -g / kt  # the currents that hold the arm still against gravity
    assert np.allclose(F.estimate_contact_force(P, q, hold[None], np.zeros((1, 3))).vector_n, 0.0, atol=1e-9)
    w = np.array([[0.0, 0.05, -0.05]])  # moving: the friction the motors overcome is taken out
    tau_f = np.array([p.gear_ratio * (p.motor_coulomb * np.sign(v) + p.motor_viscous * p.gear_ratio * v)
                      + p.load_viscous * v for p, v in zip(P.drives, w[0], strict=True)])
    moving = (-g + tau_f) / kt
    assert np.allclose(F.estimate_contact_force(P, q, moving[None], w).vector_n, 0.0, atol=1e-9)
    assert np.abs(F.estimate_contact_force(P, q, hold[None], w).vector_n).max() > 0.3  # friction left in


def test_the_bench_section_reports_each_method_and_the_force_estimate() -> None:
    from ttt_sm.twin.motion_bench import bench_motion_lab

    r = bench_motion_lab(P, quick=True)
    assert {f"trajectory_{m}_us_per_tick" for m in METHODS} <= set(r)
    assert r["forces_estimate_mean_rel"] < 0.10 and 0.0 < r["forces_observable_share"] <= 1.0
    assert r["trajectory_run_move_ms"] > 0 and r["forces_run_ms"] > 0
