"""What a game tells: its record's first and last events, the board pictures, the report, the state a replay
reproduces (docs/play.md, "What it reports"; :mod:`.game_record` writes the lines).

Mixed into :class:`~.game.GameSession`, whose state these methods read.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..files import RecordWriteError
from ..params import ArmParams
from ..twin.board_picture import save_board_picture
from .game_outcome import outcome_in_words
from .game_record import GameRecord, checkpoint, params_digest
from .game_stages import NO_PRECISION, PenPathStage, Wait

if TYPE_CHECKING:
    from ..charts.game import AlgorithmActivator
    from .camera_link import CameraLink
    from .person import Cell, Person
    from .robot import Robot


class GameReporting:
    """The record, the pictures and the report of a :class:`~.game.GameSession`."""

    # what of the session these read (set in GameSession.__init__)
    params: ArmParams
    robot: Robot
    activator: AlgorithmActivator
    camera: CameraLink
    person: Person
    pen_path: PenPathStage | None
    record: GameRecord
    out_dir: Path | None
    pictures: dict[str, str]
    moves: list[dict[str, Any]]
    robot_symbol: str
    person_symbol: str
    engine_name: str
    time_limit_s: float
    setup_wall_s: float
    outcome: str | None
    board: str
    truth: str
    o_pos: int
    result_code: int
    pending_move: Cell | None
    erase_started: bool
    erase_cause: str | None
    erased_seen: bool
    detections_correct: int
    detections_wrong: int
    _ending: bool
    _wait: Wait | None
    _event: Callable[..., dict[str, Any]]

    def record_start(self, max_moves: int) -> None:
        """The record's first line: what a replay of the record needs."""
        self._event("game", seed=self.robot.seed, robot_symbol=self.robot_symbol, engine=self.engine_name,
                    person=getattr(self.person, "name", type(self.person).__name__), camera=self.camera.mode,
                    params_sha256=params_digest(self.params), time_limit_s=self.time_limit_s, max_moves=max_moves)

    def end_record(self, how: str, **data: Any) -> None:
        """The record's last event (where the game stood, and its state), and the board picture of the moment."""
        if self.record.ended is not None:
            return
        self._ending = True
        wait = self._wait
        where = {"waiting_for": wait.what if wait is not None else "the start of the game",
                 "control": sorted(self.robot.active("Control")), "game": sorted(self.robot.active("Game"))}
        if how != "finished" and self.record.failed is None:  # the record's disk failed: that is what is said
            try:
                self._save_board("final" if "final" not in self.pictures else "erased", ending=how)
            except RecordWriteError as exc:  # how the game ended matters more than its picture
                self.pictures["not_written"] = f"{exc.filename}: {exc.strerror}"
        self._event(how, **data, **({} if how == "finished" else where), pictures=dict(self.pictures),
                    state=self.checkpoint())
        self.record.close()

    def _save_board(self, which: str, ending: str | None = None) -> None:
        """The board picture ``board_<which>.png`` in ``out_dir`` (nothing without one)."""
        if self.out_dir is None:
            return
        robot = self.robot
        ink = robot.board.ink_area_mm2()
        if which == "final":
            how = {None: outcome_in_words(self.outcome, self.robot_symbol, self.person_symbol),
                   "interrupted": "the game interrupted",
                   "error": "the game stopped by an error"}[ending]
            title = f"The whiteboard at the end of the game: {how}, {len(self.moves)} moves played"
        else:
            title = "The whiteboard after erasing" if ending is None else \
                f"The whiteboard while erasing: {'interrupted' if ending == 'interrupted' else 'an error'}"
        path = save_board_picture(
            robot.board, self.out_dir / f"board_{which}.png", title,
            f"the robot plays {self.robot_symbol} (blue ink), the person {self.person_symbol} (black ink); "
            f"seed {robot.seed}, simulated time {robot.t:.1f} s, {ink:.0f} mm² of ink on the board")
        self.pictures[which] = str(path)

    def report(self, wall_s: float) -> dict[str, Any]:
        """What a game reports (docs/play.md, "What it reports"); `wall_s`: the wall time it took."""
        robot = self.robot
        outcome = self.outcome or "abandoned"
        ink_left = robot.board.ink_area_mm2()
        winner = {self.robot_symbol: "robot", self.person_symbol: "person", "given_up": "robot"}.get(outcome, outcome)
        return {
            "winner": winner,
            "outcome": outcome,
            "moves": self.moves,
            "robot_symbol": self.robot_symbol,
            "detections_correct": self.detections_correct,
            "detections_wrong": self.detections_wrong,
            "sim_time_s": round(robot.t, 3),
            "wall_time_s": round(wall_s, 3),
            "realtime_factor": round(robot.t / wall_s, 1),
            "setup_wall_s": round(self.setup_wall_s, 3),
            "erased": ink_left == 0.0,
            "erase_cause": self.erase_cause,
            "ink_left_mm2": round(ink_left, 3),
            "camera": self.camera.mode,
            "camera_link": self.camera.stats(),
            "camera_wall_s": round(self.camera.read_wall_s, 3),
            "ignored_play_clicks": self.activator.ignored_triggers,
            **(NO_PRECISION if self.pen_path is None else self.pen_path.precision()),
        }

    def checkpoint(self) -> dict[str, Any]:
        """The state of the game now, as its record keeps it (:func:`.game_record.checkpoint`)."""
        return checkpoint(self.robot, self.state())

    def state(self) -> dict[str, Any]:
        """The session's own state (boards, moves, flags), plain data: what a replay must reproduce too."""
        return {"board": self.board, "truth": self.truth, "moves": [dict(m) for m in self.moves],
                "o_pos": self.o_pos, "result": self.result_code, "outcome": self.outcome,
                "pending_move": self.pending_move, "erase_started": self.erase_started,
                "erased_seen": self.erased_seen, "detections": [self.detections_correct, self.detections_wrong]}
