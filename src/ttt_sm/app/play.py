"""The main job: the whole arm at work on the simulated whiteboard.

For now (the game itself comes with the game issue): the drives initialise
with their charts, the Control chart moves above the board, draws the
playing field, an X and an O, erases the board, and finishes back at its
start pose.  Every drawing is measured as in thesis section 3.5, and the
board is saved as a picture (:mod:`ttt_sm.twin.board_picture`) before and after erasing.

Given a :class:`~ttt_sm.runtime.recordfile.RecordFile` (``ttt-sm demo`` writes
``--out``/demo.jsonl), :func:`run_play` writes what happens as it happens:
every chart transition, each step done (a line with ``event``), and a last
line that says how the demo ended; a demo that is interrupted or fails saves
the board as it is (``board_stopped.png``) and names it in that line.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict
from pathlib import Path
from typing import Any

from ..arm import Arm
from ..params import ArmParams
from ..runtime.listeners import Trace
from ..runtime.recordfile import RecordFile, ending_of
from ..twin.board_picture import save_board_picture
from ..twin.truth import GroundTruth
from .drawing import DrawError, DrawSession

#: What the demo draws, in order: (kind, row, column).
DEMO_DRAWINGS = (("field", 3, 3), ("X", 2, 2), ("O", 3, 3))


def _what(kind: str, row: int, column: int) -> str:
    return "the field" if kind == "field" else f"an {kind} in cell ({row}, {column})"


def run_play(params: ArmParams, seed: int = 0, out_dir: Path = Path("out/play"),
             progress: Callable[[str], None] | None = None, arm: Arm | None = None,
             truth: GroundTruth | None = None, record: RecordFile | None = None) -> dict[str, Any]:
    """Initialise, draw the field, an X and an O, erase, finish; return what happened.

    `arm` and `truth`: another arm than the twin (``--arm serial:PORT``) and the ground truth it offers.
    ``record``: written as the demo goes (transitions and steps), ended with how it ended.
    """
    say = progress or (lambda _m: None)
    if record is not None:
        record.add({"event": "demo", "seed": seed, "drawings": [list(d) for d in DEMO_DRAWINGS]})
    session = DrawSession(params, seed=seed, progress=say, arm=arm, truth=truth)
    if record is None:
        return _demo(session, seed, out_dir, say, lambda _event, **_data: None)
    Trace(sink=record, keep=False).observe(*session.robot.charts.values())
    robot = session.robot

    def note(event: str, **data: Any) -> None:
        record.add({"event": event, "t": round(robot.t, 4), **data})

    try:
        result = _demo(session, seed, out_dir, say, note)
    except BaseException as exc:  # the record says where it stopped, with the board as it is
        how, data = ending_of(exc)
        try:
            if record.failed is not None:  # the disk refused the record: no picture either, that error stands
                raise record.failed
            picture = str(save_board_picture(robot.board, out_dir / "board_stopped.png",
                                             f"The whiteboard when the demo stopped ({how})",
                                             f"ttt-sm demo, seed {seed}, t = {robot.t:.1f} s"))
        except Exception as picture_exc:  # the record's last line matters more than the picture
            picture = f"not saved: {picture_exc}"
        record.end(how, **data, t=round(robot.t, 4), tick=robot.chart_ticks,
                   control=sorted(robot.active("Control")), pictures={"board": picture})
        raise
    record.end("finished", t=round(robot.t, 4), tick=robot.chart_ticks, erased=result["erased"])
    return result


def _demo(session: DrawSession, seed: int, out_dir: Path, say: Callable[[str], None],
          note: Callable[..., None]) -> dict[str, Any]:
    robot = session.robot
    wall0 = time.perf_counter()
    t_ready = session.start()
    note("initialised")
    out_dir.mkdir(parents=True, exist_ok=True)
    drawings = []
    for kind, row, column in DEMO_DRAWINGS:
        d = session.draw(kind, row, column)
        drawings.append(d)
        note("drawn", kind=kind, row=row, column=column, rms_error_mm=d.rms_error_mm, max_error_mm=d.max_error_mm)
        say(f"  {d.kind}: rms {d.rms_error_mm:.3f} mm, max {d.max_error_mm:.3f} mm, {d.duration_s:.1f} s"
            + (f", closes within {d.closure_gap_mm:.2f} mm" if d.kind == "O" else ""))
    before = save_board_picture(robot.board, out_dir / "board_drawn.png",
                                "The whiteboard after " + ", ".join(_what(*d) for d in DEMO_DRAWINGS),
                                f"ttt-sm demo, seed {seed}: what the true pen tip inked; next, the sponge erases it")
    ink_drawn = robot.board.ink_area_mm2()
    say(f"board saved: {before}")
    note("board_saved", picture=str(before), ink_mm2=round(ink_drawn, 1))

    say("erasing")
    robot.control_stage.erase_requested = True
    c = robot.control
    if not robot.run_until(lambda: c.erasing, 30.0):
        raise DrawError("the Control chart did not start erasing")
    if not robot.run_until(lambda: not c.erasing, 300.0):
        raise DrawError("erasing did not finish within 300 s")
    ink_left = robot.board.ink_area_mm2()
    note("erased", ink_left_mm2=round(ink_left, 3))
    after = save_board_picture(robot.board, out_dir / "board_erased.png", "The whiteboard after erasing",
                               f"ttt-sm demo, seed {seed}: {ink_drawn:.0f} mm² of ink before, "
                               f"{ink_left:.1f} mm² left after the sponge's passes")
    say(f"erased: {ink_drawn:.0f} mm2 of ink before, {ink_left:.1f} mm2 after")

    say("finishing: back to the start pose")
    c.finish = True
    if not robot.run_until(lambda: c.at_start, 120.0):
        raise DrawError("finishing did not end within 120 s")
    wall = time.perf_counter() - wall0
    say(f"finished after {robot.t:.1f} s simulated in {wall:.1f} s ({robot.t / wall:.0f}x real time)")
    return {
        "seed": seed,
        "ready_time_s": round(t_ready, 3),
        "drawings": [asdict(d) for d in drawings],
        "ink_drawn_mm2": round(ink_drawn, 1),
        "ink_after_erase_mm2": round(ink_left, 3),
        "erased": ink_left == 0.0,
        "pen_overpress": robot.board.contact.pen_overpress_count,
        "ik_failures": robot.sched.ik_failures,
        "limit_clamps": robot.sched.limit_clamps,
        "ignored_buttons": robot.control.ignored_buttons,
        "sim_time_s": round(robot.t, 3),
        "wall_time_s": round(wall, 3),
        "realtime_factor": round(robot.t / wall, 1),
        "board_png": str(before),
        "board_erased_png": str(after),
    }


def game_motion(params: ArmParams, seed: int = 0, symbols: int = 12) -> dict[str, float]:
    """The motion of a whole game on virtual time: the field, `symbols` symbols, erasing.

    What `bench` reports as `game_motion_realtime_factor` (no recording, no plots).
    """
    from .robot import Robot

    robot = Robot(params, seed=seed)
    c = robot.control
    wall0 = time.perf_counter()

    if not robot.run_until(lambda: c.ready, 200.0):
        raise DrawError("the field was not drawn within 200 s")
    cells = [(r, col) for r in range(1, 6) for col in range(1, 6)]
    for k in range(symbols):
        c.row, c.column = cells[(7 * k) % 25]
        c.symbol = k % 2
        robot.post("Control", "button")
        robot.chart_step()
        robot.chart_step()
        if not robot.run_until(lambda: not c.busy, 60.0):
            raise DrawError(f"symbol {k + 1} did not finish within 60 s")
    robot.control_stage.erase_requested = True
    robot.run_until(lambda: c.erasing, 10.0)
    if not robot.run_until(lambda: not c.erasing, 300.0):
        raise DrawError("erasing did not finish within 300 s")
    wall = time.perf_counter() - wall0
    return {
        "game_motion_realtime_factor": round(robot.t / wall, 1),
        "game_motion_sim_s": round(robot.t, 2),
        "game_motion_wall_s": round(wall, 2),
        "game_motion_ink_left_mm2": round(robot.board.ink_area_mm2(), 3),
    }
