"""The memory of the Safety stage's compiled Monitor block (``_monitor.py``), as tables.

Four flat arrays, each a :class:`~ttt_sm.twin.layout.Block` whose offsets
are computed when this module is imported (as the twin's are:
``twin/layout.py``) and become its attributes, plain ints that numba
freezes into the compiled functions:

- ``m[M_*]``: the stage's whole state, float64;
- ``OUT_*``: what :func:`~ttt_sm.app._monitor.monitor` computes, by position
  (kept in ``m[M_OUT:]``);
- ``ix[IX_*]``: where :func:`~ttt_sm.app._monitor.step` finds the Safety
  chart's data in the chart's buffer, one place per output, flag and datum
  (``IX_<NAME>`` for the datum ``name`` of :data:`NAMES`), then where it
  reads the arm (``IX_SRC + SRC_*``) and the output/previous pairs;
- ``SRC_*``: the arm's readings, in the order of ``ix[IX_SRC:]``.
"""

from __future__ import annotations

from ..twin.layout import block, export

OUT = block("OUT", "what monitor() returns, by position (m[M_OUT + OUT_*])", [
    ("ERR", "following errors (rad)", 3),
    ("SPEED", "encoder speeds (rad/s)", 3),
    ("CMD_SPEED", "commanded speeds (rad/s)", 3),
    ("CURRENT", "currents' magnitudes (A)", 3),
    ("Q", "encoder angles (rad)", 3),
    ("FAST", "at the speed clamp (1.0 or 0.0)", 3),
    ("SERVO_ERR", "the servo's model minus its feedback angle (rad)"),
    ("SERVO_Q", "the servo's feedback angle (rad)"),
    ("TOOL", "the tool's x, y, z (m) and phi (rad)", 4),
])
M = block("M", "the Monitor block's buffer m[M_*]: three numbers per drive unless said", [
    ("R", "the model of the setpoint filter: angle (encoder coordinates), rad", 3),
    ("V", "its rate, rad/s", 3),
    ("P", "where the drive can be: the filter's angle followed no faster than the speed clamp, rad", 3),
    ("DP", "how far M_P moved over the last chart step, rad", 3),
    ("FAST", "chart steps the drive still counts as at its speed clamp", 3),
    ("COUNTS", "the encoder counts of the last chart step", 3),
    ("OFFSET", "the encoder offsets the model's angles are in, rad", 3),
    ("STEP_MAX", "the speed clamp times the chart period, rad", 3),
    ("SPEED_PER_COUNT", "rad/s of one count over a chart step", 3),
    ("RPC", "rad per count", 3),
    ("ROW", "the fast setpoint filter over one chart step (a11 a12 b1 a21 a22 b2)", 6),
    ("ROW_SLOW", "the slow one (fr_sw)", 6),
    ("GEOMETRY", "L1 L2 L3 L4 l_f", 5),
    ("FAST_STEPS", "chart steps a drive counts as at its clamp after the model left it"),
    ("CHART_DT", "the chart period, s"),
    ("SV", "the model of the pen servo: where its output shaft should be, rad"),
    ("SV_RATE", "the servo's slew rate, rad/s"),
    ("SV_INV_TAU", "1 / the time constant of its position loop, 1/s"),
    ("TICK_S", "the Safety chart's tick period (its still timers count it), s"),
    ("FB_CAL", "the servo feedback's calibration a0, c0, 1/k: a0 + (counts - c0) / k rad", 3),
    ("OUT", "what monitor() (or step()) computed this chart step, OUT_* by position", OUT.size),
])
SRC = block("SRC", "where step() reads the arm, in ix[IX_SRC + SRC_*]", [
    ("COUNTS", "encoder counts (the int source)", 3),
    ("CURRENTS", "currents (the float source)", 3),
    ("SERVO_Q", "the servo feedback reading (the float source, through M_FB_CAL)"),
    ("OFFSETS", "encoder offsets (the controller's source)", 3),
    ("SERVO", "the servo's setpoint (the controller's source)"),
])

#: The Safety chart's flags :func:`~ttt_sm.app._monitor.step` writes every chart step.
FLAGS = ("initialised", "init_failed", "link_ok", "camera_ok")
#: The Safety chart's data :func:`~ttt_sm.app._monitor.step` reads and writes, by name.
NAMES = ("err_1", "err_2", "err_3", "speed_1", "speed_2", "speed_3", "cmd_speed_1", "cmd_speed_2", "cmd_speed_3",
         "current_1", "current_2", "current_3", "q_1", "q_2", "q_3", "fast_1", "fast_2", "fast_3", "servo_err",
         "max_following_error", "max_following_error_init", "max_following_error_fast", "max_current",
         "max_current_init", "max_speed", "moving_speed", "stall_ratio", "silent_s", "limit_margin",
         "q_min_1", "q_min_2", "q_min_3", "q_max_1", "q_max_2", "q_max_3",
         "still_1", "still_2", "still_3", "max_servo_error", "servo_error_s", "servo_off")
IX = block("IX", "places in the Safety chart's buffer, ix[IX_*] (int64)", [
    ("OUT", "where each of the N_OUT outputs goes (-1: wired elsewhere)", OUT.size),
    *((flag.upper(), f"the flag {flag}") for flag in FLAGS),
    *((name.upper(), f"the datum {name}") for name in NAMES),
    ("SRC", "where the arm's readings are (SRC_*)", SRC.size),
    ("PREV", "the number of (output, previous) pairs, then the pairs"),
])

CONSTANTS = export(globals(), (OUT, M, SRC, IX))
#: Where the flags start in ``ix``, and the data of :data:`NAMES`.
IX_FLAGS = CONSTANTS[f"IX_{FLAGS[0].upper()}"]
IX_NAMES = CONSTANTS[f"IX_{NAMES[0].upper()}"]


def __getattr__(name: str) -> int:
    # The constants are real attributes (put there by export above); this tells a type checker
    # that `from ._monitor_layout import M_R` is an int, and says what a misspelt name is not.
    raise AttributeError(f"module {__name__!r} has no layout constant {name!r} (app/_monitor_layout.py's tables)")
