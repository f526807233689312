"""Which ways the camera's picture may have been changed, as a game learns it (docs/vision.md, "What a single
photo can tell").

A photo of the square field looks the same turned or mirrored, and so do an X and an O: the game cannot tell from
one photo that its camera is not mirrored.  A direct camera beyond the field's far edge tells a turn by its
perspective but not a left-right mirror (it stands on the mirror's axis); the serial smart camera sends no field
corners, so for it every turn and mirror is open.  What tells the rest are the robot's own marks: the robot knows
where it drew them.

:class:`OpenWays` keeps the set of ways (:data:`~ttt_sm.vision.orientation.WAYS`) that all evidence so far allows,
and drops, after every photo, each way that would not show every robot mark where the robot drew it.  While more
than the photo as it is remain, a person's move is detected but not confirmed; the robot plays only cells empty
under every reading (:meth:`OpenWays.robot_move`), and a result is declared only when every reading agrees
(:meth:`OpenWays.result`).  Once only the photo as it is remains, the person's moves are confirmed.

Mixed into :class:`~.game.GameSession`: :class:`GameCamera`, its photos and how far it trusts them (a photo
refused, the camera lost, the ways narrowed by the robot's marks).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from typing import TYPE_CHECKING, Any

from ..game.bitboard import cell_index
from ..vision import MoveError, OrientationError
from ..vision.detection import OCCUPIED_PCT
from ..vision.orientation import AS_IS, undo_way, ways_perspective_allows
from .camera_link import CameraLink, CameraLost
from .game_outcome import GameError, result_of
from .person import Cell, Person

if TYPE_CHECKING:
    from .game_stages import GameDriver
    from .robot import Robot

#: Longest the game waits, once the camera is lost, for the Safety chart to lift the pen and hold, s of simulated
#: time (its lift gives up after 2 s).
CAMERA_LIFT_S = 3.0

#: Where the robot looks for a cell when no reading's best move is empty under every reading: the middle
#: first, then outwards (a cell nearer the middle lies on more lines of four).
_NEAR_MIDDLE = sorted(((r, c) for r in range(1, 6) for c in range(1, 6)),
                      key=lambda rc: (abs(rc[0] - 3) + abs(rc[1] - 3), rc))


class OpenWays:
    """The ways a game's camera picture may have been turned or mirrored that the photos so far allow.

    Parameters
    ----------
    mode : str
        The camera: ``"direct"`` (its perspective is checked on every photo, so only the photo as it is and the
        mirror along the camera's axis remain) or ``"serial"`` (no corners: all eight ways).
    view : str
        Where the camera stands (:data:`~ttt_sm.vision.orientation.VIEW_NAMES`).
    """

    def __init__(self, mode: str, view: str) -> None:
        self.view = view
        self.ways = ways_perspective_allows(view) if mode == "direct" else ways_perspective_allows("field")

    @property
    def open(self) -> list[str]:
        """The ways other than the photo as it is that remain (empty: the photo is established as it is)."""
        return [w for w in self.ways if w != AS_IS]

    def prune(self, percentages: Sequence[float], robot_cells: Iterable[Cell]) -> list[str]:
        """Drop the ways under which the photo (25 percentages, board order) would not show every robot mark where
        the robot drew it; the ways dropped.  The photo as it is is checked by the game first (it ends the game)."""
        occupied = "".join("#" if float(p) > OCCUPIED_PCT else "." for p in percentages)
        marks = [cell_index(*cell) for cell in robot_cells]
        dropped = [w for w in self.open if any(undo_way(occupied, w, self.view)[k] == "." for k in marks)]
        self.ways = [w for w in self.ways if w not in dropped]
        return dropped

    def readings(self, board: str, robot_cells: Iterable[Cell], robot_symbol: str,
                 person_symbol: str) -> dict[str, str]:
        """The board (25 characters, board order, as read) as each remaining way reads it: the robot's marks where
        it drew them, the person's symbol on every other cell the photo shows occupied once the way is undone."""
        robot = {cell_index(*cell) for cell in robot_cells}
        occupied = "".join("." if ch == "." else "#" for ch in board)
        out = {}
        for way in self.ways:
            seen = undo_way(occupied, way, self.view)
            out[way] = "".join(robot_symbol if k in robot else person_symbol if seen[k] == "#" else "."
                               for k in range(25))
        return out

    def robot_move(self, readings: dict[str, str], engine: Callable[[str, str], Cell], robot_symbol: str) -> Cell:
        """The robot's cell: one empty under every reading, so that nothing it does rests on a reading that may be
        wrong.  The engine's move on the board as read if it is such a cell (always, once the ways are settled);
        else its move on another reading that is; else the empty cell nearest the middle."""
        free = [k for k in range(25) if all(board[k] == "." for board in readings.values())]
        if not free:
            raise GameError(f"no cell is empty however the photo is read (it may be {' or '.join(self.open)}):"
                            f" the robot cannot move without trusting a reading that may be wrong")
        for way in (AS_IS, *self.open):
            board = readings.get(way)
            if board is None or result_of(board) is not None:
                continue
            cell = engine(board, robot_symbol)
            if cell_index(*cell) in free:
                return cell
        return next(cell for cell in _NEAR_MIDDLE if cell_index(*cell) in free)

    def result(self, readings: dict[str, str]) -> str | None:
        """The game's result if every reading agrees on it (None: the game goes on); a :class:`GameError` naming the
        camera if they do not (a result that a remaining way would read differently is never declared)."""
        results = {way: result_of(board) for way, board in readings.items()}
        if len(set(results.values())) <= 1:
            return results.get(AS_IS)
        differ = [w for w, r in results.items() if r != results.get(AS_IS)]
        raise GameError(f"the game's result cannot be told: the photo may be"
                        f" {' or '.join(differ)}, and read that way the board shows another result; the robot's"
                        f" marks have not yet told (fix the camera if it is mirrored or turned)")


class GameCamera:
    """A game's photos: taken, refused with the reason, or narrowing the ways the picture may have been changed."""

    # what of the session these read and change (set in GameSession.__init__)
    robot: Robot
    camera: CameraLink
    person: Person
    ways: OpenWays
    board: str
    robot_cells: list[Cell]
    robot_symbol: str
    person_symbol: str
    unconfirmed: list[Cell]
    detections_wrong: int
    last_view: tuple[tuple[float, ...], str | None] | None
    photos: int
    driver: GameDriver | None
    _event: Callable[..., dict[str, Any]]

    def _readings(self) -> dict[str, str]:
        """The board as read, as every way the picture may have been changed reads it."""
        return self.ways.readings(self.board, self.robot_cells, self.robot_symbol, self.person_symbol)

    def _result(self) -> str | None:
        """The result every reading agrees on (None: the game goes on); the camera's view refused if they differ."""
        try:
            return self.ways.result(self._readings())
        except GameError as exc:
            raise self._reject(str(exc)) from None

    def _look(self) -> tuple[tuple[float, ...], str | None]:
        try:
            view = self.camera.read()
        except CameraLost as exc:
            raise self._camera_lost(exc) from None
        except OrientationError as exc:  # a turned camera: the photo is refused, never read as a board
            raise self._reject(str(exc)) from None
        self.robot.camera_status.ok = True  # the Camera block: it answers
        self.last_view = view
        self.photos += 1
        return view

    def _refused(self, exc: MoveError) -> GameError:
        """The camera's view cannot be taken: the person is told why, the record says so, the game ends."""
        return self._reject(getattr(exc, "message_for_person", str(exc)))

    def _reject(self, message: str) -> GameError:
        self.detections_wrong += 1
        self.person.tell(message)
        self._event("detection_rejected", message=message)
        return GameError(f"the camera's view was refused: {message}")

    def _camera_lost(self, exc: CameraLost) -> GameError:
        """The camera stopped answering while the game waited for a photo: the Safety chart's Camera block.

        The Safety chart lifts the pen off the board and holds (docs/safety.md).
        Played by :meth:`play`, the chart steps are this thread's: they run
        until the chart holds (at most :data:`CAMERA_LIFT_S`), and the game
        ends with the chart's reason; driven from the chart steps (the GUI), the
        game ends now and the chart lifts in the steps that follow.
        """
        robot = self.robot
        robot.camera_status.ok = False
        self._event("camera_lost", message=str(exc))
        if self.driver is None:
            # held or stopped: tripped, and no lift under way (the chart's outputs, not its state names)
            robot.run_until(lambda: robot.tripped and math.isnan(robot.safety.lift_z), CAMERA_LIFT_S)
        return GameError(f"safety stop: {robot.safety.reason}" if robot.tripped else f"camera lost: {exc}")

    def _narrow(self, percentages: Sequence[float], mark: Cell) -> None:
        """Drop the ways the photo after the robot drew `mark` rules out; confirm the person's moves once only the
        photo as it is remains."""
        dropped = self.ways.prune(percentages, self.robot_cells)
        if not dropped:
            return
        if self.ways.open:
            self._event("ways_ruled_out", mark=list(mark), ruled_out=dropped, open=self.ways.open)
            return
        self._event("moves_confirmed", mark=list(mark), ruled_out=dropped, moves=[list(c) for c in self.unconfirmed])
        self.unconfirmed = []

