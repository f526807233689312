"""Whether an arm can work its field: the reach check made when a parameter file is used.

A parameter file whose board lies out of reach loads as numbers (the
parameter file is the foundation and knows no kinematics), but nothing drawn
with it would reach the board: ``ttt-sm draw X`` used to finish with no ink
and an infinite error.  :func:`load_arm` is :func:`~ttt_sm.params.load_params`
plus this check, what every ``ttt-sm`` command loads with; the robot checks
it too when it is built (:class:`~ttt_sm.app.robot.Robot`).  The check is
the one ``tests/twin/test_kinematics.py`` proves with margins for the
packaged file, by the closed-form inverse kinematics; docs/parameters.md,
"Limits checked at load", says what it covers.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path

from ..params import ArmParams, Board, Geometry, ParameterError, load_params
from .kinematics import UnreachableTargetError, ik_closed_form

#: Heights above the working height at which the whole field must be reachable, m: the
#: strokes themselves, the pen riding between them, and the moves onto and off the board.
REACH_LIFTS_M = (0.0, 0.025, 0.05)
#: Points per side of the grid over the field that the reach check solves for (15 mm apart
#: on the default 15 cm field); the field's corners and its point nearest the base are among them.
REACH_GRID = 11


def reach_problem(params: ArmParams) -> str | None:
    """Why the arm cannot work the whole field, or None.

    Every point of the field (an 11 x 11 grid, its corners and its point
    nearest the base axis), from the working height up to 5 cm above it, must
    be reachable elbow up within the joint limits, with the pen vertical
    (phi = 0) and with the sponge facing the board (phi = 90 deg, the sponge
    ``offset`` above the surface).  docs/parameters.md says why.
    """
    return _reach_problem(params.geometry, params.board, params.sponge.offset, params.joint_min, params.joint_max)


_LIMIT_KEYS = ("[drive.1] limit_{}_deg", "[drive.2] limit_{}_deg", "[drive.3] limit_{}_deg", "[servo] {}_deg")


@functools.lru_cache(maxsize=32)
def _reach_problem(geometry: Geometry, board: Board, sponge_offset: float,
                   q_min: tuple[float, ...], q_max: tuple[float, ...]) -> str | None:
    x0, x1, y0, y1 = board.field_bounds()
    # Cell (1, 1) lies at +x, far from the base (+y); rows grow towards the base, columns towards -x.
    points = [(x1, y1, "the field's corner at cell (1, 1)"), (x0, y1, "the field's corner at cell (1, 5)"),
              (x1, y0, "the field's corner at cell (5, 1)"), (x0, y0, "the field's corner at cell (5, 5)"),
              (min(max(-geometry.l_f, x0), x1), min(max(0.0, y0), y1), "the field's point nearest the base")]
    steps = [k / (REACH_GRID - 1) for k in range(REACH_GRID)]
    points += [(x0 + (x1 - x0) * u, y0 + (y1 - y0) * v, "the field's point") for u in steps for v in steps]
    tools = ((0.0, board.surface_z, "with the pen vertical (phi = 0)"),
             (math.pi / 2, board.surface_z + sponge_offset, "with the sponge down (phi = 90 deg)"))
    for phi, z0, tool in tools:
        for lift in REACH_LIFTS_M:
            z = z0 + lift
            for x, y, name in points:
                place = f"{name} (x = {x:.3f} m, y = {y:.3f} m, z = {z:.3f} m) is out of reach {tool}"
                try:
                    q = ik_closed_form((x, y, z, phi), geometry)
                except UnreachableTargetError as exc:
                    return (f"{place}: {exc.residual * 1000:.0f} mm beyond what links L2 and L3 reach; move the"
                            f" field ([board] field_center_x, field_center_y) or change [geometry]")
                for j in range(4):
                    if not q_min[j] <= q[j] <= q_max[j]:
                        side, limit = ("min", q_min[j]) if q[j] < q_min[j] else ("max", q_max[j])
                        return (f"{place}: it needs q{j + 1} = {math.degrees(q[j]):.1f} deg,"
                                f" {math.degrees(abs(q[j] - limit)):.1f} deg beyond {_LIMIT_KEYS[j].format(side)}"
                                f" = {math.degrees(limit):.1f}; move the field or widen the limit")
    return None


def check_reach(params: ArmParams) -> None:
    """Raise :class:`~ttt_sm.params.ParameterError` naming the file if the arm cannot work its field."""
    problem = reach_problem(params)
    if problem:
        raise ParameterError(f"{params.source}: {problem}")


#: The slowest joint speed the drive-initialisation charts tell from a stall, rad/s: DriveInit1's
#: ``still_speed`` (a test holds the two equal; charts and twin import nothing of each other).
INIT_STILL_SPEED_RAD_S = 0.25
#: Encoder counts the joint must turn per chart tick at that speed, at least: the charts compare each tick's
#: encoder step with ``still_speed * tick``, and a step is known to within one count, so one count must be at
#: most a quarter of the threshold.  Below it a drive under way shows ticks of no count, read as a stall: a
#: gear ratio of 1 (0.16 counts) or a control rate of 20 kHz (1.2 counts) never initialised.
INIT_COUNTS_PER_TICK = 4.0
#: The largest product of the gear spring's natural frequency and the plant's sub-step (rad): the
#: semi-implicit sub-step of the twin (docs/model.md) is stable below 2 and loses little amplitude below 0.5.
PLANT_OMEGA_H = 0.5


def drive_problem(params: ArmParams) -> str | None:
    """Why a drive's encoder, gear and the control rate cannot work together, or None (docs/parameters.md).

    - The initialisation charts must see a drive turning at
      :data:`INIT_STILL_SPEED_RAD_S` as at least :data:`INIT_COUNTS_PER_TICK`
      encoder counts per chart tick: ``0.25 rad/s * chart_dt * encoder_counts
      * gear_ratio / 2 pi``.
    - The twin's gear spring must be resolved by its sub-step ``h = dt /
      SUBSTEPS``: ``omega * h <= 0.5`` with ``omega**2 = gear_stiffness * (1 /
      load_inertia + 1 / (gear_ratio**2 * rotor_inertia))``.
    """
    from .plant import SUBSTEPS

    c = params.control
    h = c.dt / SUBSTEPS
    for i, d in enumerate(params.drives, start=1):
        where = f"[drive.{i}]"
        counts = INIT_STILL_SPEED_RAD_S * c.chart_dt / d.rad_per_count
        if counts < INIT_COUNTS_PER_TICK:
            need = d.gear_ratio * INIT_COUNTS_PER_TICK / counts  # counts grow with the gear ratio
            return (f"{where} gear_ratio = {d.gear_ratio:g}: the encoder shows {counts:.2g} counts per chart tick at"
                    f" {INIT_STILL_SPEED_RAD_S:g} rad/s, the initialisation charts need >= {INIT_COUNTS_PER_TICK:g}"
                    f" to tell a turning drive from a stalled one: gear_ratio >= {need:.3g} with encoder_counts ="
                    f" {d.encoder_counts} and a chart tick of {c.chart_dt * 1000:g} ms ([control] rate_hz /"
                    f" chart_divider) (docs/parameters.md, The drives and the control rate)")
        omega = math.sqrt(d.gear_stiffness * (1 / d.load_inertia + 1 / (d.gear_ratio**2 * d.rotor_inertia)))
        if omega * h > PLANT_OMEGA_H:
            lowest = (PLANT_OMEGA_H / h) ** 2 / d.gear_stiffness - 1 / d.load_inertia
            need_text = (f"gear_ratio >= {math.sqrt(1 / (d.rotor_inertia * lowest)):.3g}" if lowest > 0 else
                         "a softer gear_stiffness or a higher [control] rate_hz")
            return (f"{where} gear_ratio = {d.gear_ratio:g}: the gear spring's natural frequency"
                    f" ({omega / (2 * math.pi):.4g} Hz) is too fast for the twin's step of {h * 1e6:g} us"
                    f" (omega * h = {omega * h:.2g} > {PLANT_OMEGA_H:g}): {need_text} with gear_stiffness ="
                    f" {d.gear_stiffness:g} and rotor_inertia = {d.rotor_inertia:g}"
                    " (docs/parameters.md, The drives and the control rate)")
    return None


def check_drives(params: ArmParams) -> None:
    """Raise :class:`~ttt_sm.params.ParameterError` naming the file if :func:`drive_problem` finds one."""
    problem = drive_problem(params)
    if problem:
        raise ParameterError(f"{params.source}: {problem}")


def load_arm(path: str | Path | None = None) -> ArmParams:
    """:func:`~ttt_sm.params.load_params` (default: the packaged file), then :func:`check_drives` and
    :func:`check_reach`."""
    params = load_params(path)
    check_drives(params)
    check_reach(params)
    return params
