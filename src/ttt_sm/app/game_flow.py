"""The game as a session plays it (thesis section 3.6): the person's turns, the robot's, the end.

:func:`flow` is a generator: it yields a :class:`~.game_stages.Wait`
whenever the charts must run before it can go on, and does the session's
part between chart steps: the person draws and clicks Play, the camera
looks, percent-process turns the percentages into the person's move, the
boards are updated.  :meth:`.game.GameSession.play` runs it with
``Robot.run_until``, a :class:`~.game_stages.GameDriver` from inside the
chart steps.
"""

from __future__ import annotations

from collections.abc import Generator
from typing import TYPE_CHECKING

from ..game.bitboard import cell_index
from ..vision import MoveError, percent_process
from .game_errors import GameError
from .game_report import outcome_in_words, result_of, save_board
from .game_stages import Flow, Wait

if TYPE_CHECKING:
    from .game import GameSession

#: How long the game waits for a person at a GUI to draw and click Play, simulated s.
PERSON_WAIT_S = 24 * 3600.0


def flow(session: GameSession, max_moves: int = 25) -> Flow:
    """The game as the session plays it: the person's turns, the robot's, the end.

    A generator: it yields a :class:`~.game_stages.Wait` whenever the charts
    must run before it can go on, and does its part (the person draws and
    clicks Play, the camera looks, the board is updated) between chart steps.
    """
    session.say("initialising, then drawing the field")
    yield Wait(session.waiting_or_stopped, 300.0, "initialising and drawing the field")
    session.add_event("field_drawn")
    given_up = False
    # Each turn adds one move; a GUI's person's turn may end without one (the symbols
    # changed before the first move, or Stop): X moves when the number of moves is even.
    while result_of(session.board) is None and len(session.moves) < max_moves and not session.stopped():
        to_move = "X" if len(session.moves) % 2 == 0 else "O"
        if to_move == session.person_symbol:
            if not (yield from _person_turn(session)):
                given_up = True
                break
        else:
            yield from _robot_turn(session)
    stopped = session.stopped() and result_of(session.board) is None
    outcome = result_of(session.board) or ("given_up" if given_up else "halted" if stopped else "abandoned")
    session.outcome = outcome
    session.result_code = {session.robot_symbol: 1, session.person_symbol: 2, "draw": 3, "given_up": 4}.get(outcome, 3)
    session.add_event("result", outcome=outcome)
    save_board(session, "final")  # the board as the game ended, before the sponge
    session.say(f"result: {outcome_in_words(outcome, session.robot_symbol, session.person_symbol)}; "
                "erasing and turning off")
    yield Wait(lambda: session.game.ended, 600.0, "erasing and turning off")
    save_board(session, "erased")


def _person_turn(session: GameSession) -> Generator[Wait, None, bool]:
    """The person draws a move, clicks Play, the camera reads it; False: the person gave up."""
    robot = session.robot
    step = session.params.control.chart_dt
    # The Game chart shows whose turn it is before the person is asked.
    yield Wait(lambda: True, step, "the Game chart to show whose turn it is", tell=False)
    yield Wait(lambda: True, step, "the person's move")
    if session.remote:
        # The person draws by clicking cells (person_draws), then clicks Play: the camera looks then.
        session.drawn, session.play_pressed, session.awaiting = [], False, "draw"
        try:
            yield _remote_wait(session, "the person's move and Play", session.person_symbol)
        finally:
            session.awaiting = None
        if not session.play_pressed:
            return True  # the symbols changed before the first move, or Stop: the flow decides again
        session.play_pressed = False
        cell = session.drawn[-1]
    else:
        chosen = session.ask_person()
        if chosen is None:
            session.add_event("given_up", moves=len(session.moves))
            return False
        cell = chosen
        session.person_draws(cell)
    percentages, symbols = session.look()
    try:
        seen = percent_process(percentages, session.robot_cells, session.person_cells, robot_ink=session.robot_ink,
                               symbols=symbols, robot_symbol=session.robot_symbol)
    except MoveError as exc:
        session.detections_wrong += 1
        message = getattr(exc, "message_for_person", str(exc))
        session.person.tell(message)
        session.add_event("detection_rejected", message=message)
        raise GameError(f"the camera's view was refused: {message}") from exc
    ok = seen.new == cell
    session.detections_correct += ok
    session.detections_wrong += not ok
    session.add_event("detected", row=seen.new[0] if seen.new else None,
                      column=seen.new[1] if seen.new else None, correct=ok,
                      percentages=[round(p, 1) for p in percentages])
    if seen.new is not None:
        session.person_cells.append(seen.new)
        session.set_board(seen.new, session.person_symbol)
        session.o_pos |= 1 << cell_index(*seen.new)
    session.moves.append({"by": "person", "symbol": session.person_symbol, "row": cell[0], "column": cell[1],
                          "t": round(robot.t, 3), "detected": list(seen.new) if seen.new else None})
    if result_of(session.board) is None:
        _click_play(session)  # the person's Play click: the robot's turn
    return True


def _robot_turn(session: GameSession) -> Flow:
    """The engine answers (the AlgorithmActivator's enable), the Control chart draws it, the camera reads its ink."""
    robot = session.robot
    if not session.moves:
        if session.remote:  # the person clicks Play for the manipulator to open the game
            session.play_pressed, session.awaiting = False, "play"
            try:
                yield _remote_wait(session, "Play for the manipulator's first move", session.person_symbol)
            finally:
                session.awaiting = None
            if not session.play_pressed:
                return  # the symbols changed, or Stop: the flow decides again
            session.play_pressed = False
        _click_play(session)  # the robot opens: Play without a drawing first
    session.pending_move = None
    yield Wait(lambda: session.pending_move is not None or session.stopped(), 10.0, "the algorithm's answer")
    if session.stopped():
        return  # Stop: the manipulator returns to its start pose instead
    cell = session.pending_move
    assert cell is not None
    step = session.params.control.chart_dt
    yield Wait(lambda: True, step, "the Control chart to take the move", tell=False)
    yield Wait(lambda: True, step, "the Control chart to take the move", tell=False)
    yield Wait(session.waiting_or_stopped, 120.0, f"drawing the robot's move {cell}")
    if session.stopped():
        return  # Stop in the middle of the stroke: the pen is lifted, the move not made
    session.robot_cells.append(cell)
    session.set_board(cell, session.robot_symbol)
    session.place(cell, session.robot_symbol, "truth")
    percentages, _ = session.look()
    session.robot_ink[cell] = percentages[cell_index(*cell)]
    session.moves.append({"by": "robot", "symbol": session.robot_symbol, "row": cell[0], "column": cell[1],
                          "t": round(robot.t, 3)})
    session.person.tell(f"The manipulator drew {session.robot_symbol} in row {cell[0]}, column {cell[1]}.")


def _remote_wait(session: GameSession, what: str, symbol: str) -> Wait:
    """Wait for the person's Play click, or the symbols to change before the first move, or Stop."""
    return Wait(lambda: session.play_pressed or session.person_symbol != symbol or session.stopped(),
                PERSON_WAIT_S, what)


def _click_play(session: GameSession) -> None:
    """The Play button: the AlgorithmActivator's trigger."""
    session.robot.post("AlgorithmActivator", "trigger")
