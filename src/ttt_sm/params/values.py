"""The arm's parameters as values: frozen dataclasses in SI units, and the servo's calibration.

What the twin, the controllers and the kinematics assume about the arm
(docs/parameters.md says which values are assumed and why); :mod:`.reading`
builds them from a parameter file.  :func:`servo_duty` and :func:`servo_angle`
are the one definition of the pen servo's calibration (thesis §3.3), compiled
as they are by the twin's steps (``twin/_cascade.py``, ``twin/_plant.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Geometry:
    """Link lengths of the RRRR arm (eqs. 3.17-3.21), metres.

    ``[geometry]`` holds the lengths as measured (with a steel rule), which
    the controller's inverse and forward kinematics use; ``[as_built]`` the
    arm's true lengths, which only the simulated plant knows
    (:attr:`ArmParams.true_geometry`; docs/parameters.md).
    """

    L1: float
    L2: float
    L3: float
    L4: float
    l_f: float


@dataclass(frozen=True)
class Board:
    """The horizontal whiteboard and the 5x5 playing field on it, metres."""

    surface_z: float
    field_center_x: float
    field_center_y: float
    field_size: float
    cells: int
    width: float
    depth: float
    zone_clearance: float
    zone_depth: float

    @property
    def cell_size(self) -> float:
        """Side of one cell (L in eqs. 3.37-3.47), metres."""
        return self.field_size / self.cells

    def field_bounds(self) -> tuple[float, float, float, float]:
        """(x_min, x_max, y_min, y_max) of the playing field."""
        h = self.field_size / 2
        return (self.field_center_x - h, self.field_center_x + h,
                self.field_center_y - h, self.field_center_y + h)

    def board_bounds(self) -> tuple[float, float, float, float]:
        """(x_min, x_max, y_min, y_max) of the whole whiteboard."""
        return (self.field_center_x - self.width / 2, self.field_center_x + self.width / 2,
                self.field_center_y - self.depth / 2, self.field_center_y + self.depth / 2)

    def in_zone(self, x: float, y: float, z: float) -> bool:
        """True where a point is inside the board zone: the board, its stand, and the air just above."""
        x0, x1, y0, y1 = self.board_bounds()
        return (x0 <= x <= x1 and y0 <= y <= y1
                and self.surface_z - self.zone_depth <= z <= self.surface_z + self.zone_clearance)


@dataclass(frozen=True)
class Pen:
    """Spring-loaded pen holder (section 3.3.1), metres."""

    spring_travel: float
    holder_clearance: float


@dataclass(frozen=True)
class Sponge:
    """Sponge on the lateral surface of the end effector, metres."""

    offset: float
    width: float
    compliance: float


def servo_duty(angle_rad: float, min_rad: float, max_rad: float, pulse_min_s: float, pulse_max_s: float,
               period_s: float) -> float:
    """PWM duty (0..1) that commands `angle_rad`: the pulse width linear in the angle, clipped to the range.

    The one definition of the servo's calibration: :meth:`Servo.duty_for_angle` calls it, and the
    controller's compiled step (``twin/_cascade.py``) compiles this very function (plain arithmetic on
    floats, so numba can).  The firmware's C port (``firmware/src/cascade.c``) is held to it bit for bit
    by ``tests/hardware/test_cascade_c.py``.
    """
    a = min_rad if angle_rad < min_rad else (max_rad if angle_rad > max_rad else angle_rad)
    frac = (a - min_rad) / (max_rad - min_rad)
    return (pulse_min_s + frac * (pulse_max_s - pulse_min_s)) / period_s


def servo_angle(duty: float, min_rad: float, max_rad: float, pulse_min_s: float, pulse_max_s: float,
                period_s: float) -> float:
    """Angle (rad) a PWM duty commands, the inverse of :func:`servo_duty`; pulses outside the range clip.

    :meth:`Servo.angle_for_duty` calls it; the plant's compiled step (``twin/_plant.py``) compiles it.
    """
    frac = (duty * period_s - pulse_min_s) / (pulse_max_s - pulse_min_s)
    frac = 0.0 if frac < 0.0 else (1.0 if frac > 1.0 else frac)
    return min_rad + frac * (max_rad - min_rad)


@dataclass(frozen=True)
class Servo:
    """Hobby servo on joint 4: pulse width to angle, with a rate limit."""

    min_rad: float
    max_rad: float
    pulse_min_s: float
    pulse_max_s: float
    period_s: float
    rate_rad_s: float
    time_constant_s: float
    clearance_rad: float
    feedback_bits: int
    feedback_cal_a_rad: float
    feedback_cal_a_counts: float
    feedback_cal_b_rad: float
    feedback_cal_b_counts: float
    feedback_noise_lsb: float
    feedback_tau_s: float

    @property
    def feedback_counts_per_rad(self) -> float:
        """ADC counts per radian of the feedback potentiometer (the two-point calibration's slope)."""
        return (self.feedback_cal_b_counts - self.feedback_cal_a_counts) / (self.feedback_cal_b_rad
                                                                            - self.feedback_cal_a_rad)

    def feedback_angle(self, counts: float) -> float:
        """The servo angle (rad) an ADC reading of the feedback wire means, by the two-point calibration."""
        return self.feedback_cal_a_rad + (counts - self.feedback_cal_a_counts) / self.feedback_counts_per_rad

    def feedback_counts(self, angle_rad: float) -> float:
        """The ADC reading (counts, not rounded) of the feedback wire at `angle_rad`, by the calibration."""
        return self.feedback_cal_a_counts + (angle_rad - self.feedback_cal_a_rad) * self.feedback_counts_per_rad

    @property
    def calibration(self) -> tuple[float, float, float, float, float]:
        """``(min_rad, max_rad, pulse_min_s, pulse_max_s, period_s)``: :func:`servo_duty`'s arguments after angle."""
        return self.min_rad, self.max_rad, self.pulse_min_s, self.pulse_max_s, self.period_s

    def duty_for_angle(self, angle_rad: float) -> float:
        """PWM duty (0..1) that commands `angle_rad` (clipped to the range): :func:`servo_duty`."""
        return servo_duty(angle_rad, *self.calibration)

    def angle_for_duty(self, duty: float) -> float:
        """Angle (rad) a PWM duty commands; pulses outside the range clip: :func:`servo_angle`."""
        return servo_angle(duty, *self.calibration)


@dataclass(frozen=True)
class Masses:
    """Masses and centres of mass that load the pitch joints with gravity."""

    link2_kg: float
    link2_com: float
    link3_kg: float
    link3_com: float
    tool_kg: float


@dataclass(frozen=True)
class ControlParams:
    """Rates, filters and loop-shaping targets of the cascade controllers."""

    rate_hz: float
    chart_divider: int
    setpoint_cutoff_hz: float
    setpoint_cutoff_slow_hz: float
    speed_filter_hz: float
    inner_crossover_hz: float
    outer_crossover_hz: float
    gear_play_compensation: float

    @property
    def dt(self) -> float:
        """Control step, seconds."""
        return 1.0 / self.rate_hz

    @property
    def chart_dt(self) -> float:
        """Chart step, seconds (the thesis' pulse generator, section 3.1.2)."""
        return self.chart_divider / self.rate_hz


#: The cascade gains ``[tuning] preset`` may name (docs/tuning.md, "The thesis' tuning beside ours").
TUNING_PRESETS = ("ours", "thesis")


@dataclass(frozen=True)
class Tuning:
    """Which gains the cascades run: ``"ours"`` (designed, docs/tuning.md) or ``"thesis"`` (hand-set as the thesis')."""

    preset: str = "ours"


@dataclass(frozen=True)
class IKParams:
    """Levenberg-Marquardt damped least squares settings (eq. 3.35)."""

    damping: float
    tolerance: float
    max_iterations: int


@dataclass(frozen=True)
class SafetyParams:
    """Thresholds of the Safety chart (docs/safety.md, "Thresholds")."""

    max_following_error_rad: float
    max_following_error_init_rad: float
    max_following_error_fast_rad: float
    max_current_a: float
    max_current_init_a: float
    max_speed_rad_s: float
    moving_speed_rad_s: float
    stall_ratio: float
    silent_s: float
    limit_margin_rad: float
    lift_height_m: float
    lift_speed_m_s: float
    max_servo_error_rad: float
    servo_error_s: float


@dataclass(frozen=True)
class DriveParams:
    """One DC drive: motor, gear, load, encoder, switches and hard stops."""

    supply_v: float
    resistance_ohm: float
    inductance_h: float
    torque_constant: float
    rotor_inertia: float
    motor_viscous: float
    motor_coulomb: float
    gear_ratio: float
    load_inertia: float
    load_viscous: float
    gear_clearance: float
    gear_stiffness: float
    gear_damping: float
    encoder_counts: int
    limit_min_rad: float
    limit_max_rad: float
    index_rad: float
    park_rad: float

    @property
    def rad_per_count(self) -> float:
        """Joint angle of one encoder count (the encoder is on the motor)."""
        return 2 * math.pi / (self.encoder_counts * self.gear_ratio)

    @property
    def inertia_at_motor(self) -> float:
        """Rotor plus load inertia reflected to the motor shaft, kg m^2."""
        return self.rotor_inertia + self.load_inertia / self.gear_ratio**2


@dataclass(frozen=True)
class ArmParams:
    """Everything the twin, the controllers and the kinematics assume."""

    geometry: Geometry
    board: Board
    pen: Pen
    sponge: Sponge
    servo: Servo
    masses: Masses
    control: ControlParams
    ik: IKParams
    safety: SafetyParams
    drives: tuple[DriveParams, DriveParams, DriveParams]
    tuning: Tuning = Tuning()
    #: The arm's true link lengths (``[as_built]``), None: as measured (``geometry``).  Simulation only:
    #: the plant, the true tool and the whiteboard use them; kinematics on the controller's side never does.
    as_built: Geometry | None = None
    source: str = "<built-in>"

    @property
    def true_geometry(self) -> Geometry:
        """The lengths the simulated arm really has: ``[as_built]``, else the nominal ``[geometry]``."""
        return self.as_built if self.as_built is not None else self.geometry

    @property
    def joint_min(self) -> tuple[float, float, float, float]:
        """Lower joint limits q1..q4 (rad)."""
        d = self.drives
        return (d[0].limit_min_rad, d[1].limit_min_rad, d[2].limit_min_rad, self.servo.min_rad)

    @property
    def joint_max(self) -> tuple[float, float, float, float]:
        """Upper joint limits q1..q4 (rad)."""
        d = self.drives
        return (d[0].limit_max_rad, d[1].limit_max_rad, d[2].limit_max_rad, self.servo.max_rad)


#: The file's tables of one dataclass each, by name (``[drive.N]``, ``[tuning]`` and ``[as_built]`` aside).
SECTIONS: dict[str, type] = {"geometry": Geometry, "board": Board, "pen": Pen, "sponge": Sponge, "servo": Servo,
                             "masses": Masses, "control": ControlParams, "ik": IKParams, "safety": SafetyParams}
