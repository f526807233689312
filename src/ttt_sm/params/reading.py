"""Reading a parameter file: TOML into :class:`~.values.ArmParams`, every value checked.

The thesis gives no dimensions or motor data, so `data/arm.toml` holds
plausible values for a desk-sized arm (docs/parameters.md says which are
assumed and why).  :func:`load_params` reads that file, or another of the same
shape, into frozen dataclasses in SI units; angles given in degrees in the
file (keys with ``_deg`` in their name) are converted to radians here.
Every value is held to :data:`LIMITS` and the relations between keys are
checked; a message names the file, the line, the section and the key.
"""

from __future__ import annotations

import math
import os
import re
import reprlib
import tomllib
from dataclasses import fields
from importlib import resources
from pathlib import Path
from typing import Any

from .values import SECTIONS, TUNING_PRESETS, ArmParams, DriveParams, Geometry, Tuning

DEFAULT_PARAMS_NAME = "arm.toml"


class ParameterError(ValueError):
    """A parameter file is missing, malformed or holds an implausible value."""


def user_cache(kind: str) -> Path:
    """Where ttt_sm keeps what it derives once per machine: ``$XDG_CACHE_HOME/ttt_sm/<kind>`` (``~/.cache``)."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "ttt_sm" / kind

#: Largest parameter file read, bytes: the packaged one is about 6 kB.
MAX_FILE_BYTES = 1_000_000

#: ``control.rate_hz``: where the drives initialise from a hard stop (measured over four random power-on poses:
#: 4 of 4 at 700, 800, 1000 and 1250 Hz; 1 of 4 at 500, 1500, 2000 and 4000 Hz; docs/parameters.md, Limits).
#: Limits each value must keep, SI units (a ``_deg`` key of the file is checked in radians
#: and named in degrees).  They are sanity bounds, wide enough for any desk-sized arm and
#: narrow enough that no product or quotient of the model overflows or divides by zero;
#: docs/parameters.md lists them.  Relations between keys (a range that must not be empty,
#: cut-offs below the Nyquist frequency, the field within reach) are checked after them.
LIMITS: dict[str, tuple[float, float]] = {
    "geometry.L1": (0.01, 2.0), "geometry.L2": (0.01, 2.0), "geometry.L3": (0.01, 2.0),
    "geometry.L4": (0.005, 1.0), "geometry.l_f": (-0.5, 0.5),
    "as_built.L1": (0.01, 2.0), "as_built.L2": (0.01, 2.0), "as_built.L3": (0.01, 2.0),
    "as_built.L4": (0.005, 1.0), "as_built.l_f": (-0.5, 0.5),
    "board.surface_z": (-1.0, 1.0), "board.field_center_x": (-2.0, 2.0), "board.field_center_y": (-2.0, 2.0),
    "board.field_size": (0.02, 1.0), "board.cells": (5, 5), "board.width": (0.02, 4.0),
    "board.depth": (0.02, 4.0), "board.zone_clearance": (0.0, 0.5), "board.zone_depth": (0.0, 1.0),
    "pen.spring_travel": (0.0005, 0.05), "pen.holder_clearance": (0.0, 0.005),
    "sponge.offset": (0.001, 0.2), "sponge.width": (0.001, 0.2), "sponge.compliance": (0.0, 0.05),
    "servo.min_rad": (-2 * math.pi, 2 * math.pi), "servo.max_rad": (-2 * math.pi, 2 * math.pi),
    "servo.pulse_min_s": (1e-5, 0.1), "servo.pulse_max_s": (1e-5, 0.1), "servo.period_s": (1e-3, 0.1),
    "servo.rate_rad_s": (math.radians(1.0), math.radians(6000.0)), "servo.time_constant_s": (1e-4, 1.0),
    "servo.clearance_rad": (0.0, math.radians(5.0)),
    "servo.feedback_bits": (8, 16), "servo.feedback_cal_a_rad": (-2 * math.pi, 2 * math.pi),
    "servo.feedback_cal_b_rad": (-2 * math.pi, 2 * math.pi), "servo.feedback_cal_a_counts": (0.0, 65535.0),
    "servo.feedback_cal_b_counts": (0.0, 65535.0), "servo.feedback_noise_lsb": (0.0, 100.0),
    "servo.feedback_tau_s": (0.0, 1.0),
    "masses.link2_kg": (0.0, 50.0), "masses.link2_com": (0.0, 2.0), "masses.link3_kg": (0.0, 50.0),
    "masses.link3_com": (0.0, 2.0), "masses.tool_kg": (0.0, 50.0),
    "control.rate_hz": (700.0, 1250.0), "control.chart_divider": (1, 100),
    "control.setpoint_cutoff_hz": (0.01, 10_000.0), "control.setpoint_cutoff_slow_hz": (0.01, 10_000.0),
    "control.speed_filter_hz": (0.1, 10_000.0), "control.inner_crossover_hz": (0.1, 10_000.0),
    "control.outer_crossover_hz": (0.01, 10_000.0), "control.gear_play_compensation": (0.0, 1.0),
    "ik.damping": (1e-9, 10.0), "ik.tolerance": (1e-12, 1e-2), "ik.max_iterations": (1, 10_000),
    "safety.max_following_error_rad": (1e-4, 1.0), "safety.max_following_error_init_rad": (1e-4, 1.0),
    "safety.max_following_error_fast_rad": (1e-4, 1.0),
    "safety.max_current_a": (0.01, 1000.0), "safety.max_current_init_a": (0.01, 1000.0),
    "safety.max_speed_rad_s": (0.1, 1000.0), "safety.moving_speed_rad_s": (1e-4, 10.0),
    "safety.stall_ratio": (0.0, 1.0),
    "safety.silent_s": (1e-3, 1.0), "safety.limit_margin_rad": (0.0, 0.5), "safety.lift_height_m": (0.0, 0.1),
    "safety.lift_speed_m_s": (0.001, 1.0), "safety.max_servo_error_rad": (1e-4, 1.0),
    "safety.servo_error_s": (1e-3, 1.0),
    "drive.supply_v": (0.1, 100.0), "drive.resistance_ohm": (1e-3, 1e3), "drive.inductance_h": (1e-7, 1.0),
    "drive.torque_constant": (1e-4, 10.0), "drive.rotor_inertia": (1e-9, 1.0), "drive.motor_viscous": (0.0, 1.0),
    "drive.motor_coulomb": (0.0, 10.0), "drive.gear_ratio": (1.0, 10_000.0), "drive.load_inertia": (1e-6, 100.0),
    "drive.load_viscous": (0.0, 100.0), "drive.gear_clearance": (0.0, 0.1), "drive.gear_stiffness": (1.0, 1e8),
    "drive.gear_damping": (0.0, 1e5), "drive.encoder_counts": (1, 10_000_000),
    "drive.limit_min_rad": (-2 * math.pi, 2 * math.pi), "drive.limit_max_rad": (-2 * math.pi, 2 * math.pi),
    "drive.index_rad": (-2 * math.pi, 2 * math.pi), "drive.park_rad": (-2 * math.pi, 2 * math.pi),
}


class _Where:
    """Names a parameter file in messages, with the line of a key when the text is known."""

    def __init__(self, file: str, text: str | None = None) -> None:
        self.file = file
        self._text = text
        self._lines: dict[tuple[str, str], int] | None = None

    def __str__(self) -> str:
        return self.file

    def at(self, table: str, key: str | None = None) -> str:
        """``FILE:LINE`` of ``key`` in ``[table]`` (or of the table's header), else ``FILE``."""
        if self._lines is None:
            self._lines = _key_lines(self._text or "")
        line = self._lines.get((table, key or ""))
        return f"{self.file}:{line}" if line else self.file


def _key_lines(text: str) -> dict[tuple[str, str], int]:
    """Where each ``key =`` of each ``[table]`` is (1-based lines); ``(table, "")`` is the header."""
    lines: dict[tuple[str, str], int] = {}
    table = ""
    for n, raw in enumerate(text.splitlines(), start=1):
        s = raw.strip()
        if s.startswith("[") and not s.startswith("[[") and "]" in s:
            table = s[1:s.index("]")].replace(" ", "").replace('"', "")
            lines.setdefault((table, ""), n)
            continue
        m = re.match(r"([A-Za-z0-9_-]+)\s*=", s)
        if m:
            lines.setdefault((table, m.group(1)), n)
    return lines


def _file_key(key: str, raw: dict[str, Any]) -> str:
    """The key as the file spells it: ``min_deg`` for the ``min_rad`` it was converted to."""
    deg = key.replace("_rad", "_deg")
    return deg if key.endswith("_rad") and deg in raw else key


def _section(raw: dict[str, Any], cls: type, name: str, where: _Where) -> Any:
    """Build dataclass `cls` from table `raw`, converting `_deg` keys and checking the limits."""
    if not isinstance(raw, dict):
        raise ParameterError(f"{where.at(name)}: [{name}] must be a table")
    values: dict[str, Any] = {}
    wanted = {f.name: f for f in fields(cls) if f.name != "source"}
    given = dict(raw)
    for key, value in list(given.items()):
        if "_deg" in key and key.replace("_deg", "_rad") in wanted:
            if not _is_number(value):
                raise ParameterError(f"{where.at(name, key)}: [{name}] {key} must be a finite number,"
                                     f" got {_short(value)}")
            values[key.replace("_deg", "_rad")] = math.radians(value)
            del given[key]
    for key, value in given.items():
        if key not in wanted:
            raise ParameterError(f"{where.at(name, key)}: [{name}] has an unknown key {_short(key)}")
        values[key] = value
    missing = sorted(set(wanted) - set(values))
    if missing:
        raise ParameterError(f"{where.at(name)}: [{name}] is missing {', '.join(missing)}")
    family = name.split(".")[0]
    for key, value in values.items():
        spelled = _file_key(key, raw)
        kind = wanted[key].type
        if isinstance(value, bool) or not isinstance(value, (int, float)) or (
                kind in ("int", int) and not isinstance(value, int)):
            noun = "an integer" if kind in ("int", int) else "a number"
            raise ParameterError(f"{where.at(name, spelled)}: [{name}] {spelled} must be {noun}, got {_short(value)}")
        if not _is_number(value):
            raise ParameterError(f"{where.at(name, spelled)}: [{name}] {spelled} must be finite, got {_short(value)}")
        if kind not in ("int", int):
            values[key] = float(value)
        lo, hi = LIMITS[f"{family}.{key}"]
        if not lo <= values[key] <= hi:
            deg = spelled.endswith("_deg")
            shown, lo_s, hi_s = (math.degrees(v) if deg else v for v in (values[key], lo, hi))
            what = "must be positive, got" if values[key] <= 0 < lo else "="
            raise ParameterError(f"{where.at(name, spelled)}: [{name}] {spelled} {what} {shown:g}: outside"
                                 f" {lo_s:g}..{hi_s:g}{' deg' if deg else ''} (docs/parameters.md, Limits)")
    return cls(**values)


def _is_number(value: Any) -> bool:
    """A finite int or float (not a bool); a huge integer is not (it overflows a float)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def _short(value: Any, limit: int = 60) -> str:
    """``repr(value)``, cut to ``limit`` characters: a message never formats a huge value whole."""
    text = reprlib.repr(value) if isinstance(value, (dict, list, tuple)) else repr(value)
    return text if len(text) <= limit else text[:limit] + f"...({len(text)} characters)"


#: How far a true length may lie from the measured one, m: more is a typo, not a measurement error.
MAX_LENGTH_ERROR_M = 0.005


def _check(params: ArmParams, where: _Where) -> None:
    """Relations between keys that no single limit expresses; the message names the key and the fix."""
    if params.as_built is not None:
        for f in fields(Geometry):
            true, measured = getattr(params.as_built, f.name), getattr(params.geometry, f.name)
            if abs(true - measured) > MAX_LENGTH_ERROR_M:
                raise ParameterError(f"{where.at('as_built', f.name)}: [as_built] {f.name} = {true:g} m lies"
                                     f" {abs(true - measured) * 1000:.1f} mm from [geometry] {f.name} = {measured:g} m:"
                                     f" a measurement misses by less than {MAX_LENGTH_ERROR_M * 1000:g} mm")
    s, c, b = params.servo, params.control, params.board
    if not s.min_rad < s.max_rad:
        raise ParameterError(f"{where.at('servo', 'max_deg')}: [servo] min_deg must be below max_deg")
    if not s.pulse_min_s < s.pulse_max_s <= s.period_s:
        raise ParameterError(f"{where.at('servo', 'pulse_max_s')}: [servo] needs pulse_min_s < pulse_max_s <="
                             f" period_s, got {s.pulse_min_s:g} s, {s.pulse_max_s:g} s, {s.period_s:g} s")
    full = 2 ** s.feedback_bits - 1
    for key in ("feedback_cal_a_counts", "feedback_cal_b_counts"):
        if getattr(s, key) > full:
            raise ParameterError(f"{where.at('servo', key)}: [servo] {key} = {getattr(s, key):g} is beyond a"
                                 f" {s.feedback_bits}-bit ADC's {full} counts")
    if s.feedback_cal_a_rad == s.feedback_cal_b_rad or s.feedback_cal_a_counts == s.feedback_cal_b_counts:
        raise ParameterError(f"{where.at('servo', 'feedback_cal_b_deg')}: [servo] the feedback's two calibration"
                             f" points need different angles and different counts")
    nyquist = c.rate_hz / 2
    for key in ("setpoint_cutoff_hz", "setpoint_cutoff_slow_hz", "speed_filter_hz", "inner_crossover_hz",
                "outer_crossover_hz"):
        if getattr(c, key) >= nyquist:
            raise ParameterError(f"{where.at('control', key)}: [control] {key} = {getattr(c, key):g} Hz must lie"
                                 f" below the Nyquist frequency of rate_hz = {c.rate_hz:g} Hz ({nyquist:g} Hz):"
                                 f" lower it or raise rate_hz")
    if not c.outer_crossover_hz < c.inner_crossover_hz:
        raise ParameterError(f"{where.at('control', 'outer_crossover_hz')}: [control] outer_crossover_hz"
                             f" ({c.outer_crossover_hz:g} Hz) must lie below inner_crossover_hz"
                             f" ({c.inner_crossover_hz:g} Hz): the position loop wraps the speed loop")
    if not c.setpoint_cutoff_slow_hz <= c.setpoint_cutoff_hz:
        raise ParameterError(f"{where.at('control', 'setpoint_cutoff_slow_hz')}: [control]"
                             f" setpoint_cutoff_slow_hz must not exceed setpoint_cutoff_hz")
    for key in ("width", "depth"):
        if getattr(b, key) < b.field_size:
            raise ParameterError(f"{where.at('board', key)}: [board] {key} ({getattr(b, key):g} m) is smaller"
                                 f" than the field it holds (field_size = {b.field_size:g} m)")
    for i, d in enumerate(params.drives, start=1):
        table = f"drive.{i}"
        if not d.limit_min_rad < d.limit_max_rad:
            raise ParameterError(f"{where.at(table, 'limit_max_deg')}: [{table}] limit_min_deg must be below"
                                 f" limit_max_deg")
        for key in ("index_rad", "park_rad"):
            if not d.limit_min_rad < getattr(d, key) < d.limit_max_rad:
                spelled = key[:-4] + "_deg"
                raise ParameterError(f"{where.at(table, spelled)}: [{table}] {spelled} must lie between the"
                                     f" limits")


def _tuning(raw: Any, where: _Where) -> Tuning:
    """The optional ``[tuning]`` table: ``preset``, one of :data:`TUNING_PRESETS` (default "ours")."""
    if not isinstance(raw, dict):
        raise ParameterError(f"{where.at('tuning')}: [tuning] must be a table")
    unknown = sorted(set(raw) - {"preset"})
    if unknown:
        raise ParameterError(f"{where.at('tuning', str(unknown[0]))}: [tuning] has an unknown key {_short(unknown[0])}")
    preset = raw.get("preset", "ours")
    if preset not in TUNING_PRESETS:
        raise ParameterError(f"{where.at('tuning', 'preset')}: [tuning] preset must be one of"
                             f" {', '.join(TUNING_PRESETS)}, got {_short(preset)}")
    return Tuning(preset=preset)


def parse_params(data: dict[str, Any], where: str, text: str | None = None) -> ArmParams:
    """Build :class:`ArmParams` from a parsed TOML document; `where` names it in errors.

    With the document's `text`, messages also name the line of the key.
    """
    at = _Where(where, text)
    unknown = sorted(set(data) - set(SECTIONS) - {"drive", "tuning", "as_built"})
    if unknown:
        raise ParameterError(f"{where}: unknown section(s) {', '.join(str(u)[:30] for u in unknown[:5])}")
    built: dict[str, Any] = {}
    for name, cls in SECTIONS.items():
        if name not in data:
            raise ParameterError(f"{where}: missing section [{name}]")
        built[name] = _section(data[name], cls, name, at)
    drives_raw = data.get("drive")
    if not isinstance(drives_raw, dict) or sorted(drives_raw) != ["1", "2", "3"]:
        raise ParameterError(f"{where}: needs exactly the tables [drive.1], [drive.2], [drive.3]")
    drives = tuple(_section(drives_raw[k], DriveParams, f"drive.{k}", at) for k in ("1", "2", "3"))
    as_built = _section(data["as_built"], Geometry, "as_built", at) if "as_built" in data else None
    params = ArmParams(drives=drives, tuning=_tuning(data.get("tuning", {}), at), as_built=as_built, source=where,
                       **built)  # type: ignore[arg-type]
    _check(params, at)
    return params


def load_params(path: str | Path | None = None) -> ArmParams:
    """Read a parameter file (default: the packaged `data/arm.toml`).

    Raises
    ------
    ParameterError
        The file is missing, larger than :data:`MAX_FILE_BYTES`, not UTF-8,
        not TOML, or a value is missing, outside its limits or leaves the
        field out of reach; the message names the file, the line where it
        can, the section and the key.
    """
    if path is None:
        text = resources.files("ttt_sm.data").joinpath(DEFAULT_PARAMS_NAME).read_text(encoding="utf-8")
        where = f"ttt_sm/data/{DEFAULT_PARAMS_NAME}"
    else:
        where = shown_path(path)
        text = _read_text(Path(path), where)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{where}: not valid TOML ({exc})") from None
    except RecursionError:
        raise ParameterError(f"{where}: not valid TOML (arrays or tables nested too deeply)") from None
    return parse_params(data, where, text)


def shown_path(path: str | Path) -> str:
    """A file name for a message: as it is, or quoted when it holds line breaks or other control characters."""
    name = str(path)
    return name if name.isprintable() else repr(name)


def _read_text(path: Path, where: str) -> str:
    """The file as UTF-8 text, read no further than :data:`MAX_FILE_BYTES` (a device or pipe may never end)."""
    try:
        with path.open("rb") as f:
            raw = f.read(MAX_FILE_BYTES + 1)
    except (OSError, ValueError) as exc:  # ValueError: a NUL character in the name
        raise ParameterError(f"{where}: cannot read parameter file ({getattr(exc, 'strerror', None) or exc})") from None
    if len(raw) > MAX_FILE_BYTES:
        raise ParameterError(f"{where}: more than {MAX_FILE_BYTES} bytes: not a parameter file"
                             f" (the packaged one has about 6 kB)")
    try:
        return raw.decode("utf-8-sig")  # a byte-order mark first (Windows editors write one) is not TOML: left out
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        column = exc.start - (raw.rfind(b"\n", 0, exc.start) + 1) + 1
        raise ParameterError(f"{where}:{line}: not UTF-8 text (byte 0x{raw[exc.start]:02x} at column {column});"
                             f" save the file as UTF-8") from None
