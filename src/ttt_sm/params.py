"""The arm's parameter file: every assumed physical value in one place.

The thesis gives no dimensions or motor data, so `data/arm.toml` holds
plausible values for a desk-sized arm (docs/parameters.md says which are
assumed and why).  :func:`load_params` reads that file, or another of the same
shape, into frozen dataclasses in SI units; angles given in degrees in the
file (keys with ``_deg`` in their name) are converted to radians here.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, fields
from importlib import resources
from pathlib import Path
from typing import Any

DEFAULT_PARAMS_NAME = "arm.toml"


class ParameterError(ValueError):
    """A parameter file is missing, malformed or holds an implausible value."""


@dataclass(frozen=True)
class Geometry:
    """Link lengths of the RRRR arm (eqs. 3.17-3.21), metres."""

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

    def duty_for_angle(self, angle_rad: float) -> float:
        """PWM duty (0..1) that commands `angle_rad` (clipped to the range)."""
        a = min(max(angle_rad, self.min_rad), self.max_rad)
        frac = (a - self.min_rad) / (self.max_rad - self.min_rad)
        return (self.pulse_min_s + frac * (self.pulse_max_s - self.pulse_min_s)) / self.period_s

    def angle_for_duty(self, duty: float) -> float:
        """Angle (rad) a PWM duty commands; pulses outside the range clip."""
        pulse = duty * self.period_s
        frac = (pulse - self.pulse_min_s) / (self.pulse_max_s - self.pulse_min_s)
        frac = min(max(frac, 0.0), 1.0)
        return self.min_rad + frac * (self.max_rad - self.min_rad)


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


@dataclass(frozen=True)
class IKParams:
    """Levenberg-Marquardt damped least squares settings (eq. 3.35)."""

    damping: float
    tolerance: float
    max_iterations: int


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
    drives: tuple[DriveParams, DriveParams, DriveParams]
    source: str = "<built-in>"

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


def _section(raw: dict[str, Any], cls: type, name: str, where: str) -> Any:
    """Build dataclass `cls` from table `raw`, converting `_deg` keys."""
    if not isinstance(raw, dict):
        raise ParameterError(f"{where}: [{name}] must be a table")
    values: dict[str, Any] = {}
    wanted = {f.name: f for f in fields(cls) if f.name != "source"}
    given = dict(raw)
    for key, value in list(given.items()):
        if "_deg" in key and key.replace("_deg", "_rad") in wanted:
            if not isinstance(value, (int, float)) or isinstance(value, bool):
                raise ParameterError(f"{where}: [{name}] {key} must be a number, got {value!r}")
            values[key.replace("_deg", "_rad")] = math.radians(value)
            del given[key]
    for key, value in given.items():
        if key not in wanted:
            raise ParameterError(f"{where}: [{name}] has an unknown key {key!r}")
        values[key] = value
    missing = sorted(set(wanted) - set(values))
    if missing:
        raise ParameterError(f"{where}: [{name}] is missing {', '.join(missing)}")
    for key, value in values.items():
        kind = wanted[key].type
        if kind in ("int", int):
            if not isinstance(value, int) or isinstance(value, bool):
                raise ParameterError(f"{where}: [{name}] {key} must be an integer, got {value!r}")
        elif isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ParameterError(f"{where}: [{name}] {key} must be a number, got {value!r}")
        elif not math.isfinite(value):
            raise ParameterError(f"{where}: [{name}] {key} must be finite, got {value!r}")
        else:
            values[key] = float(value)
    return cls(**values)


def _check(params: ArmParams, where: str) -> None:
    """Reject physically meaningless values with a message naming the key."""
    positive = {
        "geometry": ("L1", "L2", "L3", "L4"),
        "pen": ("spring_travel",),
        "servo": ("rate_rad_s", "time_constant_s", "period_s"),
        "control": ("rate_hz", "setpoint_cutoff_hz", "setpoint_cutoff_slow_hz",
                    "speed_filter_hz", "inner_crossover_hz", "outer_crossover_hz"),
        "ik": ("damping", "tolerance"),
    }
    for section, keys in positive.items():
        obj = getattr(params, section)
        for key in keys:
            if getattr(obj, key) <= 0:
                raise ParameterError(f"{where}: [{section}] {key} must be positive")
    if params.control.chart_divider < 1 or params.ik.max_iterations < 1:
        raise ParameterError(f"{where}: [control] chart_divider and [ik] max_iterations must be >= 1")
    if params.servo.min_rad >= params.servo.max_rad:
        raise ParameterError(f"{where}: [servo] min_deg must be below max_deg")
    for i, d in enumerate(params.drives, start=1):
        for key in ("supply_v", "resistance_ohm", "inductance_h", "torque_constant", "rotor_inertia",
                    "gear_ratio", "load_inertia", "gear_stiffness", "encoder_counts"):
            if getattr(d, key) <= 0:
                raise ParameterError(f"{where}: [drive.{i}] {key} must be positive")
        for key in ("motor_viscous", "motor_coulomb", "load_viscous", "gear_clearance", "gear_damping"):
            if getattr(d, key) < 0:
                raise ParameterError(f"{where}: [drive.{i}] {key} must not be negative")
        if not d.limit_min_rad < d.limit_max_rad:
            raise ParameterError(f"{where}: [drive.{i}] limit_min_deg must be below limit_max_deg")
        for key in ("index_rad", "park_rad"):
            if not d.limit_min_rad < getattr(d, key) < d.limit_max_rad:
                raise ParameterError(
                    f"{where}: [drive.{i}] {key[:-4]}_deg must lie between the limits")


def parse_params(data: dict[str, Any], where: str) -> ArmParams:
    """Build :class:`ArmParams` from a parsed TOML document; `where` names it in errors."""
    sections = {"geometry": Geometry, "board": Board, "pen": Pen, "sponge": Sponge,
                "servo": Servo, "masses": Masses, "control": ControlParams, "ik": IKParams}
    unknown = sorted(set(data) - set(sections) - {"drive"})
    if unknown:
        raise ParameterError(f"{where}: unknown section(s) {', '.join(unknown)}")
    built: dict[str, Any] = {}
    for name, cls in sections.items():
        if name not in data:
            raise ParameterError(f"{where}: missing section [{name}]")
        built[name] = _section(data[name], cls, name, where)
    drives_raw = data.get("drive")
    if not isinstance(drives_raw, dict) or sorted(drives_raw) != ["1", "2", "3"]:
        raise ParameterError(f"{where}: needs exactly the tables [drive.1], [drive.2], [drive.3]")
    drives = tuple(_section(drives_raw[k], DriveParams, f"drive.{k}", where) for k in ("1", "2", "3"))
    params = ArmParams(drives=drives, source=where, **built)  # type: ignore[arg-type]
    _check(params, where)
    return params


def load_params(path: str | Path | None = None) -> ArmParams:
    """Read a parameter file (default: the packaged `data/arm.toml`).

    Raises
    ------
    ParameterError
        The file is missing, not TOML, or a value is missing or implausible;
        the message names the file, the section and the key.
    """
    if path is None:
        text = resources.files("ttt_sm.data").joinpath(DEFAULT_PARAMS_NAME).read_text()
        where = f"ttt_sm/data/{DEFAULT_PARAMS_NAME}"
    else:
        p = Path(path)
        where = str(p)
        try:
            text = p.read_text()
        except OSError as exc:
            raise ParameterError(f"{where}: cannot read parameter file ({exc.strerror})") from exc
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{where}: not valid TOML ({exc})") from exc
    return parse_params(data, where)
