"""The arm's parameter file: every assumed physical value in one place.

The thesis gives no dimensions or motor data, so `data/arm.toml` holds
plausible values for a desk-sized arm (docs/parameters.md says which are
assumed and why).  Two ideas, one module each, both importable from here:

- :mod:`.values`: the frozen dataclasses in SI units (:class:`ArmParams` and
  its sections) and the servo's calibration (:func:`servo_duty`,
  :func:`servo_angle`);
- :mod:`.reading`: :func:`load_params` reads the file (or another of the same
  shape) and holds every value to :data:`LIMITS`, raising
  :class:`ParameterError` that names the file, line, section and key.
"""

from __future__ import annotations

from .reading import (
    DEFAULT_PARAMS_NAME,
    LIMITS,
    MAX_FILE_BYTES,
    MAX_LENGTH_ERROR_M,
    ParameterError,
    load_params,
    parse_params,
    shown_path,
    user_cache,
)
from .values import (
    TUNING_PRESETS,
    ArmParams,
    Board,
    ControlParams,
    DriveParams,
    Geometry,
    IKParams,
    Masses,
    Pen,
    SafetyParams,
    Servo,
    Sponge,
    Tuning,
    servo_angle,
    servo_duty,
)

__all__ = [
    "DEFAULT_PARAMS_NAME", "LIMITS", "MAX_FILE_BYTES", "MAX_LENGTH_ERROR_M", "TUNING_PRESETS", "ArmParams", "Board",
    "ControlParams", "DriveParams", "Geometry", "IKParams", "Masses", "ParameterError", "Pen", "SafetyParams", "Servo",
    "Sponge", "Tuning", "load_params", "parse_params", "servo_angle", "servo_duty", "shown_path", "user_cache",
]
