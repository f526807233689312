"""The triangulation sensor of thesis section 3.5: resolution, range, noise from a seed, null out of range."""

from __future__ import annotations

import math

import numpy as np

from ttt_sm.twin.sensor import SensorMount, SensorSpec, TriangulationSensor

ALONG_Z = SensorMount(origin=(0.0, 0.25, -0.04), beam=(0.0, 0.0, 1.0))


def test_a_reading_is_the_distance_along_the_beam_to_a_micrometre():
    s = TriangulationSensor(ALONG_Z, SensorSpec(noise_m=0.0))
    d = s.distance(np.array([0.01, 0.26, 0.0301234]))  # sideways offsets do not count along the beam
    assert d is not None and math.isclose(d, 0.070123, abs_tol=1e-12)
    assert math.isclose(s.position(d, np.array([0.0, 0.0, 1.0])), 0.030123, abs_tol=1e-12)


def test_outside_its_range_the_sensor_gives_no_reading_not_a_clipped_one():
    s = TriangulationSensor(ALONG_Z, SensorSpec(noise_m=0.0))
    assert s.distance(np.array([0.0, 0.25, 0.0099])) is None  # 4.99 cm from the window
    assert s.distance(np.array([0.0, 0.25, 0.1101])) is None  # 15.01 cm
    assert s.distance(np.array([0.0, 0.25, 0.0101])) is not None
    assert s.position(None, np.array([0.0, 0.0, 1.0])) is None


def test_the_noise_comes_from_the_seed():
    p = np.array([0.0, 0.25, 0.05])
    a = [TriangulationSensor(ALONG_Z, seed=3).distance(p) for _ in range(2)]
    s1, s2 = TriangulationSensor(ALONG_Z, seed=3), TriangulationSensor(ALONG_Z, seed=4)
    r1 = [s1.distance(p) for _ in range(200)]
    r2 = [s2.distance(p) for _ in range(200)]
    assert a[0] == a[1]
    assert r1 != r2
    assert 1e-6 < float(np.std(r1)) < 4e-6  # 2 um of noise, read in steps of 1 um


def test_a_tilted_sensor_reads_the_motion_shortened_by_the_cosine():
    tilt = math.radians(2.0)
    s = TriangulationSensor(SensorMount((0.0, 0.25, -0.04), (math.sin(tilt), 0.0, math.cos(tilt))),
                            SensorSpec(noise_m=0.0, resolution_m=1e-9))
    z = np.array([0.0, 0.0, 1.0])
    moved = s.position(s.distance(np.array([0.0, 0.25, 0.08])), z) - s.position(s.distance(
        np.array([0.0, 0.25, 0.03])), z)
    assert math.isclose(moved, 0.05 * math.cos(tilt), abs_tol=2e-9)


def test_the_true_tool_is_the_arm_as_built_not_as_measured(params):
    from ttt_sm.twin.kinematics import fk
    from ttt_sm.twin.sim import ArmSim

    sim = ArmSim(params)
    q = sim.truth.q
    assert np.allclose(sim.truth.tool_pose(), fk(q, params.true_geometry))
    assert not np.allclose(sim.truth.tool_pose()[:3], fk(q, params.geometry)[:3], atol=2e-5)
