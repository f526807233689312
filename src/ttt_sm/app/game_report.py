"""What a game leaves behind: its result, the report ``ttt-sm play`` prints, the board pictures.

The report's keys are described in docs/play.md ("What it reports"); the
drawing precision is the robot's ink against the desired pen-down paths
(:class:`~.game_stages.PenPathStage`), measured as ``ttt-sm draw`` measures
one drawing (thesis section 3.5).  The pictures ``board_final.png`` and
``board_erased.png`` go into the session's ``out_dir``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..game.rules import is_full, parse_board, winner
from ..twin.board_picture import save_board_picture
from .game_stages import PenPathStage

if TYPE_CHECKING:
    from .game import GameSession


def result_of(board: str) -> str | None:
    """'X' or 'O' for a win, 'draw' for a full board, None while the game is on."""
    b = parse_board(board)
    won = winner(b)
    if won is not None:
        return won
    return "draw" if is_full(b) else None


def outcome_in_words(outcome: str | None, robot_symbol: str, person_symbol: str) -> str:
    """How a game ended, for a person to read: who won, or why there is no winner."""
    return {robot_symbol: f"the robot ({robot_symbol}) won", person_symbol: f"the person ({person_symbol}) won",
            "draw": "a draw: the board is full", "given_up": "the person gave up",
            "halted": "stopped before a result", "abandoned": "ended without a result"}.get(outcome or "abandoned",
                                                                                           str(outcome))


def game_report(session: GameSession, wall_s: float) -> dict[str, Any]:
    """What a game reports (docs/play.md, "What it reports"); `wall_s`: the wall time it took."""
    robot = session.robot
    outcome = session.outcome or "abandoned"
    ink_left = robot.board.ink_area_mm2()
    won_by = {session.robot_symbol: "robot", session.person_symbol: "person", "given_up": "robot"}.get(outcome, outcome)
    return {
        "winner": won_by,
        "outcome": outcome,
        "moves": session.moves,
        "robot_symbol": session.robot_symbol,
        "detections_correct": session.detections_correct,
        "detections_wrong": session.detections_wrong,
        "sim_time_s": round(robot.t, 3),
        "wall_time_s": round(wall_s, 3),
        "realtime_factor": round(robot.t / wall_s, 1),
        "setup_wall_s": round(session.setup_wall_s, 3),
        "erased": ink_left == 0.0,
        "ink_left_mm2": round(ink_left, 3),
        "camera": session.camera.mode,
        "camera_link": session.camera.stats(),
        "camera_wall_s": round(session.camera.read_wall_s, 3),
        "ignored_play_clicks": session.activator.ignored_triggers,
        **drawing_precision(session.pen_path, session.params.board.surface_z),
    }


def drawing_precision(pen_path: PenPathStage | None, surface_z: float) -> dict[str, float | None]:
    """The robot's ink against the desired pen-down paths of the whole game, mm (None without ground truth)."""
    from .drawing import _distance_to_runs, _pen_down_runs

    if pen_path is None:
        return {"drawing_rms_mm": None, "drawing_max_mm": None}
    ink = [p for p in pen_path.robot_ink() if len(p)]
    if not ink or not pen_path.xyz:
        return {"drawing_rms_mm": None, "drawing_max_mm": None}
    runs = _pen_down_runs(np.asarray(pen_path.xyz), surface_z)
    if not runs:
        return {"drawing_rms_mm": None, "drawing_max_mm": None}
    err = _distance_to_runs(np.vstack(ink), runs) * 1e3
    return {"drawing_rms_mm": round(float(np.sqrt(np.mean(err ** 2))), 4),
            "drawing_max_mm": round(float(err.max()), 4)}


def save_board(session: GameSession, which: str, ending: str | None = None) -> None:
    """The board picture ``board_<which>.png`` in ``out_dir`` (nothing without one)."""
    if session.out_dir is None:
        return
    robot = session.robot
    ink = robot.board.ink_area_mm2()
    if which == "final":
        how = {None: outcome_in_words(session.outcome, session.robot_symbol, session.person_symbol),
               "interrupted": "the game interrupted",
               "error": "the game stopped by an error"}[ending]
        title = f"The whiteboard at the end of the game: {how}, {len(session.moves)} moves played"
    else:
        title = "The whiteboard after erasing" if ending is None else \
            f"The whiteboard while erasing: {'interrupted' if ending == 'interrupted' else 'an error'}"
    path = save_board_picture(
        robot.board, session.out_dir / f"board_{which}.png", title,
        f"the robot plays {session.robot_symbol} (blue ink), the person {session.person_symbol} (black ink); "
        f"seed {robot.seed}, simulated time {robot.t:.1f} s, {ink:.0f} mm² of ink on the board")
    session.pictures[which] = str(path)
