"""A whole game, person against robot (thesis section 3.6 and its Tic-tac-toe GUI, 3.7).

The robot initialises, draws the field and plays: the person draws a
symbol on the board (at the terminal: types a cell and the simulated hand
draws it; or a simulated person), clicks Play (the AlgorithmActivator's
trigger), the camera reports the 25 per-cell percentages (through the
emulated smart camera on a pseudo-terminal by default), percent-process
turns them into the person's moves, the game algorithm answers, and the
Control chart draws the answer.  The Game chart shows the GUI's messages,
announces the result, erases the board and turns the arm off.

The game's record (:class:`~.game_record.GameRecord`) is written as it
happens when the session has an ``out_dir``; the board picture is taken when
the result is known, before the sponge erases it.  A game stops at a chart
step's end when asked to (:meth:`GameSession.interrupt`, from a signal
handler; at once while it waits for the person), and its record then ends
with the ``interrupted`` event; every game is bounded in simulated time
(``time_limit_s``).

Beside the session: who plays against the robot (:mod:`.person`), the engine
chosen by name (:mod:`.engines`), how a game ends (:mod:`.game_outcome`), and
the game inside the chart steps, its stages and driver (:mod:`.game_stages`).
Mixed into the session: the GUI person's clicks (:mod:`.game_gui`), the
camera's photos and how far the game trusts them while the picture may be
mirrored or turned (:mod:`.game_orientation`), and the record's events, the
board pictures and the report (:mod:`.game_report`).
"""
from __future__ import annotations

import gc
import time
from collections.abc import Callable, Generator, Sequence
from pathlib import Path
from typing import Any, cast

from ..arm import Arm
from ..charts.game import AlgorithmActivator, Game
from ..game.bitboard import cell_index
from ..params import ArmParams
from ..runtime.listeners import Trace
from ..runtime.recordfile import interruption
from ..twin.truth import GroundTruth
from ..vision import MoveError, percent_process
from ..vision.percent import check_own_marks
from .camera_link import CameraLink
from .engines import engine_for
from .game_gui import GuiInputs
from .game_orientation import GameCamera, OpenWays
from .game_outcome import GameError, GameInterrupted, outcome_in_words, winning_cells
from .game_record import GameRecord
from .game_report import GameReporting
from .game_stages import Flow, GameDriver, GameStage, PenPathStage, Wait
from .person import Cell, Person, RemotePerson, SimulatedPerson, board_picture
from .robot import Robot
from .wires import GAME_WIRES

#: Longest a game may run, in simulated seconds, unless told otherwise: a whole game of 25 moves
#: takes about 450 s (a usual one about 190 s), so only a game that is stuck reaches it.
DEFAULT_TIME_LIMIT_S = 1200.0


class GameSession(GuiInputs, GameReporting, GameCamera):
    """One game on the simulated robot.

    ``q_start`` and ``settle_s`` are the :class:`Robot`'s: the pose before the
    unpowered arm settles for ``settle_s`` seconds (default: the rest pose).
    ``arm`` and ``truth``: another arm than the twin (``--arm serial:PORT``,
    :mod:`.arms`) and the ground truth it offers for the whiteboard.
    """

    def __init__(self, params: ArmParams, seed: int = 0, robot_symbol: str = "O", person: Person | None = None,
                 engine: str = "strong", camera: str = "serial", record_trace: bool = True,
                 progress: Callable[[str], None] | None = None, q_start: Sequence[float] | None = None,
                 settle_s: float = 0.0, out_dir: Path | None = None, time_limit_s: float = DEFAULT_TIME_LIMIT_S,
                 status: Callable[[str], None] | None = None, record: GameRecord | None = None,
                 arm: Arm | None = None, truth: GroundTruth | None = None) -> None:
        if robot_symbol not in ("X", "O"):
            raise ValueError(f"robot symbol must be X or O, got {robot_symbol!r}")
        if not 0 < time_limit_s < float("inf"):
            raise ValueError(f"the time limit must be a positive number of seconds, got {time_limit_s}")
        setup0 = time.perf_counter()
        self.params = params
        self.say = progress or (lambda _m: None)
        self.trace = Trace() if record_trace else None
        listeners: list[object] = [self.trace] if self.trace else []
        self.robot = Robot(params, seed=seed, listeners=listeners, q_start=q_start, settle_s=settle_s, arm=arm,
                           truth=truth)
        #: The desired pen-down paths, for the game's drawing precision (with ground truth only).
        self.pen_path = PenPathStage(self.robot) if self.robot.truth is not None else None
        if self.pen_path is not None:
            self.robot.sched.joint_stages.append(self.pen_path)
        # the game's charts from the robot's slots (a student's chart in the lab: :mod:`.slots`)
        slots = self.robot.slots
        period = params.control.chart_dt
        self.activator = cast(AlgorithmActivator,
                              slots.make("AlgorithmActivator", tick_period_s=period, listeners=listeners))
        self.game = cast(Game, slots.make("Game", tick_period_s=period, listeners=listeners))
        self.robot_symbol = robot_symbol
        self.person_symbol = "X" if robot_symbol == "O" else "O"
        self.person = person or SimulatedPerson(seed, self.say)
        self.engine_name = engine
        self.engine = engine_for(engine)
        self.camera = CameraLink(params, self.robot.board, seed=seed, mode=camera)
        #: The ways the camera's picture may have been turned or mirrored that the photos so far allow.
        self.ways = OpenWays(camera, self.camera.view)
        #: The person's moves detected while other ways than the photo as it is remained: not yet facts.
        self.unconfirmed: list[Cell] = []
        self.board = "." * 25  # what the robot believes: its moves and the person's detected moves
        self.truth = "." * 25  # what is really drawn (the simulated person's hand is known)
        self.robot_cells: list[Cell] = []
        self.person_cells: list[Cell] = []
        self.robot_ink: dict[Cell, float] = {}
        self.o_pos = 0
        self.result_code = 0
        self.erase_started = False
        #: What set the erase flag: "game over" (the Game chart asked, thesis section 3.6) or "full board"
        #: (the manipulator's symbols and the camera's add up to 25, section 3.6.1); None: not yet.
        self.erase_cause: str | None = None
        self.erased_seen = False
        self.pending_move: Cell | None = None
        self.detections_correct = 0
        self.detections_wrong = 0
        #: What happened (``record``: one already open, e.g. before the robot was built).
        self.record = record or GameRecord()
        self.record.trace = self.trace
        #: Where the record and the board pictures go (None: only in memory, until :meth:`save`).
        self.out_dir = out_dir
        if out_dir is not None:
            self.record.attach(out_dir / "game.jsonl")
        self.time_limit_s = float(time_limit_s)
        #: Shows where a long run is (a terminal's status line), about once per simulated second.
        self.status = status
        #: Stop at the end of this chart tick (a replay of a record), else None.
        self.stop_at_tick: int | None = None
        self._stop_request: str | None = None
        self._waiting_for_person = False
        self._ending = False
        self._wait: Wait | None = None
        self.pictures: dict[str, str] = {}
        self.moves: list[dict[str, Any]] = []
        #: 'X', 'O', 'draw', 'given_up', 'abandoned' or 'halted' (Stop) once the flow has seen the game end, else None.
        self.outcome: str | None = None
        #: Plays the flow from inside the chart steps (:meth:`drive`), else None.
        self.driver: GameDriver | None = None
        self._last_message = ""
        self._given_up = False
        #: A person at a GUI (:class:`RemotePerson`): the game waits for their clicks.
        self.remote = isinstance(self.person, RemotePerson)
        #: The cells the person drew in the current turn (a GUI's person), last one last.
        self.drawn: list[Cell] = []
        #: The person clicked Play and the game has not taken it yet.
        self.play_pressed = False
        #: What the flow waits for from a GUI's person now: "draw" (their move, then Play), "play"
        #: (Play, the robot opens) or None (nothing: the manipulator moves, or the game is over).
        self.awaiting: str | None = None
        #: The camera's last reading: 25 percentages and the symbols read (None: not read), board order.
        self.last_view: tuple[tuple[float, ...], str | None] | None = None
        #: Photos the game has taken (the page refreshes the camera's picture when it changes).
        self.photos = 0
        #: The Session block's output `play_again`: one game per session.
        self.play_again = False
        self.robot.add_charts((self.activator, self.game), GAME_WIRES, GameStage(self))
        self.robot.game = self
        # the Safety chart's trips and resets go into the record as they happen, with their reasons
        self.robot.safety_stage.listeners.append(lambda kind, data: self._event(kind, **data))
        #: Building the twin (controller design, compiled kernels loaded), the charts and the camera.
        self.setup_wall_s = time.perf_counter() - setup0

    # -- the robot's move, from the AlgorithmActivator's enable pulse ---------------

    def robot_turn_now(self) -> None:
        """Ask the engine for a move and tell the Control chart to draw it."""
        if self._result() is not None:
            return
        t0 = time.perf_counter()
        row, column = self.ways.robot_move(self._readings(), self.engine, self.robot_symbol)
        ms = (time.perf_counter() - t0) * 1e3
        c = self.robot.control
        c.row, c.column, c.symbol = row, column, 1 if self.robot_symbol == "X" else 0
        self.robot.post("Control", "button")
        self.pending_move = (row, column)
        self._event("robot_move", row=row, column=column, think_ms=round(ms, 2))

    # -- running -----------------------------------------------------------------------

    def watch(self, wait: Wait) -> bool:
        """After a chart step: show the person the Game chart's new message; whether the wait is over."""
        if wait.tell:
            msg = self.game.message
            if msg != self._last_message:
                self._last_message = msg
                self.person.tell(msg)
                self._event("message", text=msg)
        return wait.until()

    def wait_failed(self, wait: Wait) -> GameError:
        """The error of a wait that timed out, naming where the charts stand."""
        control, game = sorted(self.robot.active("Control")), sorted(self.robot.active("Game"))
        return GameError(f"{wait.what} did not happen within {wait.timeout_s:.0f} s of simulated time "
                         f"(Control: {control}, Game: {game})")

    def _event(self, kind: str, **data: Any) -> dict[str, Any]:
        return self.record.add(self.robot.t, kind, tick=self.robot.chart_ticks, **data)

    def interrupt(self, why: str) -> None:
        """Stop the game (a signal handler's call; ``why``: e.g. ``SIGINT``).

        While the charts run, the game stops at the end of the chart step (a
        state a replay reaches again); while it waits for the person, or when
        asked a second time, at once: :class:`GameInterrupted` is raised here.
        """
        if self._ending:
            return  # the record's last line is being written: it says how the game ended already
        if self._waiting_for_person or self._stop_request is not None:
            self._stop_request = why
            raise GameInterrupted(why)
        self._stop_request = why

    def _check_stop(self) -> None:
        if self._stop_request is not None:
            raise GameInterrupted(self._stop_request)
        if self.stop_at_tick is not None and self.robot.chart_ticks >= self.stop_at_tick:
            raise GameInterrupted(f"replayed to tick {self.stop_at_tick}")

    def _run(self, wait: Wait) -> None:
        self._wait = wait
        robot = self.robot
        left = self.time_limit_s - robot.t
        if left <= 0:
            raise GameError(f"the game did not end within {self.time_limit_s:g} s of simulated time (its time"
                            f" limit), while waiting for {wait.what}")
        status, every = self.status, max(1, robot.sched.ticks_for(1.0))
        safety = robot.safety

        def until() -> bool:
            # A stop is honoured here only, right after a chart step and before the game goes on with what
            # it waited for: a state a replay to the same chart tick reaches again.  (The checks' own
            # conditions first: this runs after every chart step.)
            if self._stop_request is not None or self.stop_at_tick is not None:
                self._check_stop()
            if safety.tripped:
                self._check_safety()
            if status is not None and robot.chart_ticks % every == 0:
                status(f"t = {robot.t:.0f} s simulated: {wait.what}")
            return self.watch(wait)

        if not robot.run_until(until, min(wait.timeout_s, left)):
            if wait.timeout_s > left:
                raise GameError(f"the game did not end within {self.time_limit_s:g} s of simulated time (its time"
                                f" limit), while waiting for {wait.what}")
            raise self.wait_failed(wait)

    def _check_safety(self) -> None:
        """The Safety chart holds the arm (docs/safety.md): the game cannot go on, and says why."""
        if self.robot.tripped:
            raise GameError(f"safety stop: {self.robot.safety.reason}")

    def _waiting(self) -> bool:
        return bool(self.robot.control.ready)

    def _stopped(self) -> bool:
        """Stop was clicked (the Game chart's `stop`): the Game chart asks the Control chart to finish."""
        return bool(self.game.finish)

    def _waiting_or_stopped(self) -> bool:
        return self._waiting() or self._stopped()

    def _place(self, cell: Cell, symbol: str, which: str) -> None:
        i = cell_index(*cell)
        self.truth = self.truth[:i] + symbol + self.truth[i + 1:]
        if which == "board":
            self.board = self.board[:i] + symbol + self.board[i + 1:]

    def _set_board(self, cell: Cell, symbol: str) -> None:
        i = cell_index(*cell)
        self.board = self.board[:i] + symbol + self.board[i + 1:]

    def play(self, max_moves: int = 25) -> dict[str, Any]:
        """Play one game to its end (or until the person gives up); return the report."""
        if self.driver is not None:
            raise GameError("this game is played from inside the chart steps (drive()): step the robot")
        # What exists now (the twin, the charts, the engine, the modules) lives for the
        # whole game: keep it out of the collector's full passes (one of ~90 ms a game).
        gc.freeze()
        self.record_start(max_moves)
        try:
            wall0 = time.perf_counter()
            for wait in self.flow(max_moves):
                self._run(wait)
            report = self.report(time.perf_counter() - wall0)
        except GameInterrupted as exc:
            self.end_record("interrupted", signal=exc.why, boundary=True)
            raise
        except KeyboardInterrupt:  # no handler sent it through interrupt(): anywhere in a chart step
            self.end_record("interrupted", signal="SIGINT", boundary=False)
            raise
        except Exception as exc:
            interrupt = interruption(exc)  # the signal landed in a C extension's import, say
            if interrupt is not None:
                self.end_record("interrupted", signal=str(getattr(interrupt, "signal", "SIGINT")), boundary=False)
            else:
                self.end_record("error", message=str(exc) if isinstance(exc, GameError)
                          else f"{type(exc).__name__}: {exc}", boundary=isinstance(exc, GameError))
            raise
        finally:
            gc.unfreeze()
        self.end_record("finished", outcome=report["outcome"], boundary=True)
        return report

    def drive(self, max_moves: int = 25) -> GameDriver:
        """Play the game from inside the chart steps from now on: whoever steps the robot plays it.

        For a debugger or a GUI that steps the robot itself; see :class:`GameDriver`.
        """
        if self.driver is None:
            self.record_start(max_moves)
            self.driver = GameDriver(self, max_moves)
        return self.driver

    def flow(self, max_moves: int = 25) -> Flow:
        """The game as the session plays it: the person's turns, the robot's, the end.

        A generator: it yields a :class:`Wait` whenever the charts must run
        before it can go on, and does its part (the person draws and clicks
        Play, the camera looks, the board is updated) between chart steps.
        :meth:`play` runs it with ``Robot.run_until``, a :class:`GameDriver`
        from inside the chart steps.
        """
        self.say("initialising, then drawing the field")
        yield Wait(self._waiting_or_stopped, 300.0, "initialising and drawing the field")
        self._event("field_drawn")
        # Each turn adds one move; a GUI's person's turn may end without one (the symbols
        # changed before the first move, or Stop): X moves when the number of moves is even.
        while self._result() is None and len(self.moves) < max_moves and not self._stopped():
            to_move = "X" if len(self.moves) % 2 == 0 else "O"
            if to_move == self.person_symbol:
                if not (yield from self._person_turn()):
                    break
            else:
                yield from self._robot_turn()
        result = self._result()
        stopped = self._stopped() and result is None
        outcome = result or ("given_up" if self._given_up else "halted" if stopped else "abandoned")
        self.outcome = outcome
        self.result_code = {self.robot_symbol: 1, self.person_symbol: 2, "draw": 3, "given_up": 4}.get(outcome, 3)
        self._event("result", outcome=outcome)
        self._save_board("final")  # the board as the game ended, before the sponge
        line = winning_cells(self.board)
        won = "" if line is None else "\n  the four in a row: " + " ".join(f"({r}, {c})" for r, c in line)
        self.say(f"result: {outcome_in_words(outcome, self.robot_symbol, self.person_symbol)}; "
                 f"erasing and turning off; the board as the game ended:\n{board_picture(self.board)}{won}")
        yield Wait(lambda: self.game.ended, 600.0, "erasing and turning off")
        self._save_board("erased")

    @property
    def detected_count(self) -> int:
        """The Session block's `detected`: the person's symbols the camera has detected."""
        return self.o_pos.bit_count()

    def _click_play(self) -> None:
        self.robot.post("AlgorithmActivator", "trigger")

    def _person_turn(self) -> Generator[Wait, None, bool]:
        robot = self.robot
        step = self.params.control.chart_dt
        # The Game chart shows whose turn it is before the person is asked.
        yield Wait(lambda: True, step, "the Game chart to show whose turn it is", tell=False)
        yield Wait(lambda: True, step, "the person's move")
        if self.remote:
            # The person draws by clicking cells (person_draws), then clicks Play: the camera looks then.
            self.drawn, self.play_pressed, self.awaiting = [], False, "draw"
            try:
                yield self._remote_wait("the person's move and Play", self.person_symbol)
            finally:
                self.awaiting = None
            if not self.play_pressed:
                return True  # the symbols changed before the first move, or Stop: the flow decides again
            self.play_pressed = False
            cell = self.drawn[-1]
        else:
            self._waiting_for_person = True  # an interrupt now stops the game at once
            try:
                if self._stop_request is not None:
                    raise GameInterrupted(self._stop_request)
                chosen = self.person.choose(self.truth, self.person_symbol)
            finally:
                self._waiting_for_person = False
            if chosen is None:
                self._given_up = True
                self._event("given_up", moves=len(self.moves))
                return False
            cell = chosen
            self.person_draws(cell)
        percentages, symbols = self._look()
        try:
            seen = percent_process(percentages, self.robot_cells, self.person_cells, robot_ink=self.robot_ink,
                                   symbols=symbols, robot_symbol=self.robot_symbol)
        except MoveError as exc:
            raise self._refused(exc) from exc
        ok = seen.new == cell
        self.detections_correct += ok
        self.detections_wrong += not ok
        # while the photo may be mirrored or turned, the move read is not a fact (docs/vision.md)
        pending = {"confirmed": False, "open": self.ways.open} if self.ways.open and seen.new else {}
        self._event("detected", row=seen.new[0] if seen.new else None,
                    column=seen.new[1] if seen.new else None, correct=ok,
                    percentages=[round(p, 1) for p in percentages], **pending)
        if seen.new is not None:
            if pending:
                self.unconfirmed.append(seen.new)
            self.person_cells.append(seen.new)
            self._set_board(seen.new, self.person_symbol)
            self.o_pos |= 1 << cell_index(*seen.new)
        self.moves.append({"by": "person", "symbol": self.person_symbol, "row": cell[0], "column": cell[1],
                           "t": round(robot.t, 3), "detected": list(seen.new) if seen.new else None})
        if self._result() is None:
            self._click_play()  # the person's Play click: the robot's turn
        return True

    def _robot_turn(self) -> Flow:
        robot = self.robot
        if not self.moves:
            if self.remote:  # the person clicks Play for the manipulator to open the game
                self.play_pressed, self.awaiting = False, "play"
                try:
                    yield self._remote_wait("Play for the manipulator's first move", self.person_symbol)
                finally:
                    self.awaiting = None
                if not self.play_pressed:
                    return  # the symbols changed, or Stop: the flow decides again
                self.play_pressed = False
            self._click_play()  # the robot opens: Play without a drawing first
        self.pending_move = None
        yield Wait(lambda: self.pending_move is not None or self._stopped(), 10.0, "the algorithm's answer")
        if self._stopped():
            return  # Stop: the manipulator returns to its start pose instead
        cell = self.pending_move
        assert cell is not None
        step = self.params.control.chart_dt
        yield Wait(lambda: True, step, "the Control chart to take the move", tell=False)
        yield Wait(lambda: True, step, "the Control chart to take the move", tell=False)
        yield Wait(self._waiting_or_stopped, 120.0, f"drawing the robot's move {cell}")
        if self._stopped():
            return  # Stop in the middle of the stroke: the pen is lifted, the move not made
        self.robot_cells.append(cell)
        self._set_board(cell, self.robot_symbol)
        self._place(cell, self.robot_symbol, "truth")
        percentages, _ = self._look()
        try:  # the robot's marks are the truth the game has: a mirrored or turned picture shows them moved
            check_own_marks(percentages, self.robot_cells)
        except MoveError as exc:
            raise self._refused(exc) from exc
        self._narrow(percentages, cell)
        self.robot_ink[cell] = percentages[cell_index(*cell)]
        self.moves.append({"by": "robot", "symbol": self.robot_symbol, "row": cell[0], "column": cell[1],
                           "t": round(robot.t, 3)})
        self.person.tell(f"The manipulator drew {self.robot_symbol} in row {cell[0]}, column {cell[1]}.")

    def save(self, out_dir: Path | None = None) -> dict[str, str]:
        """The files of the game: the record (``game.jsonl``) and the board pictures.

        A session with an ``out_dir`` wrote them as the game went; one without
        writes them now to ``out_dir`` (the record of what happened so far, the
        board as it is now).
        """
        if self.out_dir is None:
            if out_dir is None:
                raise ValueError("save() needs a folder: the session was made without out_dir")
            self.out_dir = out_dir
            self.record.attach(out_dir / "game.jsonl")
            if "final" not in self.pictures:
                ended = self.record.ended
                self._save_board("final", ending=ended if ended in ("interrupted", "error") else None)
        files = {"record": str(self.record.path)}
        if "final" in self.pictures:
            files["board_png"] = self.pictures["final"]
        if "erased" in self.pictures:
            files["board_erased_png"] = self.pictures["erased"]
        return files

    def close(self) -> None:
        """Stop the camera emulator; close the record (a game not played to its end: ended as interrupted)."""
        try:
            if self.record.attached and self.record.ended is None and self.record.events:
                self.end_record("interrupted", signal="closed before the end", boundary=True)
            self.record.close()
        finally:
            self.camera.close()
