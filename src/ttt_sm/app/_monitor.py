"""The Safety stage's Monitor block, compiled: one call per chart step (docs/safety.md, "Cost").

The Monitor block (:class:`~ttt_sm.app.safety_wiring.SafetyStage`) runs on
every chart step of every robot.  Written as plain Python it cost more than
the Safety chart it feeds (~15 µs a chart step of a game); here its
arithmetic is compiled functions over one float buffer ``m[M_*]``, the
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

The stage calls :func:`step`, which does both around the Safety chart: it
reads the arm (in place in the simulated arm's memory, or from copies of the
protocol's readings), runs :func:`monitor`, writes its outputs and the flags
into the chart's buffer (the chart is buffered: docs/runtime.md, "Data in a
buffer") where the wiring table sends them and, while the chart is in
``monitoring`` with no event queued and no input forced, tries that state's
guards on the chart's data; when none holds, it does the chart's quiet tick
(previous outputs, the still timers of ``Safety._count_still``) and
:func:`advance`, all in one call.  Otherwise the chart ticks itself: its
Python code stays the definition, and tests hold :func:`step` to it.

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
M_TICK_S = 52  # 1: the Safety chart's tick period (its still timers count it), s
M_FB_CAL = 53  # 3: the servo feedback's calibration a0, c0, 1/k: a0 + (counts - c0) / k rad (app/_monitor.py: SRC_*)
M_OUT = 56  # N_OUT: what :func:`monitor` (or :func:`step`) computed this chart step, OUT_* by position
N_M = M_OUT + 24
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

#: The Safety chart's data :func:`step` reads and writes in the chart's buffer, by their places in the
#: int array ``ix`` (``IX_*``): first where each of the ``N_OUT`` outputs goes (-1: wired elsewhere),
#: then the inputs wired from the Link, Camera and Homing blocks, then these data by name.
FLAGS = ("initialised", "init_failed", "link_ok", "camera_ok")
NAMES = ("err_1", "err_2", "err_3", "speed_1", "speed_2", "speed_3", "cmd_speed_1", "cmd_speed_2", "cmd_speed_3",
         "current_1", "current_2", "current_3", "q_1", "q_2", "q_3", "fast_1", "fast_2", "fast_3", "servo_err",
         "max_following_error", "max_following_error_init", "max_following_error_fast", "max_current",
         "max_current_init", "max_speed", "moving_speed", "stall_ratio", "silent_s", "limit_margin",
         "q_min_1", "q_min_2", "q_min_3", "q_max_1", "q_max_2", "q_max_3",
         "still_1", "still_2", "still_3", "max_servo_error", "servo_error_s", "servo_off")
IX_FLAGS = N_OUT
IX_NAMES = IX_FLAGS + len(FLAGS)
#: Where :func:`step` reads the arm: counts (3, in the int source), currents (3, float source), the servo
#: feedback (float source, through ``M_FB_CAL``), offsets (3, controller source), the servo's setpoint (same).
IX_SRC = IX_NAMES + len(NAMES)
SRC_COUNTS, SRC_CURRENTS, SRC_SERVO_Q, SRC_OFFSETS, SRC_SERVO = 0, 3, 6, 7, 10
N_SRC = 11
IX_PREV = IX_SRC + N_SRC  # then the number of (output, previous) pairs, and the pairs
#: What :func:`step` returns when it only fed the chart (a guard of ``monitoring`` holds, or not asked to tick).
FED = -2


def _chain_fingerprint() -> str:
    """SHA-256 of the forward kinematics' source: numba's disk cache checks only this file (see twin/_kernel.py)."""
    return hashlib.sha256(Path(str(chain.__file__)).read_bytes()).hexdigest()


def _compile(fingerprint: str) -> tuple[Any, Any, Any]:
    """The three functions, compiled (or loaded from numba's cache) for this forward kinematics."""

    @njit(cache=True, error_model="numpy")
    def monitor_(m: np.ndarray, c1: int, c2: int, c3: int, i1: float, i2: float, i3: float,
                o1: float, o2: float, o3: float, servo: float, servo_q: float) -> None:
        """The Monitor block's outputs for counts `c`, currents `i`, offsets `o`, the servo's setpoint `servo`
        and its feedback reading `servo_q`.

        Writes the ``N_OUT`` numbers ``OUT_*`` lays out into ``m[M_OUT:]`` (a flag as 1.0 or 0.0);
        remembers the counts for the next chart step's speeds.
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
        o = M_OUT
        m[o + OUT_ERR], m[o + OUT_ERR + 1], m[o + OUT_ERR + 2] = m[M_P] - e1, m[M_P + 1] - e2, m[M_P + 2] - e3
        m[o + OUT_SPEED], m[o + OUT_SPEED + 1], m[o + OUT_SPEED + 2] = s1, s2, s3
        for i in range(3):
            m[o + OUT_CMD_SPEED + i] = m[M_DP + i] / dt
            m[o + OUT_FAST + i] = 1.0 if m[M_FAST + i] > 0 else 0.0
        m[o + OUT_CURRENT], m[o + OUT_CURRENT + 1], m[o + OUT_CURRENT + 2] = abs(i1), abs(i2), abs(i3)
        m[o + OUT_Q], m[o + OUT_Q + 1], m[o + OUT_Q + 2] = e1, e2, e3
        m[o + OUT_SERVO_ERR], m[o + OUT_SERVO_Q] = m[M_SV] - servo_q, servo_q
        m[o + OUT_TOOL], m[o + OUT_TOOL + 1], m[o + OUT_TOOL + 2], m[o + OUT_TOOL + 3] = x, y, z, phi

    @njit(cache=True, error_model="numpy")
    def advance_(m: np.ndarray, u1: float, u2: float, u3: float, slow: bool, u4: float) -> None:
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

    @njit(cache=True, error_model="numpy")
    def step(m: np.ndarray, b: np.ndarray, ix: np.ndarray, fsrc: np.ndarray, isrc: np.ndarray, csrc: np.ndarray,
             initialised: bool, init_failed: bool, link_ok: bool, camera_ok: bool, quiet: bool,
             u1: float, u2: float, u3: float, slow: bool, u4: float) -> int:
        """The Monitor block into the Safety chart's buffer `b`, and, with `quiet`, the chart's tick in
        ``monitoring`` when none of its transitions fires.

        Reads the arm where ``ix[IX_SRC:]`` says (the simulated arm's own memory, or the
        numbers the stage copied from the :class:`~ttt_sm.arm.Arm` protocol's readings),
        computes :func:`monitor` (into ``m[M_OUT:]``), writes it and the flags where the
        wiring table sends them in `b` (places in `ix`, ``IX_*``).  Without `quiet`, returns
        ``FED``: the chart ticks itself.  With it, tries the guards of ``monitoring`` in the
        chart's order (``Safety.arm_fault``; ``not camera_ok and initialised``; ``not camera_ok``;
        ``servo_stuck and initialised``; ``servo_stuck``) on the chart's data: if one holds,
        returns ``FED`` and the chart ticks itself (taking it); else does what the chart's tick
        would: each output to its previous value, the during action (``Safety._count_still``),
        then :func:`advance` with the setpoints `u`, and returns -1.
        """
        fingerprint  # noqa: B018
        r = IX_SRC
        servo = csrc[ix[r + SRC_SERVO]]
        servo_q = m[M_FB_CAL] + (fsrc[ix[r + SRC_SERVO_Q]] - m[M_FB_CAL + 1]) * m[M_FB_CAL + 2]
        monitor(m, isrc[ix[r]], isrc[ix[r + 1]], isrc[ix[r + 2]],
                fsrc[ix[r + SRC_CURRENTS]], fsrc[ix[r + SRC_CURRENTS + 1]], fsrc[ix[r + SRC_CURRENTS + 2]],
                csrc[ix[r + SRC_OFFSETS]], csrc[ix[r + SRC_OFFSETS + 1]], csrc[ix[r + SRC_OFFSETS + 2]],
                servo, servo_q)
        for j in range(N_OUT):
            if ix[j] >= 0:
                b[ix[j]] = m[M_OUT + j]
        f = IX_FLAGS
        b[ix[f]], b[ix[f + 1]], b[ix[f + 2]], b[ix[f + 3]] = initialised, init_failed, link_ok, camera_ok
        if not quiet:
            return FED
        n = IX_NAMES
        err1, err2, err3 = b[ix[n]], b[ix[n + 1]], b[ix[n + 2]]
        sp1, sp2, sp3 = b[ix[n + 3]], b[ix[n + 4]], b[ix[n + 5]]
        cmd1, cmd2, cmd3 = b[ix[n + 6]], b[ix[n + 7]], b[ix[n + 8]]
        cu1, cu2, cu3 = b[ix[n + 9]], b[ix[n + 10]], b[ix[n + 11]]
        q1, q2, q3 = b[ix[n + 12]], b[ix[n + 13]], b[ix[n + 14]]
        fa1, fa2, fa3 = b[ix[n + 15]] != 0.0, b[ix[n + 16]] != 0.0, b[ix[n + 17]] != 0.0
        servo_err = b[ix[n + 18]]
        ini = b[ix[f]] != 0.0
        still1, still2, still3 = b[ix[n + 35]], b[ix[n + 36]], b[ix[n + 37]]
        max_servo_error, servo_error_s, servo_off = b[ix[n + 38]], b[ix[n + 39]], b[ix[n + 40]]
        # Safety.arm_fault
        fault = b[ix[f + 2]] == 0.0 or b[ix[f + 1]] != 0.0
        if not fault:
            cur_max = b[ix[n + 22]] if ini else b[ix[n + 23]]
            speed_max, silent = b[ix[n + 24]], b[ix[n + 27]]
            fault = (sp1 > speed_max or sp2 > speed_max or sp3 > speed_max
                     or cu1 > cur_max or cu2 > cur_max or cu3 > cur_max
                     or still1 >= silent or still2 >= silent or still3 >= silent)
        if not fault:
            err_max = b[ix[n + 19]] if ini else b[ix[n + 20]]
            fast = b[ix[n + 21]]
            fault = (abs(err1) > (fast if fa1 and fast > err_max else err_max)
                     or abs(err2) > (fast if fa2 and fast > err_max else err_max)
                     or abs(err3) > (fast if fa3 and fast > err_max else err_max))
        if not fault and ini:
            mg = b[ix[n + 28]]
            fault = not (b[ix[n + 29]] - mg <= q1 <= b[ix[n + 32]] + mg
                         and b[ix[n + 30]] - mg <= q2 <= b[ix[n + 33]] + mg
                         and b[ix[n + 31]] - mg <= q3 <= b[ix[n + 34]] + mg)
        # not camera_ok (and initialised); Safety.servo_stuck (and initialised)
        if fault or b[ix[f + 3]] == 0.0 or servo_off >= servo_error_s:
            return FED
        # the quiet tick: outputs to their previous values, then during_monitoring
        p = IX_PREV
        for k in range(ix[p]):
            b[ix[p + 1 + 2 * k + 1]] = b[ix[p + 1 + 2 * k]]
        dt, moving = m[M_TICK_S], b[ix[n + 25]]
        ratio = b[ix[n + 26]] if ini else 0.0
        a1, a2, a3 = abs(cmd1), abs(cmd2), abs(cmd3)
        b[ix[n + 35]] = still1 + dt if a1 > moving and sp1 <= ratio * a1 else 0.0
        b[ix[n + 36]] = still2 + dt if a2 > moving and sp2 <= ratio * a2 else 0.0
        b[ix[n + 37]] = still3 + dt if a3 > moving and sp3 <= ratio * a3 else 0.0
        b[ix[n + 40]] = servo_off + dt if abs(servo_err) > max_servo_error else 0.0
        advance(m, u1, u2, u3, slow, u4)
        return -1

    # step calls monitor and advance as this module's globals: a closure over a compiled function
    # is not cached by numba (every process would compile step again, ~2 s)
    return monitor_, advance_, step


monitor, advance, step = _compile(_chain_fingerprint())
