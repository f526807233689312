"""The Safety stage's Monitor block, compiled: one call per chart step (docs/safety.md, "Cost").

The Monitor block (:class:`~ttt_sm.app.safety_wiring.SafetyStage`) runs on
every chart step of every robot.  Written as plain Python it cost more than
the Safety chart it feeds (~15 µs a chart step of a game); here its
arithmetic is compiled functions over one float buffer ``m[M_*]``, the
stage's whole state (its layout, and those of ``OUT_*``, ``ix[IX_*]`` and
``SRC_*``, are tables in ``_monitor_layout.py``):

- :func:`monitor`, before the chart ticks: the encoder angles from this chart
  step's counts and the offsets (``counts * rad_per_count + offset``, as the
  :class:`~ttt_sm.arm.Arm` protocol defines them), the following errors
  against the model of the setpoint filters, the encoder speeds from the
  counts, the commanded speeds, the currents' magnitudes, which drives count
  as at their speed clamp, the pen servo's error (the model of the servo
  minus its feedback reading) and the tool pose by forward kinematics
  (:func:`~ttt_sm.twin.kinematics.chain.arm_chain`) of the encoder angles;
- :func:`advance`, after the chart ticked: the model of the controller's
  setpoint filters (the controller's own :func:`~ttt_sm.twin._cascade.setpoint_filter`,
  with its coefficients over a chart step) stepped with the setpoints sent to the drives, followed no
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

from typing import Any

import numpy as np
from numba import njit

from ..twin import _cascade, layout
from ..twin._cascade import setpoint_filter
from ..twin.kinematics import chain
from ..twin.kinematics.chain import arm_chain
from . import _monitor_layout
from ._monitor_layout import (
    IX_CAMERA_OK,
    IX_CMD_SPEED_1,
    IX_CMD_SPEED_2,
    IX_CMD_SPEED_3,
    IX_CURRENT_1,
    IX_CURRENT_2,
    IX_CURRENT_3,
    IX_ERR_1,
    IX_ERR_2,
    IX_ERR_3,
    IX_FAST_1,
    IX_FAST_2,
    IX_FAST_3,
    IX_INIT_FAILED,
    IX_INITIALISED,
    IX_LIMIT_MARGIN,
    IX_LINK_OK,
    IX_MAX_CURRENT,
    IX_MAX_CURRENT_INIT,
    IX_MAX_FOLLOWING_ERROR,
    IX_MAX_FOLLOWING_ERROR_FAST,
    IX_MAX_FOLLOWING_ERROR_INIT,
    IX_MAX_SERVO_ERROR,
    IX_MAX_SPEED,
    IX_MOVING_SPEED,
    IX_PREV,
    IX_Q_1,
    IX_Q_2,
    IX_Q_3,
    IX_Q_MAX_1,
    IX_Q_MAX_2,
    IX_Q_MAX_3,
    IX_Q_MIN_1,
    IX_Q_MIN_2,
    IX_Q_MIN_3,
    IX_SERVO_ERR,
    IX_SERVO_ERROR_S,
    IX_SERVO_OFF,
    IX_SILENT_S,
    IX_SPEED_1,
    IX_SPEED_2,
    IX_SPEED_3,
    IX_SRC,
    IX_STALL_RATIO,
    IX_STILL_1,
    IX_STILL_2,
    IX_STILL_3,
    M_CHART_DT,
    M_COUNTS,
    M_DP,
    M_FAST,
    M_FAST_STEPS,
    M_FB_CAL,
    M_GEOMETRY,
    M_OFFSET,
    M_OUT,
    M_P,
    M_R,
    M_ROW,
    M_ROW_SLOW,
    M_RPC,
    M_SPEED_PER_COUNT,
    M_STEP_MAX,
    M_SV,
    M_SV_INV_TAU,
    M_SV_RATE,
    M_TICK_S,
    M_V,
    N_OUT,
    OUT_CMD_SPEED,
    OUT_CURRENT,
    OUT_ERR,
    OUT_FAST,
    OUT_Q,
    OUT_SERVO_ERR,
    OUT_SERVO_Q,
    OUT_SPEED,
    OUT_TOOL,
    SRC_CURRENTS,
    SRC_OFFSETS,
    SRC_SERVO,
    SRC_SERVO_Q,
)

#: Sub-steps of the servo's model over one chart step (its time constant, 20 ms, is 10 chart steps).
SV_SUBSTEPS = 4

#: The wiring table's ports :func:`monitor` returns, in its order (the Monitor block's, then the FK block's;
#: the tool's phi after them is the stage's own).
PORTS = ("Monitor.err", "Monitor.speed", "Monitor.cmd_speed", "Monitor.current", "Monitor.q", "Monitor.fast",
         "Monitor.servo_err", "Monitor.servo_q", "FK.X", "FK.Y", "FK.Z")
#: What :func:`step` returns when it only fed the chart (a guard of ``monitoring`` holds, or not asked to tick).
FED = -2


def _sources_fingerprint() -> str:
    """SHA-256 of the sources the functions are compiled from beside this file: numba's disk cache checks only
    this file (see twin/_kernel.py): the forward kinematics, the setpoint filter, the layouts."""
    return layout.fingerprint(*(str(m.__file__) for m in (chain, _cascade, _monitor_layout, layout)))


def _compile(fingerprint: str) -> tuple[Any, Any, Any]:
    """The three functions, compiled (or loaded from numba's cache) for these sources (:func:`_sources_fingerprint`)."""

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
        for i, u in ((0, u1), (1, u2), (2, u3)):
            rn, m[M_V + i] = setpoint_filter(m, row, m[M_R + i], m[M_V + i], u)  # the controller's own filter
            m[M_R + i] = rn
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
        b[ix[IX_INITIALISED]], b[ix[IX_INIT_FAILED]] = initialised, init_failed
        b[ix[IX_LINK_OK]], b[ix[IX_CAMERA_OK]] = link_ok, camera_ok
        if not quiet:
            return FED
        err1, err2, err3 = b[ix[IX_ERR_1]], b[ix[IX_ERR_2]], b[ix[IX_ERR_3]]
        sp1, sp2, sp3 = b[ix[IX_SPEED_1]], b[ix[IX_SPEED_2]], b[ix[IX_SPEED_3]]
        cmd1, cmd2, cmd3 = b[ix[IX_CMD_SPEED_1]], b[ix[IX_CMD_SPEED_2]], b[ix[IX_CMD_SPEED_3]]
        cu1, cu2, cu3 = b[ix[IX_CURRENT_1]], b[ix[IX_CURRENT_2]], b[ix[IX_CURRENT_3]]
        q1, q2, q3 = b[ix[IX_Q_1]], b[ix[IX_Q_2]], b[ix[IX_Q_3]]
        fa1, fa2, fa3 = b[ix[IX_FAST_1]] != 0.0, b[ix[IX_FAST_2]] != 0.0, b[ix[IX_FAST_3]] != 0.0
        servo_err = b[ix[IX_SERVO_ERR]]
        ini = b[ix[IX_INITIALISED]] != 0.0
        still1, still2, still3 = b[ix[IX_STILL_1]], b[ix[IX_STILL_2]], b[ix[IX_STILL_3]]
        max_servo_error, servo_error_s = b[ix[IX_MAX_SERVO_ERROR]], b[ix[IX_SERVO_ERROR_S]]
        servo_off = b[ix[IX_SERVO_OFF]]
        # Safety.arm_fault
        fault = b[ix[IX_LINK_OK]] == 0.0 or b[ix[IX_INIT_FAILED]] != 0.0
        if not fault:
            cur_max = b[ix[IX_MAX_CURRENT]] if ini else b[ix[IX_MAX_CURRENT_INIT]]
            speed_max, silent = b[ix[IX_MAX_SPEED]], b[ix[IX_SILENT_S]]
            fault = (sp1 > speed_max or sp2 > speed_max or sp3 > speed_max
                     or cu1 > cur_max or cu2 > cur_max or cu3 > cur_max
                     or still1 >= silent or still2 >= silent or still3 >= silent)
        if not fault:
            err_max = b[ix[IX_MAX_FOLLOWING_ERROR]] if ini else b[ix[IX_MAX_FOLLOWING_ERROR_INIT]]
            fast = b[ix[IX_MAX_FOLLOWING_ERROR_FAST]]
            fault = (abs(err1) > (fast if fa1 and fast > err_max else err_max)
                     or abs(err2) > (fast if fa2 and fast > err_max else err_max)
                     or abs(err3) > (fast if fa3 and fast > err_max else err_max))
        if not fault and ini:
            mg = b[ix[IX_LIMIT_MARGIN]]
            fault = not (b[ix[IX_Q_MIN_1]] - mg <= q1 <= b[ix[IX_Q_MAX_1]] + mg
                         and b[ix[IX_Q_MIN_2]] - mg <= q2 <= b[ix[IX_Q_MAX_2]] + mg
                         and b[ix[IX_Q_MIN_3]] - mg <= q3 <= b[ix[IX_Q_MAX_3]] + mg)
        # not camera_ok (and initialised); Safety.servo_stuck (and initialised)
        if fault or b[ix[IX_CAMERA_OK]] == 0.0 or servo_off >= servo_error_s:
            return FED
        # the quiet tick: outputs to their previous values, then during_monitoring
        p = IX_PREV
        for k in range(ix[p]):
            b[ix[p + 1 + 2 * k + 1]] = b[ix[p + 1 + 2 * k]]
        dt, moving = m[M_TICK_S], b[ix[IX_MOVING_SPEED]]
        ratio = b[ix[IX_STALL_RATIO]] if ini else 0.0
        a1, a2, a3 = abs(cmd1), abs(cmd2), abs(cmd3)
        b[ix[IX_STILL_1]] = still1 + dt if a1 > moving and sp1 <= ratio * a1 else 0.0
        b[ix[IX_STILL_2]] = still2 + dt if a2 > moving and sp2 <= ratio * a2 else 0.0
        b[ix[IX_STILL_3]] = still3 + dt if a3 > moving and sp3 <= ratio * a3 else 0.0
        b[ix[IX_SERVO_OFF]] = servo_off + dt if abs(servo_err) > max_servo_error else 0.0
        advance(m, u1, u2, u3, slow, u4)
        return -1

    # step calls monitor and advance as this module's globals: a closure over a compiled function
    # is not cached by numba (every process would compile step again, ~2 s)
    return monitor_, advance_, step


monitor, advance, step = _compile(_sources_fingerprint())
