"""The cascade controllers in-process: the memory and the commands of the compiled controller step.

:class:`CascadeController` is what a microcontroller runs for a real arm
(thesis section 3.2, fig. 3.6): per DC drive a setpoint filter switched by
``fr_sw``, a speed estimate from the encoder, an outer position PID and an
inner speed PID with PWM saturation; and the servo's PWM.  It holds the
controller's parameters (from the parameter file and the gains), its state
and its outputs in the layout of ``layout.py`` (docs/model.md, "The
controller step"), takes setpoints, offsets and modes, and runs
``_cascade.cascade_step``: encoder counts in, actuator commands out.  It
never sees the plant: the simulated arm (:class:`ttt_sm.twin.sim.ArmSim`)
feeds it the plant's counts inside one compiled loop.

Drives are numbered 1, 2, 3 as in the thesis wherever a method takes a
drive number; arrays of three are indexed 0..2 (drive 1 first).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from math import isfinite

import numpy as np

from ..params import ArmParams
from . import _cascade as C
from . import layout
from ._buffers import flat_view
from .errors import SimError
from .gains import Gains, check_drive, setpoint_filter_row, speed_filter_alpha

# slots of the controllers' shared state that every chart step writes
_FR_SW, _SV_SET = layout.CGS_FR_SW, layout.CGS_SV_SET


class CascadeController:
    """The three drives' cascade controllers and the servo's PWM, with their state.

    Parameters
    ----------
    params : ArmParams
        The parameter file (control rate, filters, encoders, servo calibration).
    gains : Gains
        The cascade's gains (``tuning.design_gains``).
    servo_angle : float
        The servo's setpoint at power-on (rad): where it stands.

    Attributes
    ----------
    buffer : ndarray, shape (``layout.N_CR``, ``layout.CONTROLLER_WIDTH``)
        The controller's float memory; ``cp``, ``cs`` (3 rows each), ``cg``,
        ``cgs`` and ``act`` are views of its rows (``layout.CR_*``).
    modes : ndarray of int64, shape (3,)
        ``MODE_OFF``, ``MODE_CLOSED`` or ``MODE_OPEN`` per drive; all drives
        start closed, holding where they power on.
    """

    def __init__(self, params: ArmParams, gains: Gains, servo_angle: float) -> None:
        self.buffer = np.zeros((layout.N_CR, layout.CONTROLLER_WIDTH))
        self.cp, self.cs = self.buffer[layout.CR_CP:layout.CR_CP + 3], self.buffer[layout.CR_CS:layout.CR_CS + 3]
        self.cg, self.cgs, self.act = self.buffer[layout.CR_CG], self.buffer[layout.CR_CGS], self.buffer[layout.CR_ACT]
        self.modes = np.full(3, layout.MODE_CLOSED, dtype=np.int64)
        alpha = speed_filter_alpha(params.control)
        for d, p in enumerate(params.drives):
            self.cp[d, layout.CP_RPC] = p.rad_per_count
            self.cp[d, layout.CP_ALPHA_W] = alpha
        self.set_gains(gains)
        c, s, cg = params.control, params.servo, self.cg
        cg[layout.CG_DT] = c.dt
        cg[layout.CG_SF_NORMAL:layout.CG_SF_NORMAL + 6] = setpoint_filter_row(c.setpoint_cutoff_hz, c.dt)
        cg[layout.CG_SF_SLOW:layout.CG_SF_SLOW + 6] = setpoint_filter_row(c.setpoint_cutoff_slow_hz, c.dt)
        cg[layout.CG_SV_MIN:layout.CG_SV_MIN + layout.SERVO_CALIBRATION_SIZE] = s.calibration
        self.cgs[layout.CGS_SV_SET] = servo_angle
        self.cgs[layout.CGS_SV_DUTY_OF] = math.nan  # the first step computes the servo's duty
        # Flat views for the per-chart-step commands: a memoryview reads and
        # writes plain Python numbers at a third of the cost of numpy indexing.
        self._csv = flat_view(self.cs)
        self._cgsv = flat_view(self.cgs)
        self._modev = flat_view(self.modes)
        # ... at flat indices worked out once (not from the layout's names on every call)
        n = layout.CONTROLLER_WIDTH
        self._i_raw = (layout.CS_R_RAW, n + layout.CS_R_RAW, 2 * n + layout.CS_R_RAW)
        self._i_offset = (layout.CS_OFFSET, n + layout.CS_OFFSET, 2 * n + layout.CS_OFFSET)

    def set_gains(self, gains: Gains) -> None:
        """Run the cascades with `gains` from the next step on; states and integrators are kept (no bump)."""
        for d, g in enumerate(gains.drives):
            row = self.cp[d]
            row[layout.CP_KP_POS] = g.kp_pos
            row[layout.CP_KI_POS] = g.ki_pos
            row[layout.CP_KD_POS] = g.kd_pos
            row[layout.CP_KFF] = g.kff_speed
            row[layout.CP_WMAX] = g.max_speed_rad_s
            row[layout.CP_KP_SPD] = g.kp_speed
            row[layout.CP_KI_SPD] = g.ki_speed
            row[layout.CP_KD_SPD] = g.kd_speed

    # ---- the step -------------------------------------------------------------

    def step(self, counts: np.ndarray) -> None:
        """One control step on its own: encoder `counts` (3 int64) in, :attr:`act` out.

        The simulated arm does not call this: its fused loop runs the same
        compiled step beside the plant's (``_kernel.run_steps``).
        """
        C.cascade_step(self.cp, self.cg, self.cs, self.cgs, self.modes, counts, self.act)

    # ---- commands --------------------------------------------------------------

    def set_setpoints(self, q_des: Sequence[float] | np.ndarray, fr_sw: bool = False) -> None:
        """Joint setpoints: drives 1-3 in encoder coordinates (rad), q4 the servo angle (rad).

        `fr_sw` selects the slow setpoint filters (thesis' slow moves).  The
        step turns the servo angle into its PWM duty.
        """
        try:
            q1, q2, q3, q4 = q_des
            finite = isfinite(q1) and isfinite(q2) and isfinite(q3) and isfinite(q4)
        except (TypeError, ValueError):
            finite = False
        if not finite:
            raise SimError(f"setpoints must be 4 finite angles (rad), got {q_des!r}")
        # (a float64 view takes any real number as float() makes it)
        cs, (i1, i2, i3) = self._csv, self._i_raw
        cs[i1] = q1
        cs[i2] = q2
        cs[i3] = q3
        cgs = self._cgsv
        cgs[_FR_SW] = 1.0 if fr_sw else 0.0
        cgs[_SV_SET] = q4

    @property
    def servo_setpoint(self) -> float:
        """The servo angle last commanded (rad)."""
        return self._cgsv[layout.CGS_SV_SET]

    def offset_estimates(self) -> tuple[float, float, float]:
        """The encoder offsets (rad), 0 until a drive is initialised."""
        cs, (i1, i2, i3) = self._csv, self._i_offset
        return cs[i1], cs[i2], cs[i3]

    def set_offset_estimate(self, drive: int, offset_rad: float) -> None:
        """Set a drive's encoder offset (rad); its setpoints and speed estimate move with it.

        The physical target stays where it was, so the arm does not jump.
        """
        C.set_offset(self.cs, check_drive(drive) - 1, float(offset_rad))

    def enabled(self) -> tuple[bool, bool, bool]:
        """True per drive while its cascade runs."""
        m, on = self._modev, layout.MODE_CLOSED
        return m[0] == on, m[1] == on, m[2] == on

    def mode(self, drive: int) -> int:
        """Drive `drive`'s mode: ``MODE_OFF``, ``MODE_CLOSED`` or ``MODE_OPEN`` (``_cascade``)."""
        return int(self.modes[check_drive(drive) - 1])

    def set_mode(self, drive: int, mode: int, hold_rad: float | None = None) -> None:
        """Switch drive `drive` to `mode`; entering closed loop holds `hold_rad` (its encoder angle), bumplessly."""
        d = check_drive(drive) - 1
        if mode == layout.MODE_CLOSED and self.modes[d] != layout.MODE_CLOSED and hold_rad is None:
            raise SimError(f"drive {drive}: closing the loop needs the angle to hold")
        C.set_mode(self.cs, self.modes, d, mode, math.nan if hold_rad is None else hold_rad)

    def set_open_duty(self, drive: int, duty: float) -> None:
        """Drive open loop with a fixed PWM duty (clipped to -1..1 by the step)."""
        C.set_open_duty(self.cs, self.modes, check_drive(drive) - 1, float(duty))

    def hold(self, drive: int, q_rad: float) -> None:
        """Make drive `drive`'s cascade hold the encoder angle `q_rad`, with no bump: filters and integrators reset."""
        C.hold(self.cs, check_drive(drive) - 1, q_rad)

    # ---- outputs ------------------------------------------------------------------

    @property
    def duty(self) -> np.ndarray:
        """PWM duties applied to the three H-bridges now (-1..1), a copy."""
        return self.act[layout.ACT_DUTY:layout.ACT_DUTY + 3].copy()

    @property
    def servo_duty(self) -> float:
        """The servo's PWM duty now (0..1)."""
        return float(self.act[layout.ACT_SV_DUTY])

    def max_speed(self) -> np.ndarray:
        """Speed setpoint clamps of drives 1..3 (rad/s)."""
        return self.cp[:, layout.CP_WMAX].copy()


__all__ = ["CascadeController"]
