"""A triangulation position sensor watching the end effector (thesis section 3.5).

The thesis measured the tool with "a triangulation position sensor with high
precision": a resolution of 10^-6 m and a range of 10 cm that starts 5 cm
from the sensor and ends at 15 cm.  Such a sensor throws a light spot along
its beam and reads the distance to the surface it lands on.

:class:`TriangulationSensor` models it on the twin: a mounting pose (where
the sensor sits and which way its beam points), the range, the resolution
and a measurement noise drawn from a seed.  It reads the distance along the
beam to the true tool point (ground truth: simulation only), i.e. to a
small plate on the tool square to the beam; a target
outside the range gives no reading (``None``), never a value clipped to the
range's end, as a real sensor reports "out of range".

Pure data in, a number out: the experiment that uses it is
:mod:`ttt_sm.app.precision`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: The thesis' sensor (section 3.5): resolution, m.
RESOLUTION_M = 1e-6
#: Its range along the beam: from 5 cm to 15 cm away from the sensor, m.
RANGE_MIN_M = 0.05
RANGE_MAX_M = 0.15
#: Noise of one reading (standard deviation), m: two steps of the resolution, an assumption
#: (the thesis gives none; laser triangulation heads of 1 um resolution quote 1-3 um repeatability).
NOISE_M = 2e-6


@dataclass(frozen=True)
class SensorMount:
    """Where the sensor sits and which way it looks, in the global frame.

    ``origin`` is the sensor's window (m); ``beam`` the direction of its beam
    (normalised on use).  A reading is the distance from the window to the
    target along the beam.
    """

    origin: tuple[float, float, float]
    beam: tuple[float, float, float]

    def unit_beam(self) -> np.ndarray:
        """The beam direction as a unit vector."""
        b = np.asarray(self.beam, dtype=float)
        n = float(np.linalg.norm(b))
        if not n > 0 or not math.isfinite(n):
            raise ValueError(f"the sensor's beam must be a nonzero finite direction, got {self.beam}")
        return b / n


@dataclass(frozen=True)
class SensorSpec:
    """The sensor's resolution, range and noise (defaults: the thesis' sensor, noise assumed)."""

    resolution_m: float = RESOLUTION_M
    range_min_m: float = RANGE_MIN_M
    range_max_m: float = RANGE_MAX_M
    noise_m: float = NOISE_M


class TriangulationSensor:
    """A one-axis triangulation sensor: distance along its beam, quantised, noisy, ``None`` out of range.

    Parameters
    ----------
    mount : SensorMount
        Its pose in the global frame.
    spec : SensorSpec
        Resolution, range, noise.
    seed : int
        Seeds the measurement noise: the same seed gives the same readings.
    """

    def __init__(self, mount: SensorMount, spec: SensorSpec | None = None, seed: int = 0) -> None:
        self.mount = mount
        self.spec = spec or SensorSpec()
        self._origin = np.asarray(mount.origin, dtype=float)
        self._beam = mount.unit_beam()
        self._rng = np.random.default_rng(seed)

    def distance(self, point: np.ndarray) -> float | None:
        """One reading of the distance to `point` (x, y, z in m) along the beam, m; None out of range."""
        s = self.spec
        d = float(np.dot(np.asarray(point[:3], dtype=float) - self._origin, self._beam))
        if not s.range_min_m <= d <= s.range_max_m:
            return None
        d += float(self._rng.normal(0.0, s.noise_m)) if s.noise_m > 0 else 0.0
        return round(d / s.resolution_m) * s.resolution_m

    def position(self, reading: float | None, axis: np.ndarray) -> float | None:
        """A reading turned into the target's coordinate along the global `axis` (unit vector), m.

        As the experimenter does: the window's coordinate along the axis plus
        the reading, taking the beam to lie along the axis (its sign from the
        beam).  A beam tilted by an angle reads the motion shortened by its
        cosine, and so does this coordinate: the cosine error of a sensor
        mounted askew.
        """
        if reading is None:
            return None
        along = float(np.dot(self._beam, axis))
        return float(np.dot(self._origin, axis)) + math.copysign(reading, along)


__all__ = ["RESOLUTION_M", "RANGE_MIN_M", "RANGE_MAX_M", "NOISE_M", "SensorMount", "SensorSpec",
           "TriangulationSensor"]
