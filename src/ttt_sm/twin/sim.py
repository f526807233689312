"""The simulated arm: the cascade controller and the plant, fused in one compiled loop.

:class:`ArmSim` is the simulation backend of the :class:`ttt_sm.arm.Arm`
protocol, what the scheduler steps at the control rate.  It holds two
separate parts, each with its own memory and its own compiled step:

* the cascade controller (:class:`~ttt_sm.twin.cascade.CascadeController`,
  ``_cascade.cascade_step``): setpoint filters switched by ``fr_sw``, speed
  estimate, outer position PID, inner speed PID, PWM saturation, the
  servo's PWM; encoder counts in, actuator commands out.  A hardware
  backend runs this in its microcontroller;
* the plant (:class:`~ttt_sm.twin.plant.Plant`, ``_plant.plant_step``):
  drives, gears, gravity, hard stops, encoders, index switches, servo,
  currents; actuator commands in, motion and sensors out.

:meth:`ArmSim.step` runs both, one after the other in every control step,
inside one compiled loop (``_kernel.run_steps``), so a step costs what the
single kernel cost.  Ground truth, which a real arm cannot report, is
behind :attr:`ArmSim.truth` (:class:`~ttt_sm.twin.truth.ArmTruth`).

Drives are numbered 1, 2, 3 as in the thesis wherever a method takes a
drive number; arrays of three are indexed 0..2 (drive 1 first).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..arm.protocol import Sensors
from ..params import ArmParams
from . import _kernel as K
from . import layout
from .cascade import CascadeController
from .errors import SimError
from .gains import Gains
from .gains_cache import kept_gains
from .plant import CURRENT_NOISE_A, REST_POSE, SUBSTEPS, Angles, Plant, check_pose, gravity_torques
from .truth import ArmTruth


@dataclass(frozen=True)
class Trace:
    """Time series of a run, one row per control step (taken at its end).

    Columns of the (n, 4) arrays are drives 1..3 and the servo; of the
    (n, 3) arrays drives 1..3.  For the servo, ``setpoint_filtered`` is the
    angle its PWM duty commands and ``duty`` its PWM duty (0..1).
    ``q_true``, ``q_motor`` and ``current_a`` are ground truth (simulation only).
    """

    t: np.ndarray  # (n,) s
    setpoint_raw: np.ndarray  # (n, 4) rad, encoder coordinates for drives 1-3
    setpoint_filtered: np.ndarray  # (n, 4) rad
    q_encoder: np.ndarray  # (n, 3) rad, what the controllers see
    q_true: np.ndarray  # (n, 4) rad, load side
    q_motor: np.ndarray  # (n, 3) rad, motor angle / gear ratio
    current_a: np.ndarray  # (n, 3) A, true armature current
    duty: np.ndarray  # (n, 4) PWM duty applied
    speed_ref: np.ndarray  # (n, 3) rad/s, outer loop output
    speed_meas: np.ndarray  # (n, 3) rad/s, filtered encoder derivative


@dataclass(frozen=True)
class ReadingsInPlace:
    """The simulated arm's readings where they live (:meth:`ArmSim.readings_in_place`).

    ``plant_floats[currents[k]]`` is drive k's measured current (A), ``plant_ints[counts[k]]`` its
    encoder count, ``controller_floats[offsets[k]]`` its offset estimate (rad),
    ``controller_floats[servo_setpoint]`` the servo's last setpoint (rad), and the servo's feedback
    reads ``a0 + (plant_floats[servo_counts] - c0) * inv_k`` rad with ``servo_calibration = (a0, c0, inv_k)``.
    The arrays are views: they change as the arm steps.
    """

    plant_floats: np.ndarray
    plant_ints: np.ndarray
    controller_floats: np.ndarray
    counts: tuple[int, ...]
    currents: tuple[int, ...]
    servo_counts: int
    offsets: tuple[int, ...]
    servo_setpoint: int
    servo_calibration: tuple[float, float, float]


class ArmSim:
    """The simulated arm: cascade controllers and plant, stepped at the control rate.

    Parameters
    ----------
    params : ArmParams
        The parameter file.
    gains : Gains, optional
        Controller gains; None designs them (``tuning.design_gains(params)``, kept: ``gains_cache.kept_gains``).
    seed : int
        Seeds the current-measurement noise; everything else is deterministic.
    q0 : sequence of 4 floats, optional
        True joint angles at power-on (rad), default :data:`REST_POSE`.  The
        gears start engaged on the side gravity loads them.  Encoder counts
        are 0 at power-on, so the controllers' angles start at 0 (offset
        estimates 0) and the drives hold where they are.
    substeps : int
        Plant sub-steps per control step (see :data:`SUBSTEPS`).
    current_noise_a : float
        Standard deviation of the current measurement noise, A.
    """

    def __init__(self, params: ArmParams, gains: Gains | None = None, seed: int = 0,
                 q0: Angles | None = None, substeps: int = SUBSTEPS,
                 current_noise_a: float = CURRENT_NOISE_A) -> None:
        if gains is None:
            gains = kept_gains(params)
        if substeps < 1:
            raise SimError(f"substeps must be >= 1, got {substeps}")
        q_start = check_pose(params, q0)
        self.params = params
        self.gains = gains
        self.seed = seed
        self.substeps = int(substeps)
        self.dt = params.control.dt
        #: The physics (simulation only, like :attr:`truth`).
        self.plant = Plant(params, q_start, np.random.default_rng(seed), self.substeps, current_noise_a)
        #: The cascade controllers, run in-process (in a microcontroller on a real arm).
        self.controller = CascadeController(params, gains, servo_angle=float(q_start[3]))
        #: Ground truth (true angles, offsets, tool pose ...): simulation only, never read by
        #: code typed on :class:`~ttt_sm.arm.Arm` (docs/model.md, "Ground truth").
        self.truth = ArmTruth(params, self.plant, self.controller.act)
        self._cf, self._cm = self.controller.buffer, self.controller.modes
        self._pf, self._pi = self.plant.buffer, self.plant.ints
        self._no_rec = np.zeros((0, layout.N_REC))
        # plain-number views for the per-chart-step accessors
        self._rpc = tuple(float(d.rad_per_count) for d in params.drives)
        self._intsv, self._pgsv = self.plant.intsv, self.plant.pgsv
        self._csv = self.controller._csv
        ni = layout.N_PI  # the encoder counts' flat indices, drives 1-3 (the offsets': the controller's)
        self._i_counts = (layout.PI_COUNTS, ni + layout.PI_COUNTS, 2 * ni + layout.PI_COUNTS)
        self._i_offset = self.controller._i_offset
        # set_setpoints runs every chart step: the controller's own method, bound here, spares
        # the call a delegating method would add (the method below documents it)
        self.set_setpoints = self.controller.set_setpoints  # type: ignore[method-assign]
        self.sensors = self.plant.sensors  # type: ignore[method-assign]  # the Safety chart reads them every chart step
        self.offset_estimates = self.controller.offset_estimates  # type: ignore[method-assign]  # so does its Monitor
        # Load the compiled loop now (from numba's disk cache: ~0.3 s the first time in a
        # process), not in the first control step: zero steps change nothing.
        K.run_steps(0, self._cf, self._cm, self._pf, self._pi, self._no_rec)

    # ---- stepping -----------------------------------------------------------

    @property
    def t(self) -> float:
        """Simulated time since power-on, s."""
        return self._pgsv[layout.PGS_T]

    def set_setpoints(self, q_des: Angles, fr_sw: bool = False) -> None:
        """Set the joint setpoints: drives 1-3 in encoder coordinates (rad), q4 the servo angle.

        `fr_sw` selects the slow setpoint filters (thesis' slow moves).  The
        controller's step turns the servo angle into its PWM duty.  (Each arm
        binds :meth:`CascadeController.set_setpoints` in its place.)
        """
        self.controller.set_setpoints(q_des, fr_sw)

    def step(self, n: int = 1) -> None:
        """Advance `n` control steps: controller, then plant, in each."""
        K.run_steps(n, self._cf, self._cm, self._pf, self._pi, self._no_rec)

    def run(self, n: int, record: bool = True) -> Trace:
        """Advance `n` control steps and return their time series (empty if not `record`)."""
        rec = np.zeros((n if record else 0, layout.N_REC))
        K.run_steps(n, self._cf, self._cm, self._pf, self._pi, rec)
        return Trace(
            t=rec[:, layout.REC_T], setpoint_raw=rec[:, layout.REC_R_RAW:layout.REC_R_RAW + 4],
            setpoint_filtered=rec[:, layout.REC_R_F:layout.REC_R_F + 4],
            q_encoder=rec[:, layout.REC_Q_ENC:layout.REC_Q_ENC + 3],
            q_true=rec[:, layout.REC_Q_TRUE:layout.REC_Q_TRUE + 4],
            q_motor=rec[:, layout.REC_Q_MOTOR:layout.REC_Q_MOTOR + 3],
            current_a=rec[:, layout.REC_CURRENT:layout.REC_CURRENT + 3],
            duty=rec[:, layout.REC_DUTY:layout.REC_DUTY + 4],
            speed_ref=rec[:, layout.REC_W_REF:layout.REC_W_REF + 3],
            speed_meas=rec[:, layout.REC_W_MEAS:layout.REC_W_MEAS + 3],
        )

    def run_for(self, seconds: float, record: bool = True) -> Trace:
        """:meth:`run` for a duration, rounded to whole control steps."""
        return self.run(int(round(seconds / self.dt)), record)

    def state_arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The whole memory of both steps (controller floats and modes, plant floats and integers), live."""
        return self._cf, self._cm, self._pf, self._pi

    # ---- sensors (the Arm protocol) -----------------------------------------

    def sensors(self) -> Sensors:
        """The readings of the encoders, index switches and current sensors now.

        (Each arm binds :meth:`~ttt_sm.twin.plant.Plant.sensors` in its place, as :meth:`set_setpoints`.)
        """
        return self.plant.sensors()

    def readings_in_place(self) -> ReadingsInPlace:
        """Where :meth:`sensors`, :meth:`offset_estimates` and :attr:`servo_setpoint` read their numbers.

        For compiled code that reads them itself every chart step (the Safety stage's
        Monitor block, docs/safety.md "Cost"): the plant's and the controller's memory,
        flat, and the places in it.  An arm that is no simulation has no such memory
        (the protocol's methods are what it offers).
        """
        pf, pi, cf = self._pf.reshape(-1), self._pi.reshape(-1), self._cf.reshape(-1)
        pw, cw = layout.PLANT_WIDTH, layout.CONTROLLER_WIDTH
        a0, c0, inv_k = self.plant._fb
        return ReadingsInPlace(
            pf, pi, cf,
            counts=tuple(d * layout.N_PI + layout.PI_COUNTS for d in range(3)),
            currents=tuple((layout.PR_PS + d) * pw + layout.PS_I_MEAS for d in range(3)),
            servo_counts=layout.PR_PGS * pw + layout.PGS_FB_COUNTS,
            offsets=tuple((layout.CR_CS + d) * cw + layout.CS_OFFSET for d in range(3)),
            servo_setpoint=layout.CR_CGS * cw + layout.CGS_SV_SET,
            servo_calibration=(a0, c0, inv_k))

    def encoder_angles(self) -> tuple[float, float, float]:
        """What the controllers see: counts * rad_per_count + offset estimate (rad), as plain floats."""
        di, cs = self._intsv, self._csv
        (c1, c2, c3), (o1, o2, o3), (r1, r2, r3) = self._i_counts, self._i_offset, self._rpc
        return di[c1] * r1 + cs[o1], di[c2] * r2 + cs[o2], di[c3] * r3 + cs[o3]

    def offset_estimates(self) -> tuple[float, float, float]:
        """The controllers' encoder offsets (rad), 0 until a drive is initialised."""
        return self.controller.offset_estimates()

    @property
    def servo_setpoint(self) -> float:
        """The servo angle last commanded (rad); at power-on, where the servo stands."""
        return self.controller.servo_setpoint

    def enabled(self) -> tuple[bool, bool, bool]:
        """True per drive while its cascade controller runs."""
        return self.controller.enabled()

    @property
    def q_encoder(self) -> np.ndarray:
        """:meth:`encoder_angles` as an array (rad)."""
        return np.array(self.encoder_angles())

    @property
    def offset_estimate(self) -> np.ndarray:
        """:meth:`offset_estimates` as an array (rad)."""
        return np.array(self.offset_estimates())

    @property
    def duty(self) -> np.ndarray:
        """PWM duties the controllers apply to the three H-bridges now (-1..1)."""
        return self.controller.duty

    def max_speed(self) -> np.ndarray:
        """Speed setpoint clamps of drives 1..3 (rad/s)."""
        return self.controller.max_speed()

    # ---- controller management ------------------------------------------------

    def set_offset_estimate(self, drive: int, offset_rad: float) -> None:
        """Set a drive's encoder offset (rad) as the init charts estimate it.

        The drive's setpoints and speed-estimate state move with its angle, so
        the arm does not jump: the physical target stays where it was.
        """
        self.controller.set_offset_estimate(drive, offset_rad)

    def assume_initialised(self) -> None:
        """Give every drive its true offset: simulation only, a stand-in for the init charts.

        A real arm learns its offsets from the init charts; tests and the
        bench that start from an initialised arm use this instead.
        """
        for d, off in enumerate(self.truth.offsets):
            self.set_offset_estimate(d + 1, float(off))

    def set_gains(self, gains: Gains) -> None:
        """Run the cascades with `gains` from now on (a tuning preset switched in after the init charts)."""
        self.gains = gains
        self.controller.set_gains(gains)

    def set_enabled(self, drive: int, enabled: bool) -> None:
        """Switch a drive's controller on (holding where the drive is) or off (bridge off)."""
        mode = layout.MODE_CLOSED if enabled else layout.MODE_OFF
        self.controller.set_mode(drive, mode, hold_rad=self.encoder_angles()[drive - 1] if enabled else None)

    def set_duty(self, drive: int, duty: float) -> None:
        """Drive open loop with a fixed PWM duty (clipped to -1..1) until set_enabled."""
        self.controller.set_open_duty(drive, duty)

    def settle_unpowered(self, seconds: float) -> None:
        """Let gravity and friction act with the bridges off for `seconds`, then restore the modes.

        Drives that were under control hold where they came to rest.
        """
        modes = self._cm.copy()
        self._cm[:] = layout.MODE_OFF
        self.step(int(round(seconds / self.dt)))
        for d in range(3):
            if modes[d] == layout.MODE_CLOSED:
                self.controller.hold(d + 1, self.encoder_angles()[d])
            self._cm[d] = modes[d]


__all__ = ["ArmSim", "Trace", "Sensors", "SimError", "REST_POSE", "SUBSTEPS", "CURRENT_NOISE_A",
           "gravity_torques"]
