"""Clocks and chart-rate path sampling."""

import time

import numpy as np
import pytest

from ttt_sm.params import load_params
from ttt_sm.sched.clock import VirtualClock, WallClock
from ttt_sm.sched.trajectory import Waypoint, sample_polyline, square_path


def test_virtual_clock_never_waits():
    c = VirtualClock()
    c.start()
    t0 = time.perf_counter()
    for k in range(10000):
        c.wait_period(k)
    # 10 s of 1 ms periods would take 10 s if it waited
    assert time.perf_counter() - t0 < 1.0


def test_wall_clock_paces_and_counts_lateness():
    c = WallClock(period_s=0.002)
    t0 = time.perf_counter()  # before start(): period 49 is due 98 ms after start's own reading, not after ours
    c.start()
    for k in range(50):
        c.wait_period(k)
    elapsed = time.perf_counter() - t0
    assert elapsed >= 49 * 0.002  # it did wait for period 49
    st = c.stats()
    assert st.periods == 50
    assert st.lateness_p99_us >= st.lateness_p50_us >= 0


def test_wall_clock_counts_an_overrun_as_a_miss():
    c = WallClock(period_s=0.001)
    c.start()
    c.wait_period(0)
    time.sleep(0.005)  # a step that took 5 periods
    c.wait_period(1)
    st = c.stats()
    assert st.deadline_misses >= 1
    assert st.lateness_max_us >= 3000


def test_polyline_moves_at_the_set_speed():
    dt, speed = 0.002, 0.02
    s = sample_polyline([Waypoint(0, 0, 0), Waypoint(0.03, 0, 0), Waypoint(0.03, 0.03, 0)], speed, dt)
    steps = np.linalg.norm(np.diff(s[:, :3], axis=0), axis=1)
    assert steps.max() <= speed * dt * 1.0001
    assert len(s) == 1 + 2 * int(np.ceil(0.03 / (speed * dt)))
    assert np.allclose(s[-1], [0.03, 0.03, 0, 0])


def test_polyline_rejects_nonsense():
    with pytest.raises(ValueError, match="at least one waypoint"):
        sample_polyline([], 0.01, 0.002)
    with pytest.raises(ValueError, match="must be positive"):
        sample_polyline([Waypoint(0, 0, 0)], 0.0, 0.002)


def test_square_path_draws_below_the_surface_and_lifts():
    b = load_params().board
    path = square_path(b, side=0.03)
    zs = [w.z for w in path]
    assert min(zs) < b.surface_z < max(zs)
    drawn = [w for w in path if w.z < b.surface_z]
    xs = [w.x for w in drawn]
    assert max(xs) - min(xs) == pytest.approx(0.03)
    assert path[-1].z > b.surface_z


def test_distance_to_path_is_geometric():
    from ttt_sm.sched.trajectory import distance_to_path

    path = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])
    pts = np.array([[0.5, 0.2], [1.3, 0.5], [-0.3, -0.4], [1.0, 1.0]])
    assert np.allclose(distance_to_path(pts, path), [0.2, 0.3, 0.5, 0.0])
    # a single vertex is a point
    assert np.allclose(distance_to_path(pts[:1], path[:1]), [np.hypot(0.5, 0.2)])
    # chunking does not change the answer
    many = np.random.default_rng(0).uniform(-1, 2, size=(1500, 2))
    assert np.allclose(distance_to_path(many, path, chunk=7), distance_to_path(many, path))


def test_simplify_keeps_the_shape_and_drops_collinear_points():
    from ttt_sm.sched.trajectory import distance_to_path, simplify_polyline

    line = np.column_stack([np.linspace(0, 0.15, 3751), np.full(3751, 0.2)])
    assert len(simplify_polyline(line)) == 2
    a = np.linspace(0, 2 * np.pi, 2000)
    circle = np.column_stack([0.0075 * np.cos(a), 0.0075 * np.sin(a)])
    short = simplify_polyline(circle, tol=1e-6)
    assert 10 < len(short) < 500
    assert distance_to_path(circle, short).max() <= 1e-6 + 1e-12
