"""The Safety stage's Monitor block, compiled: one call per chart step (docs/safety.md, "Cost").

The Monitor block (:class:`~ttt_sm.app.safety_wiring.SafetyStage`) runs on
every chart step of every robot.  Written as plain Python it cost more than
the Safety chart it feeds (~15 µs a chart step of a game); here its
arithmetic is two compiled functions over one float buffer ``m[M_*]``, the
stage's whole state:

- :func:`monitor`, before the chart ticks: the encoder angles from this chart
  step's counts and the offsets (``counts * rad_per_count + offset``, as the
  :class:`~ttt_sm.arm.Arm` protocol defines them), the following errors
  against the model of the setpoint filters, the encoder speeds from the
  counts, the commanded speeds, the currents' magnitudes, which drives count
  as at their speed clamp, the pen servo's error (the model of the servo
  minus its feedback reading) and the tool pose by forward kinematics
  (:func:`~ttt_sm.twin.kinematics.chain.arm_chain`) of the encoder angles;
- :func:`advance`, after the chart ticked: the model of the controller's
  setpoint filters stepped with the setpoints sent to the drives, followed no
  faster than the speed clamp; and the model of the pen servo, its first-order
  lag and slew-rate limit of ``[servo]``, stepped with the servo's setpoint.

The model moves with the encoder offsets when the init charts change them
(:func:`monitor` compares the offsets with those it was computed in).

``NUMBA_DISABLE_JIT=1`` runs the same code as plain Python.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any

import numpy as np
from numba import njit

from ..twin.kinematics import chain
from ..twin.kinematics.chain import arm_chain

# ---- the buffer m[M_*]: three numbers per drive unless said ------------------
M_R = 0  # the model of the setpoint filter: angle (encoder coordinates), rad
M_V = 3  # its rate, rad/s
M_P = 6  # where the drive can be: the filter's angle followed no faster than the speed clamp, rad
M_DP = 9  # how far M_P moved over the last chart step, rad
M_FAST = 12  # chart steps the drive still counts as at its speed clamp
M_COUNTS = 15  # the encoder counts of the last chart step
M_OFFSET = 18  # the encoder offsets the model's angles are in, rad
M_STEP_MAX = 21  # the speed clamp times the chart period, rad
M_SPEED_PER_COUNT = 24  # rad/s of one count over a chart step
M_RPC = 27  # rad per count
M_ROW = 30  # 6: the fast setpoint filter over one chart step (a11 a12 b1 a21 a22 b2)
M_ROW_SLOW = 36  # 6: the slow one (fr_sw)
M_GEOMETRY = 42  # 5: L1 L2 L3 L4 l_f
M_FAST_STEPS = 47  # 1: chart steps a drive counts as at its clamp after the model left it
M_CHART_DT = 48  # 1: the chart period, s
M_SV = 49  # 1: the model of the pen servo: where its output shaft should be, rad
M_SV_RATE = 50  # 1: the servo's slew rate, rad/s
M_SV_INV_TAU = 51  # 1: 1 / the time constant of its position loop, 1/s
N_M = 52
#: Sub-steps of the servo's model over one chart step (its time constant, 20 ms, is 10 chart steps).
SV_SUBSTEPS = 4

#: The wiring table's ports :func:`monitor` returns, in its order (the Monitor block's, then the FK block's;
#: the tool's phi after them is the stage's own).
PORTS = ("Monitor.err", "Monitor.speed", "Monitor.cmd_speed", "Monitor.current", "Monitor.q", "Monitor.fast",
         "Monitor.servo_err", "Monitor.servo_q", "FK.X", "FK.Y", "FK.Z")
#: What :func:`monitor` returns, by position: following errors, encoder speeds, commanded speeds,
#: currents (magnitudes), encoder angles, at the speed clamp (three each), the servo's error and its
#: feedback angle, then the tool's x, y, z, phi.
OUT_ERR, OUT_SPEED, OUT_CMD_SPEED, OUT_CURRENT, OUT_Q, OUT_FAST = 0, 3, 6, 9, 12, 15
OUT_SERVO_ERR, OUT_SERVO_Q, OUT_TOOL = 18, 19, 20
N_OUT = 24


def _chain_fingerprint() -> str:
    """SHA-256 of the forward kinematics' source: numba's disk cache checks only this file (see twin/_kernel.py)."""
    return hashlib.sha256(Path(str(chain.__file__)).read_bytes()).hexdigest()


def _compile(fingerprint: str) -> tuple[Any, Any]:
    """The two functions, compiled (or loaded from numba's cache) for this forward kinematics."""

    @njit(cache=True, error_model="numpy")
    def monitor(m: np.ndarray, c1: int, c2: int, c3: int, i1: float, i2: float, i3: float,
                o1: float, o2: float, o3: float, servo: float, servo_q: float) -> tuple[Any, ...]:
        """The Monitor block's outputs for counts `c`, currents `i`, offsets `o`, the servo's setpoint `servo`
        and its feedback reading `servo_q`.

        Returns the ``N_OUT`` numbers ``OUT_*`` lays out; remembers the counts for the next chart step's speeds.
        """
        fingerprint  # noqa: B018  (a closure variable: part of numba's cache key)
        # the init charts moved the encoder coordinates: the model's angles move with them
        for i, o in ((0, o1), (1, o2), (2, o3)):
            delta = o - m[M_OFFSET + i]
            if delta != 0.0:
                m[M_R + i] += delta
                m[M_P + i] += delta
                m[M_OFFSET + i] = o
        e1 = c1 * m[M_RPC] + o1
        e2 = c2 * m[M_RPC + 1] + o2
        e3 = c3 * m[M_RPC + 2] + o3
        s1 = abs(c1 - m[M_COUNTS]) * m[M_SPEED_PER_COUNT]
        s2 = abs(c2 - m[M_COUNTS + 1]) * m[M_SPEED_PER_COUNT + 1]
        s3 = abs(c3 - m[M_COUNTS + 2]) * m[M_SPEED_PER_COUNT + 2]
        m[M_COUNTS], m[M_COUNTS + 1], m[M_COUNTS + 2] = c1, c2, c3
        dt = m[M_CHART_DT]
        x, y, z, phi, _, _, _, _ = arm_chain(e1, e2, e3, servo, m[M_GEOMETRY], m[M_GEOMETRY + 1],
                                             m[M_GEOMETRY + 2], m[M_GEOMETRY + 3], m[M_GEOMETRY + 4])
        return (m[M_P] - e1, m[M_P + 1] - e2, m[M_P + 2] - e3, s1, s2, s3,
                m[M_DP] / dt, m[M_DP + 1] / dt, m[M_DP + 2] / dt, abs(i1), abs(i2), abs(i3),
                e1, e2, e3, m[M_FAST] > 0, m[M_FAST + 1] > 0, m[M_FAST + 2] > 0, m[M_SV] - servo_q, servo_q,
                x, y, z, phi)

    @njit(cache=True, error_model="numpy")
    def advance(m: np.ndarray, u1: float, u2: float, u3: float, slow: bool, u4: float) -> None:
        """Step the model of the setpoint filters as the controller will over this chart step's control steps,
        and the model of the servo with its setpoint `u4`."""
        fingerprint  # noqa: B018
        h = m[M_CHART_DT] / SV_SUBSTEPS
        rate, inv_tau, sv = m[M_SV_RATE], m[M_SV_INV_TAU], m[M_SV]
        for _ in range(SV_SUBSTEPS):
            w = (u4 - sv) * inv_tau
            sv += h * (rate if w > rate else (-rate if w < -rate else w))
        m[M_SV] = sv
        row = M_ROW_SLOW if slow else M_ROW
        a11, a12, b1 = m[row], m[row + 1], m[row + 2]
        a21, a22, b2 = m[row + 3], m[row + 4], m[row + 5]
        for i, u in ((0, u1), (1, u2), (2, u3)):
            r, v = m[M_R + i], m[M_V + i]
            rn = a11 * r + a12 * v + b1 * u
            m[M_R + i] = rn
            m[M_V + i] = a21 * r + a22 * v + b2 * u
            step = m[M_STEP_MAX + i]
            d = rn - m[M_P + i]
            if d > step:
                d = step
            elif d < -step:
                d = -step
            m[M_DP + i] = d
            m[M_P + i] += d
            # at the clamp, and for a while after, the drive lags its acceleration behind the model
            if d == step or d == -step:
                m[M_FAST + i] = m[M_FAST_STEPS]
            elif m[M_FAST + i] > 0:
                m[M_FAST + i] -= 1.0

    return monitor, advance


monitor, advance = _compile(_chain_fingerprint())
