"""The Operational page (``/operate``, thesis section 3.7, fig. 3.36) over the session's robot.

A view of the same :class:`~.session.Session` as the chart cockpit and the
Tic-tac-toe page.  Its buttons are commands of :mod:`.protocol`
(``operate_trigger``, ``operate_stop``; Run_simulation is the session's
``run``), handled here in the simulation thread between two control steps;
what it shows comes in each frame: the ``operate`` part (:meth:`Operate.view`,
sent when it changed) and the ``plot`` part, the graphs' new samples.

Trigger sets the Control chart's inputs through the debugger (recorded, so a
replay draws the same) and posts the chart's ``button`` (an X or an O in the
middle cell of the field) or ``draw_sine`` event; or, for "Staircase", plays
the precision experiment of section 3.5 from the waiting pose and back
(:class:`ttt_sm.app.precision.Staircase`, recorded too), along the axis and
with the steps chosen, and measures it as ``ttt-sm precision staircase`` does:

* Magnitude, 0 to 10 cm (the thesis' range): the X's side, the O's diameter,
  the sine wave's peak-to-peak height (``Control.size``;
  ``Control.sine_amplitude`` is half of it);
* Speed, 0 to 5 (0 the slowest, 5 the fastest): :func:`speed_mm_s`, a straight
  line from 5 mm/s to 30 mm/s; 3 is the project's usual 20 mm/s.

What the page says and allows is read from what the Control chart declares
(its ``busy``, ``ready`` outputs and ``finish`` input), never from its state
names: the four messages of section 3.7, and Trigger only while the arm waits
at its waiting pose (``wait_1``) with nothing of its own to do.

The graphs' data are sampled in simulated time, :data:`SAMPLE_PERIOD_S`
apart, by a joint stage (:class:`OperateStage`) that runs after inverse
kinematics in every chart step: the desired tool position (the pose
commanded: the chart's ``X_out``, ``Y_out``, ``Z_out``, or a staircase's while
it plays) against forward kinematics of the encoders
(its ``X_now``, ``Y_now``, ``Z_now``), the current of drives 1-3 and each
drive's following error (its joint setpoint minus its encoder angle).  So
the graphs get the same points per simulated second at any pacing, x0.1 or as
fast as it goes.  After each drawing the stage measures its precision as
``ttt-sm draw`` does (:func:`ttt_sm.app.drawing.measure`: the ink on the
simulated whiteboard against the desired path, and an O's closure gap).
"""

from __future__ import annotations

import math
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..app.drawing import DrawError, measure
from ..app.precision import AXES, STEP_KINDS, PrecisionError, Staircase, staircase_playing
from ..app.recorders import DrawRecord, RecordStage
from ..app.robot import Robot
from ..debug.debugger import Debugger
from ..sched.scheduler import Signals

#: The thesis' messages of the manipulator's status (section 3.7, Operational GUI), in its words.
MSG_INITIALISING = "The manipulator is being initialized"
MSG_READY = "The manipulator is ready for your command"
MSG_DRAWING = "The manipulator is drawing"
MSG_TURNING_OFF = "The manipulator is being turned off"
#: Ours, not the thesis': the precision experiment of section 3.5 runs.
MSG_STAIRCASE = "The manipulator follows the staircase"
STATUS_MESSAGES = (MSG_INITIALISING, MSG_READY, MSG_DRAWING, MSG_TURNING_OFF, MSG_STAIRCASE)

#: The Symbol list, as the page offers it: what Trigger draws (or, for "staircase", plays).
SYMBOLS = ("X", "O", "sine", "staircase")
#: The staircase's axes and steps (:mod:`ttt_sm.app.precision`).
STAIRCASE_AXES, STAIRCASE_STEPS = AXES, STEP_KINDS
#: The Magnitude slider's range, cm (section 3.7).
MAGNITUDE_CM = (0.0, 10.0)
#: The Speed slider's range (0 the slowest, 5 the fastest).
SPEED_RANGE = (0.0, 5.0)
#: Speed 0 and speed 5 in mm/s; between them a straight line.
SPEED_MM_S = (5.0, 30.0)
#: The smallest X or O the chart draws as a symbol, cm (below it an X or O is a dot).
MIN_SYMBOL_CM = 0.4
#: The row and column of the field's middle cell: an X and an O are centred there, any size.
MIDDLE_CELL = 3

#: The graphs' samples are this far apart in simulated time (25 a simulated second).
SAMPLE_PERIOD_S = 0.04
#: Samples a page gets when it joins (the last 30 simulated seconds).
HISTORY = 750
#: Samples waiting for the next frame at most (a stalled page loses the oldest).
PENDING = 5000
#: Plot-latency samples kept for the p95 figure.
LATENCY_SAMPLES = 2000

#: The columns of every sample, in order (mm, A, degrees).
COLUMNS = ("t_s", "x_desired_mm", "x_fk_mm", "y_desired_mm", "y_fk_mm", "z_desired_mm", "z_fk_mm",
           "current_1_a", "current_2_a", "current_3_a",
           "following_error_1_deg", "following_error_2_deg", "following_error_3_deg")


def speed_mm_s(speed: float) -> float:
    """The drawing speed, mm/s, of the Speed slider's value (0 .. 5): 5 mm/s at 0, 30 mm/s at 5."""
    lo, hi = SPEED_MM_S
    return lo + (hi - lo) * speed / SPEED_RANGE[1]


def _mm(value: float) -> float | None:
    return round(value * 1e3, 3) if math.isfinite(value) else None


@dataclass
class Drawing:
    """A drawing Trigger started: what, how big, how fast, and where the robot's ink began."""

    symbol: str
    magnitude_cm: float
    speed: float
    t0: float
    wall0: float
    strokes_before: int
    started: bool = False  # the Control chart has left wait_1 for it


class OperateStage:
    """Joint stage: samples the graphs' signals and closes a drawing Trigger started.

    Runs at every chart step, after inverse kinematics (the joint setpoints
    of this step are known), for as long as its robot lives (a replay builds
    another robot, and :class:`Operate` another stage).
    """

    def __init__(self, robot: Robot, on_done: Callable[[Drawing | None, dict[str, Any]], None]) -> None:
        self.robot = robot
        self.control = robot.control
        self.arm = robot.arm
        self.recorder = RecordStage(robot, robot.truth) if robot.truth is not None else None
        self.every = max(1, round(SAMPLE_PERIOD_S / robot.params.control.chart_dt))
        self.ticks = 0
        #: The Control chart has waited at its waiting pose once: the arm is initialised and placed.
        self.waited = False
        self.drawing: Drawing | None = None
        #: The staircase Trigger started, until it is measured.
        self.staircase: tuple[Staircase, float] | None = None
        self.pending: deque[tuple[float, list[float | None]]] = deque(maxlen=PENDING)
        self.history: deque[list[float | None]] = deque(maxlen=HISTORY)
        self.on_done = on_done

    def tick(self, signals: Signals) -> None:
        c = self.robot.control
        if c is not self.control:  # the Safety chart's reset: a new Control chart, initialising again
            self.control, self.waited, self.drawing = c, False, None
        if not c.busy:
            self.waited = True
        if self.recorder is not None:
            self.recorder.tick(signals)
        drawing = self.drawing
        if drawing is not None:
            if c.busy:
                drawing.started = True
            elif drawing.started:
                self.drawing = None
                self.on_done(drawing, self._precision(drawing))
        if self.staircase is not None and not self.staircase[0].playing:
            staircase, t0 = self.staircase
            self.staircase = None
            self.on_done(None, self._staircase_result(staircase, t0))
        self.ticks += 1
        if self.ticks % self.every == 0:
            self._sample(signals)

    def _sample(self, signals: Signals) -> None:
        c = self.control
        q_set = signals.q_set
        q_enc = self.arm.encoder_angles()
        current = self.arm.sensors().current_a
        task = signals.task  # the pose commanded: the Control chart's, or a staircase's while one plays
        row: list[float | None] = [
            round(self.robot.t, 4), _mm(float(task[0])), _mm(c.X_now), _mm(float(task[1])), _mm(c.Y_now),
            _mm(float(task[2])), _mm(c.Z_now),
            *(round(float(current[i]), 4) for i in range(3)),
            *(round(math.degrees(float(q_set[i]) - q_enc[i]), 4) if math.isfinite(float(q_set[i])) else None
              for i in range(3)),
        ]
        self.pending.append((time.perf_counter(), row))
        self.history.append(row)

    def start(self, drawing: Drawing) -> None:
        """Trigger was pressed: record the paths until the chart waits again."""
        self.drawing = drawing
        if self.recorder is not None:
            self.recorder.record = DrawRecord()
            self.recorder.on = True

    def _staircase_result(self, staircase: Staircase, t0: float) -> dict[str, Any]:
        """The staircase's three comparisons, as ``ttt-sm precision staircase`` reports them."""
        spec = staircase.spec
        done: dict[str, Any] = {"symbol": "staircase", "axis": spec.axis, "steps": spec.steps,
                                "step_mm": spec.step_m * 1e3, "stairs": spec.count, "tuning": staircase.tuning,
                                "duration_s": round(self.robot.t - t0, 3)}
        try:
            result = staircase.result()
        except PrecisionError as exc:
            return {**done, "error": str(exc)}
        return {**done, "thesis_figure": result.thesis_figure, "summary": result.summary,
                "clearance_bound_mm": result.clearance_bound_mm, "reading": result.reading}

    def _precision(self, drawing: Drawing) -> dict[str, Any]:
        done: dict[str, Any] = {"symbol": drawing.symbol, "magnitude_cm": drawing.magnitude_cm,
                                "speed": drawing.speed, "speed_mm_s": round(speed_mm_s(drawing.speed), 3),
                                "duration_s": round(self.robot.t - drawing.t0, 3)}
        if self.recorder is None:
            return {**done, "error": "the precision is measured on the simulated whiteboard; this arm has none"}
        self.recorder.on = False
        kind = drawing.symbol
        try:
            result = measure(self.robot, self.recorder.record, kind, MIDDLE_CELL, MIDDLE_CELL, drawing.t0,
                             drawing.strokes_before, drawing.wall0)
        except DrawError as exc:
            return {**done, "error": str(exc)}
        finally:
            self.recorder.record = DrawRecord()
        return {**done, "rms_error_mm": result.rms_error_mm, "max_error_mm": result.max_error_mm,
                "closure_gap_mm": result.closure_gap_mm, "fk_vs_true_max_mm": result.fk_vs_true_max_mm,
                "ink_points": result.ink_points}


class Operate:
    """The Operational page's side of a session: its stage on the robot, its view, its commands.

    Every method runs in the session's simulation thread.
    """

    def __init__(self, debugger: Debugger) -> None:
        self.debugger = debugger
        self.stage: OperateStage | None = None
        self.results: list[dict[str, Any]] = []
        self._stamps: dict[int, float] = {}
        self._latency_s: deque[float] = deque(maxlen=LATENCY_SAMPLES)
        self._lock = threading.Lock()  # the stamps and the latency: acks come from the server's thread
        self._attach()

    def _attach(self) -> OperateStage:
        robot = self.debugger.robot
        if self.stage is None or self.stage.robot is not robot:
            self.stage = OperateStage(robot, self._done)
            robot.sched.joint_stages.append(self.stage)
            self.results = []
        return self.stage

    def _done(self, drawing: Drawing | None, result: dict[str, Any]) -> None:
        self.results.append(result)
        del self.results[:-20]

    # -- what the page shows ------------------------------------------------------------------

    def view(self) -> dict[str, Any]:
        """The frame's ``operate`` part: status message, Trigger and why not, the last precision."""
        stage = self._attach()
        robot = self.debugger.robot
        c = robot.control
        if c.finish or c.at_start:
            status = MSG_TURNING_OFF
        elif staircase_playing(robot) is not None:
            status = MSG_STAIRCASE
        elif not c.busy:
            status = MSG_READY
        elif stage.waited or stage.drawing is not None:
            status = MSG_DRAWING
        else:
            status = MSG_INITIALISING
        why = self._why_not(stage)
        drawing = stage.drawing
        return {
            "status": status, "trigger": why == "", "why": why,
            "drawing": None if drawing is None else {"symbol": drawing.symbol, "magnitude_cm": drawing.magnitude_cm,
                                                     "speed": drawing.speed},
            "precision": self.results[-1] if self.results else None,
            "drawings": len(self.results),
            "turning_off": status == MSG_TURNING_OFF,
            "speed_mm_s_range": list(SPEED_MM_S),
        }

    def _why_not(self, stage: OperateStage) -> str:
        """Why Trigger is not taken now ("" when it is)."""
        robot = self.debugger.robot
        c = robot.control
        if self.debugger.game is not None:
            return ("this session plays a game: the Game chart commands the arm (start `ttt-sm gui` without"
                    " --game to draw shapes here)")
        if robot.tripped:
            return f"the Safety chart holds the arm ({robot.safety.reason}): Reset it once the cause is removed"
        if c.finish or c.at_start:
            return "the manipulator is being turned off"
        if stage.drawing is not None:
            return "the manipulator is drawing: Trigger again when it waits at its waiting pose"
        if staircase_playing(robot) is not None:
            return "the manipulator follows the staircase: Trigger again when it is back at its waiting pose"
        if c.busy:
            if not stage.waited:
                return ("the manipulator is not at its waiting pose yet: Run_simulation, then wait for it to be"
                        " initialized and placed beside the board")
            return "the manipulator is busy (drawing, erasing): wait until it waits at its waiting pose"
        if not c.ready:
            return "the manipulator draws the playing field first"
        return ""

    # -- the graphs' stream --------------------------------------------------------------------

    def plot_history(self) -> dict[str, Any]:
        """A joining page's graphs: the columns and the last :data:`HISTORY` samples."""
        stage = self._attach()
        return {"columns": list(COLUMNS), "period_s": SAMPLE_PERIOD_S, "rows": list(stage.history), "reset": True}

    def plot_since(self, seq: int) -> dict[str, Any] | None:
        """The samples taken since the last frame (for frame ``seq``), or None when there are none."""
        stage = self._attach()
        if not stage.pending:
            return None
        with self._lock:
            self._stamps[seq] = stage.pending[0][0]
            if len(self._stamps) > 256:
                for old in sorted(self._stamps)[:-256]:
                    del self._stamps[old]
        rows = [row for _, row in stage.pending]
        stage.pending.clear()
        return {"rows": rows}

    def ack(self, seq: int, received: float) -> None:
        """A page drew frame ``seq``: its oldest sample's age is a plot-latency sample (any thread)."""
        with self._lock:
            stamp = self._stamps.pop(seq, None)
            if stamp is not None:
                self._latency_s.append(received - stamp)

    def latency(self) -> list[float]:
        """Plot-latency samples so far, s (any thread)."""
        with self._lock:
            return list(self._latency_s)

    # -- the page's commands ------------------------------------------------------------------

    def trigger(self, symbol: str, magnitude_cm: float, speed: float, axis: str = "z",
                steps: str = "big") -> dict[str, Any]:
        """Trigger: draw ``symbol`` at ``magnitude_cm`` and ``speed`` (checked by :mod:`.protocol`), or play
        the staircase along ``axis`` with ``steps`` stairs (``symbol`` "staircase"; magnitude and speed unused)."""
        stage = self._attach()
        why = self._why_not(stage)
        if why:
            raise ValueError(f"Trigger is not taken now: {why}")
        if symbol == "staircase":
            return self._staircase(stage, axis, steps)
        if symbol != "sine" and magnitude_cm < MIN_SYMBOL_CM:
            raise ValueError(f"an {symbol} of {magnitude_cm:g} cm is a dot: choose a Magnitude of"
                             f" {MIN_SYMBOL_CM:g} cm or more")
        dbg = self.debugger
        robot = dbg.robot
        size_m = magnitude_cm / 100.0
        dbg.set_input("Control", "speed", speed_mm_s(speed) / 1e3)
        if symbol == "sine":
            dbg.set_input("Control", "sine_amplitude", size_m / 2)
        else:
            dbg.set_input("Control", "size", size_m)
            dbg.set_input("Control", "row", MIDDLE_CELL)
            dbg.set_input("Control", "column", MIDDLE_CELL)
            dbg.set_input("Control", "symbol", 1 if symbol == "X" else 0)
        stage.start(Drawing(symbol, magnitude_cm, speed, robot.t, time.perf_counter(), len(robot.board.strokes)))
        dbg.post("Control", "draw_sine" if symbol == "sine" else "button")
        what = {"X": "an X", "O": "an O", "sine": "a sine wave"}[symbol]
        measure_word = {"X": "side", "O": "diameter", "sine": "peak to peak"}[symbol]
        return {"text": f"Trigger: {what}, {magnitude_cm:g} cm {measure_word}, speed {speed:g}"
                        f" ({speed_mm_s(speed):g} mm/s)"}

    def _staircase(self, stage: OperateStage, axis: str, steps: str) -> dict[str, Any]:
        robot = self.debugger.robot
        t0 = robot.t
        staircase = self.debugger.staircase(axis, steps)
        stage.staircase = (staircase, t0)
        spec = staircase.spec
        return {"text": f"Trigger: the staircase of section 3.5 along {axis.upper()}, {spec.count} {steps} stairs of"
                        f" {spec.step_m * 1e3:g} mm held {spec.hold_s:g} s each, from the waiting pose and back"
                        f" ({staircase.chart_ticks * robot.params.control.chart_dt:.1f} s of simulated time)"}

    def stop(self) -> dict[str, Any]:
        """Stop_simulation: the Control chart's ``finish``; the arm returns to its start pose."""
        dbg = self.debugger
        if dbg.game is not None:
            raise ValueError("this session plays a game: stop it with the Tic-tac-toe page's Stop")
        if not dbg.robot.initialised:
            raise ValueError("the manipulator has not been started: nothing to turn off (Run_simulation first)")
        if dbg.robot.control.finish:
            raise ValueError("the manipulator is being turned off already")
        if staircase_playing(dbg.robot) is not None:
            raise ValueError("the manipulator follows the staircase: Stop_simulation once it is back at its"
                             " waiting pose")
        dbg.set_input("Control", "finish", True)
        return {"text": "Stop_simulation: the manipulator returns to its start pose, then stops"}
