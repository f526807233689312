"""Drawing with the Control chart on the simulated whiteboard, and its precision.

Thesis section 3.5 compares three paths: the desired one, the one forward
kinematics gives from the encoder angles, and the true one measured by a
sensor.  Here the "sensor" is the whiteboard itself: the ink the true pen
tip leaves.  :func:`draw` commands one drawing through the Control chart
(the field, an X, an O or the sine wave of section 3.5.3) and measures it:
`rms_error_mm` / `max_error_mm` (true ink against the desired pen-down
path), `fk_vs_true_max_mm` (what clearance and model error hide from the
encoders; split into `length_error_max_mm`, the measured link lengths
against the arm as built, and `clearance_error_max_mm`, the rest),
`closure_gap_mm` for an O, the longest pen-lift/lower tail, and the
duration.  It writes the board picture (:mod:`ttt_sm.twin.board_picture`)
and the path plot (:mod:`.path_plot`: the path seen from above, the pen's
height, the error along the path and the Control chart's states over time;
figs. 3.15-3.20).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..arm import Arm
from ..params import ArmParams
from ..sched.scheduler import PathStage
from ..sched.trajectory import Waypoint, distance_to_path, sample_polyline, simplify_polyline
from ..twin.board_picture import save_board_picture
from ..twin.truth import GroundTruth
from .path_plot import PathData, save_path_plot
from .recorders import ActiveStateLog, DrawRecord, RecordStage
from .robot import Robot

KINDS = ("field", "X", "O", "sine", "lines")

#: Fig. 3.19 (section 3.5.3): two lines parallel to X, 5 cm apart by default, each this long, centred on the
#: field; drawn on millimetre paper.
LINES_SPACING_M = 0.05
LINES_LENGTH_M = 0.10


class DrawError(ValueError):
    """A drawing request that cannot be carried out (bad cell, size, speed, or a stuck chart)."""


@dataclass(frozen=True)
class DrawResult:
    """What `ttt-sm draw` reports (lengths in mm, times in s)."""

    kind: str
    row: int | None
    column: int | None
    speed_mm_s: float
    size_mm: float | None
    rms_error_mm: float
    max_error_mm: float
    fk_vs_true_max_mm: float
    closure_gap_mm: float | None
    longest_tail_mm: float
    ink_points: int
    duration_s: float
    sim_time_s: float
    wall_time_s: float
    board_png: str | None = None
    plot_png: str | None = None
    #: Of ``fk_vs_true_max_mm``, what the link lengths alone cause: FK of the encoder angles with the
    #: measured lengths against FK with the true ones (``[as_built]``), largest while the pen touches, mm.
    length_error_max_mm: float | None = None
    #: And what is left: FK with the true lengths against the true tip (clearances, deflection, pen play), mm.
    clearance_error_max_mm: float | None = None
    #: Desired against forward kinematics of the encoders (thesis section 3.5's first comparison: the
    #: controllers and inverse kinematics), largest while the pen is commanded down, in x and y, mm.
    desired_vs_fk_max_mm: float | None = None
    #: ``lines`` only (fig. 3.19): each line's angle to the X axis (deg, from a straight line fitted to its
    #: ink), the angle between them (deg) and their distance at the field's centre (mm).
    lines_angle_deg: tuple[float, float] | None = None
    lines_parallel_deg: float | None = None
    lines_spacing_mm: float | None = None


def _pen_down_runs(desired: np.ndarray, surface_z: float) -> list[np.ndarray]:
    """The desired xy path split where the pen is commanded off the board."""
    down = desired[:, 2] <= surface_z
    runs, start = [], None
    for i, d in enumerate(down):
        if d and start is None:
            start = i
        elif not d and start is not None:
            runs.append(desired[start:i, :2])
            start = None
    if start is not None:
        runs.append(desired[start:, :2])
    # one vertex per chart tick is far more than the shape needs (exact to 1 um)
    return [simplify_polyline(r) for r in runs if len(r) > 1]


def _distance_to_runs(points: np.ndarray, runs: list[np.ndarray]) -> np.ndarray:
    return np.min(np.vstack([distance_to_path(points, run) for run in runs]), axis=0)


def closure_gap_mm(board: Any, x0: float, y0: float, radius: float, tol_m: float) -> float:
    """Longest arc of the desired circle with no ink within `tol_m` of it, in mm.

    A closed O leaves none (0 mm, within the raster's resolution).
    """
    n = max(64, int(2 * math.pi * radius / 1e-4))
    a = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    ink = board.pixel_centers_m(board.ink_mask())
    if len(ink) == 0:
        return 2 * math.pi * radius * 1e3
    pts = np.column_stack([x0 + radius * np.cos(a), y0 + radius * np.sin(a)])
    near = np.zeros(n, dtype=bool)
    # only ink close to the circle matters
    d_centre = np.hypot(ink[:, 0] - x0, ink[:, 1] - y0)
    ring = ink[np.abs(d_centre - radius) <= tol_m]
    for i in range(0, n, 256):
        block = pts[i:i + 256, None, :] - ring[None, :, :]
        near[i:i + 256] = (np.hypot(block[..., 0], block[..., 1]) <= tol_m).any(axis=1) if len(ring) else False
    if near.all():
        return 0.0
    # longest circular run of uninked samples
    gaps = ~near
    doubled = np.concatenate([gaps, gaps])
    best = run = 0
    for g in doubled:
        run = run + 1 if g else 0
        best = max(best, run)
    best = min(best, n)
    return best * (2 * math.pi * radius / n) * 1e3


#: Ink farther than this from the desired pen-down path is outside the intended strokes.
TAIL_TOL_M = 0.0003


def longest_tail_mm(strokes: list[Any], runs: list[np.ndarray], tol_m: float) -> float:
    """Longest stretch of one stroke that stays farther than `tol_m` from the desired path, mm.

    The ink a pen leaves while it lands or lifts away from the desired path
    shows up here (the strokes are this drawing's own, not the whole board).
    """
    best = 0.0
    for s in strokes:
        pts = s.points
        if len(pts) < 2:
            continue
        out = _distance_to_runs(pts, runs) > tol_m
        seg = np.hypot(*np.diff(pts, axis=0).T)
        run = 0.0
        for i in range(1, len(pts)):
            run = run + seg[i - 1] if (out[i] and out[i - 1]) else 0.0
            best = max(best, run)
    return best * 1e3


def check_request(params: ArmParams, kind: str, row: int, column: int, speed: float | None,
                  size: float | None, spacing: float | None = None) -> None:
    """Reject a drawing request that cannot be drawn, naming what is wrong (before anything moves)."""
    if kind not in KINDS:
        raise DrawError(f"unknown drawing {kind!r}; choose from {', '.join(KINDS)}")
    b = params.board
    if spacing is not None:
        if kind != "lines":
            raise DrawError(f"spacing is for the two lines of fig. 3.19 (draw lines), not for {kind}")
        if not 0.002 <= spacing <= b.field_size:
            raise DrawError(f"spacing {spacing * 1000:.1f} mm is outside 2..{b.field_size * 1000:.0f} mm"
                            " (both lines on the field)")
    if not (1 <= row <= b.cells and 1 <= column <= b.cells):
        raise DrawError(f"cell ({row}, {column}) is off the {b.cells}x{b.cells} field")
    if speed is not None and not 0.001 <= speed <= 0.1:
        raise DrawError(f"speed {speed * 1000:.1f} mm/s is outside 1..100 mm/s")
    if size is not None and not 0.004 <= size <= b.cell_size:
        raise DrawError(f"size {size * 1000:.1f} mm does not fit a {b.cell_size * 1000:.0f} mm cell (4 mm at least)")


def measure(robot: Robot, rec: DrawRecord, kind: str, row: int, column: int, t0: float, strokes_before: int,
            wall0: float) -> DrawResult:
    """One drawing's precision: its record and the robot's ink since stroke ``strokes_before``.

    ``rec``: what a :class:`RecordStage` recorded while the drawing ran (from
    ``t0``, simulated s; ``wall0``, ``time.perf_counter()`` then); ``kind``,
    ``row``, ``column``: what was drawn.  The ink is the whiteboard's strokes
    of author ``"robot"`` (a person's strokes on the same board are not
    counted).  Raises :class:`DrawError` when the record commands no pen-down
    path.
    """
    params, board, c = robot.params, robot.board, robot.control
    desired = np.asarray(rec.desired)
    runs = _pen_down_runs(desired, params.board.surface_z)
    if not runs:
        raise DrawError(f"drawing {kind} commanded no pen-down path")
    strokes = [s for s in board.strokes[strokes_before:] if s.author == "robot"]
    ink = np.vstack([s.points for s in strokes]) if strokes else np.zeros((0, 2))
    err = _distance_to_runs(ink, runs) * 1e3 if len(ink) else np.array([math.inf])
    tip = np.asarray(rec.tip)
    fk_enc = np.asarray(rec.fk_encoder)[:, :2]
    touching = np.isfinite(tip[:, 0])
    fk_vs_true = np.hypot(*(fk_enc[touching] - tip[touching]).T) * 1e3 if touching.any() else np.zeros(1)
    fk_built = np.asarray(rec.fk_as_built)[:, :2]
    lengths = np.hypot(*(fk_enc[touching] - fk_built[touching]).T) * 1e3 if touching.any() else np.zeros(1)
    clearance = np.hypot(*(fk_built[touching] - tip[touching]).T) * 1e3 if touching.any() else np.zeros(1)
    gap = None
    if kind == "O":
        gap = round(closure_gap_mm(board, c.x0, c.y0, c.R, tol_m=0.0005), 3)
    tail = longest_tail_mm(strokes, runs, tol_m=TAIL_TOL_M)
    lines = _lines_geometry(ink, params.board.field_center_x, params.board.field_center_y) if kind == "lines" \
        else None
    down = desired[:, 2] <= params.board.surface_z
    desired_vs_fk = np.hypot(*(desired[down, :2] - fk_enc[down]).T) * 1e3 if down.any() else np.zeros(1)
    return DrawResult(
        kind=kind, row=row if kind in ("X", "O") else None, column=column if kind in ("X", "O") else None,
        speed_mm_s=round(c.speed * 1e3, 3), size_mm=round(c.size * 1e3, 3) if kind in ("X", "O") else None,
        rms_error_mm=round(float(np.sqrt(np.mean(err ** 2))), 4), max_error_mm=round(float(err.max()), 4),
        fk_vs_true_max_mm=round(float(fk_vs_true.max()), 4), closure_gap_mm=gap,
        longest_tail_mm=round(float(tail), 3), ink_points=int(len(ink)),
        duration_s=round(robot.t - t0, 3), sim_time_s=round(robot.t, 3),
        wall_time_s=round(time.perf_counter() - wall0, 3),
        length_error_max_mm=round(float(lengths.max()), 4), clearance_error_max_mm=round(float(clearance.max()), 4),
        desired_vs_fk_max_mm=round(float(desired_vs_fk.max()), 4), **(lines or {}),
    )


def _lines_geometry(ink: np.ndarray, cx: float, cy: float) -> dict[str, Any] | None:
    """Fig. 3.19's two lines measured on their ink: angles to X, the angle between them, their spacing.

    The ink below the field's centre line (``y < cy``) is the first line, above it the second; a
    straight line ``y = a x + b`` is fitted to each; the spacing is the distance between the two fitted
    lines at ``x = cx``, measured square to their mean direction.
    """
    parts = [ink[ink[:, 1] < cy], ink[ink[:, 1] >= cy]]
    if any(len(p) < 10 for p in parts):
        return None
    fits = [np.polyfit(p[:, 0], p[:, 1], 1) for p in parts]
    angles = [math.degrees(math.atan(a)) for a, _ in fits]
    y_at = [a * cx + b for a, b in fits]
    mean = math.radians((angles[0] + angles[1]) / 2)
    return {"lines_angle_deg": (round(angles[0], 4), round(angles[1], 4)),
            "lines_parallel_deg": round(abs(angles[1] - angles[0]), 4),
            "lines_spacing_mm": round(abs(y_at[1] - y_at[0]) * math.cos(mean) * 1e3, 4)}


def lines_path(params: ArmParams, control: Any, spacing: float, chart_dt: float) -> np.ndarray:
    """The task poses of fig. 3.19, one per chart tick, from where the Control chart holds the tool.

    Two lines parallel to X, `spacing` apart (m) on either side of the field's centre, each
    ``LINES_LENGTH_M`` long, drawn towards -X as the Control chart draws (eq. 3.36): pen-up moves at the
    chart's ``travel_speed``, the pen lowered to ``z_draw`` and lifted to ``z_up`` at ``z_speed``, the
    lines at ``speed``; back to the starting pose at the end.
    """
    c, b = control, params.board
    x_a, x_b = b.field_center_x + LINES_LENGTH_M / 2, b.field_center_x - LINES_LENGTH_M / 2
    here = Waypoint(c.X_out, c.Y_out, c.Z_out)
    pts = [here]
    for y in (b.field_center_y - spacing / 2, b.field_center_y + spacing / 2):
        pts += [Waypoint(x_a, y, c.z_up, speed=c.travel_speed), Waypoint(x_a, y, c.z_draw, speed=c.z_speed),
                Waypoint(x_b, y, c.z_draw, speed=c.speed), Waypoint(x_b, y, c.z_up, speed=c.z_speed)]
    pts.append(Waypoint(here.x, here.y, here.z, speed=c.travel_speed))
    return sample_polyline(pts, c.speed, chart_dt)


class DrawSession:
    """A robot, its whiteboard and a recorder, ready to draw on command."""

    def __init__(self, params: ArmParams, seed: int = 0, progress: Callable[[str], None] | None = None,
                 arm: Arm | None = None, truth: GroundTruth | None = None) -> None:
        self.params = params
        self.robot = Robot(params, seed=seed, arm=arm, truth=truth)
        if self.robot.truth is None:
            raise DrawError("measuring a drawing's precision needs ground truth: the simulated arm's, or an"
                            " emulator's (ttt-sm arm serve sends it; a board does not)")
        self.recorder = RecordStage(self.robot, self.robot.truth)
        self.robot.sched.joint_stages.append(self.recorder)
        #: The Control chart's active sub-state over time, for the path plot's bands.
        self.control_states = ActiveStateLog(lambda: self.robot.t).observe(self.robot.control)
        self.say = progress or (lambda _m: None)
        self._last: tuple[float, int] | None = None  # the last drawing's start time and first stroke
        self._spacing_mm = LINES_SPACING_M * 1000  # the last lines' spacing, for the picture's command line

    def run_to_wait(self, timeout_s: float) -> None:
        """Run until the Control chart waits in wait_1 (raises DrawError on timeout)."""
        r = self.robot
        c = r.control
        if not r.run_until(lambda: not c.busy, timeout_s):
            raise DrawError(f"the Control chart did not reach wait_1 within {timeout_s:.0f} s "
                            f"(active: {sorted(r.active('Control'))})")

    def start(self) -> float:
        """Initialise and wait for the first wait_1 without drawing the field: returns sim time."""
        r = self.robot
        self.say("initialising the drives (init charts)")
        if not r.run_until(lambda: r.initialised, 40.0):
            raise DrawError("the drives did not initialise within 40 s")
        self.say(f"initialised after {r.t:.1f} s; moving to the waiting pose")
        r.control.Pl_fld = True  # hold the field back: the first command decides what is drawn
        self.run_to_wait(40.0)
        return r.t

    def draw(self, kind: str, row: int = 3, column: int = 3, speed: float | None = None,
             size: float | None = None, out_dir: Path | None = None, spacing: float | None = None) -> DrawResult:
        """Draw one thing from wait_1 and measure it.

        ``lines`` (fig. 3.19) is no sub-chart of the Control chart: a path stage after it
        (:func:`lines_path`) plays the two lines while the chart waits in ``wait_1``.
        """
        check_request(self.params, kind, row, column, speed, size, spacing)
        c = self.robot.control
        if speed is not None:
            c.speed = speed
        if size is not None:
            c.size = size
        if c.busy:
            raise DrawError("the arm is busy: draw only from wait_1")
        wall0 = time.perf_counter()
        self.recorder.record = DrawRecord()
        self.recorder.on = True
        t0 = self.robot.t
        strokes_before = len(self.robot.board.strokes)
        c.row, c.column = row, column
        if kind == "lines":
            self.say(f"drawing two lines parallel to X, {(spacing or LINES_SPACING_M) * 1000:g} mm apart (fig. 3.19)")
            self._spacing_mm = (spacing or LINES_SPACING_M) * 1000
            self._draw_lines(spacing or LINES_SPACING_M)
            self.recorder.on = False
            self._last = (t0, strokes_before)
            result = self._measure(kind, row, column, t0, strokes_before, wall0)
            return self._write(result, out_dir) if out_dir is not None else result
        if kind == "field":
            c.Pl_fld = False
        elif kind == "sine":
            self.robot.post("Control", "draw_sine")
        else:
            c.symbol = 1 if kind == "X" else 0
            self.robot.post("Control", "button")
        self.say(f"drawing {kind}" + (f" in cell ({row}, {column})" if kind in ("X", "O") else ""))
        r = self.robot
        r.chart_step()
        r.chart_step()
        self.run_to_wait(300.0)
        self.recorder.on = False
        self._last = (t0, strokes_before)
        result = self._measure(kind, row, column, t0, strokes_before, wall0)
        if out_dir is not None:
            result = self._write(result, out_dir)
        return result

    def _draw_lines(self, spacing: float) -> None:
        r = self.robot
        path = PathStage(lines_path(self.params, r.control, spacing, self.params.control.chart_dt))
        r.sched.task_stages.append(path)  # after the Control chart's stage: its pose wins
        try:
            if not r.run_until(lambda: path.done or r.tripped, 120.0) or r.tripped:
                raise DrawError(f"the lines were not drawn: {r.safety.reason or 'still drawing after 120 s'}")
            r.run_for(0.5)  # the arm settles at the waiting pose
        finally:
            r.sched.task_stages.remove(path)

    def _measure(self, kind: str, row: int, column: int, t0: float, strokes_before: int,
                 wall0: float) -> DrawResult:
        return measure(self.robot, self.recorder.record, kind, row, column, t0, strokes_before, wall0)

    def _write(self, result: DrawResult, out_dir: Path) -> DrawResult:
        out_dir.mkdir(parents=True, exist_ok=True)
        name = result.kind + (f"_r{result.row}c{result.column}" if result.row else "")
        what = _what(result)
        seed = self.robot.seed
        lines = result.kind == "lines"  # fig. 3.19: on millimetre paper, the desired lines drawn over the ink
        board_png = save_board_picture(
            self.robot.board, out_dir / f"board_{name}.png", f"{what}, drawn by the robot on the simulated whiteboard",
            f"ttt-sm draw {result.kind}" + (f" --row {result.row} --column {result.column}" if result.row else "")
            + f" --speed {result.speed_mm_s:g}" + (f" --size {result.size_mm:g}" if result.size_mm else "")
            + (f" --spacing {self._spacing_mm:g}" if result.kind == "lines" else "")
            + f" --seed {seed}: the whole board as it is after this drawing",
            grid_mm=lines,
            desired=_pen_down_runs(np.asarray(self.recorder.record.desired), self.params.board.surface_z) if lines
            else ())
        t0 = self._last[0] if self._last else self.robot.t
        plot_png = save_path_plot(
            self.path_data(), out_dir / f"paths_{name}.png", f"{what}: where the pen went",
            f"{result.speed_mm_s:g} mm/s, seed {seed}, commanded at t = {t0:.2f} s of simulated time, "
            f"{result.duration_s:.1f} s to the waiting pose again; ink against the desired path: "
            f"rms {result.rms_error_mm:.3f} mm, max {result.max_error_mm:.3f} mm")
        return DrawResult(**{**asdict(result), "board_png": str(board_png), "plot_png": str(plot_png)})

    def path_data(self) -> PathData:
        """The last drawing's record as the path plot's data (see :mod:`.path_plot`).

        Take it before anything else touches the board: the ink is read from
        the board's strokes, which a sponge pass cuts.
        """
        if self._last is None:
            raise DrawError("nothing drawn yet: path_data describes the last drawing")
        t0, strokes_before = self._last
        rec = self.recorder.record
        params = self.params
        desired = np.asarray(rec.desired)
        runs = _pen_down_runs(desired, params.board.surface_z)
        strokes = [s for s in self.robot.board.strokes[strokes_before:] if s.author == "robot"]
        tip = np.asarray(rec.tip)
        enc = np.asarray(rec.fk_encoder)
        t = np.asarray(rec.t)
        return PathData(
            t=t, desired=desired, fk_encoder=enc, fk_true=np.asarray(rec.fk_true),
            strokes=[(s.points, s.times, _distance_to_runs(s.points, runs)) for s in strokes],
            runs=runs, tip_vs_encoders_m=np.hypot(*(enc[:, :2] - tip).T),
            states=self.control_states.between(t0, float(t[-1])),
            surface_z=params.board.surface_z, field_bounds=params.board.field_bounds(),
            cell_size=params.board.cell_size, cells=params.board.cells,
        )


def _what(result: DrawResult) -> str:
    if result.kind == "lines":
        return "Two lines parallel to X on millimetre paper (thesis fig. 3.19)"
    if result.kind == "field":
        return "The playing field"
    if result.kind == "sine":
        return "The sine wave of thesis section 3.5.3"
    return f"An {result.kind} in cell ({result.row}, {result.column})"
