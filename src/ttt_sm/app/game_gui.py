"""The person at a GUI (:class:`~.person.RemotePerson`, the Tic-tac-toe page): their clicks, checked against
where the game stands (thesis section 3.7, the Tic-tac-toe GUI).

The page draws the person's symbol where they click (the simulated hand: the camera must see it), clicks Play,
and before the first move chooses the manipulator's symbol and engine.  Each click is an input from outside the
simulation: a debugger records it with its control step and applies it again when it replays
(:meth:`GuiInputs.person_input`).  Mixed into :class:`~.game.GameSession`, whose state these methods read and
change.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

from ..game.bitboard import cell_index
from .engines import engine_for
from .game_outcome import GameError
from .game_stages import Wait
from .person import Cell

if TYPE_CHECKING:
    from ..charts.game import Game
    from .robot import Robot

#: How long the game waits for a person at a GUI to draw and click Play, simulated s.
PERSON_WAIT_S = 24 * 3600.0


class GuiInputs:
    """The Tic-tac-toe page's inputs to a :class:`~.game.GameSession`."""

    # what of the session these read and change (set in GameSession.__init__)
    robot: Robot
    game: Game
    engine: Callable[[str, str], Cell]
    engine_name: str
    robot_symbol: str
    person_symbol: str
    truth: str
    moves: list[dict[str, Any]]
    robot_cells: list[Cell]
    remote: bool
    drawn: list[Cell]
    play_pressed: bool
    awaiting: str | None
    _event: Callable[..., dict[str, Any]]
    _place: Callable[[Cell, str, str], None]
    _stopped: Callable[[], bool]

    @property
    def symbol_locked(self) -> bool:
        """The robot's symbol cannot change any more: a move has been made (or drawn)."""
        return bool(self.moves or self.drawn)

    def set_robot_symbol(self, symbol: str) -> None:
        """The GUI's Symbol button: the robot plays ``symbol`` ('X' or 'O'), only before the first move."""
        if symbol not in ("X", "O"):
            raise ValueError(f"the robot's symbol must be X or O, got {symbol!r}")
        if self.symbol_locked and symbol != self.robot_symbol:
            raise GameError(f"the manipulator plays {self.robot_symbol}: the symbol cannot change after the"
                            " first move")
        if symbol != self.robot_symbol:
            self._event("symbol", robot_symbol=symbol)
        self.robot_symbol = symbol
        self.person_symbol = "X" if symbol == "O" else "O"

    def set_engine(self, name: str) -> None:
        """The game algorithm the manipulator plays with ("strong" or "thesis"), before the first move only."""
        if self.symbol_locked and name != self.engine_name:
            raise GameError(f"the manipulator plays with the {self.engine_name} engine: the engine cannot change"
                            " after the first move")
        self.engine = engine_for(name)
        if name != self.engine_name:
            self._event("engine", engine=name)
        self.engine_name = name

    def person_input(self, name: str, **data: Any) -> None:
        """One input of the person at a GUI, by name: ``cell`` (row, column), ``play``, ``symbol`` (symbol),
        ``engine`` (engine).  A debugger records each with its control step and applies it again there
        when it replays (the person's clicks are inputs from outside the simulation)."""
        if name == "cell":
            self.person_draws((int(data["row"]), int(data["column"])))
        elif name == "play":
            self.press_play()
        elif name == "symbol":
            self.set_robot_symbol(str(data["symbol"]))
        elif name == "engine":
            self.set_engine(str(data["engine"]))
        else:
            raise ValueError(f"unknown input of the person {name!r}; inputs: cell, play, symbol, engine")

    def person_draws(self, cell: Cell) -> None:
        """The simulated hand draws the person's symbol in ``cell`` on the whiteboard (the camera must see it)."""
        row, column = cell
        if not (1 <= row <= 5 and 1 <= column <= 5):
            raise ValueError(f"cell (row {row}, column {column}) is not on the 5x5 field")
        if self.remote and self.awaiting != "draw":
            raise GameError("it is not your turn to draw: " + (
                "click Play for the manipulator to move" if self.awaiting == "play" else self.game.message))
        there = self.truth[cell_index(row, column)]
        if self.remote and there != ".":  # the page's hand draws only where it can: it cannot wipe a mark off
            whose = "the manipulator's" if there == self.robot_symbol and cell in self.robot_cells else "an"
            raise GameError(f"cell ({row}, {column}) holds {whose} {there} already: click an empty cell")
        self.robot.board.draw_symbol(self.person_symbol, row, column)
        self._place(cell, self.person_symbol, "truth")
        self._event("person_drew", row=row, column=column)
        if self.remote:
            self.drawn.append(cell)

    def press_play(self) -> None:
        """The GUI's Play button: the manipulator moves (after the person drew theirs, or to open the game)."""
        if self.awaiting == "play" or (self.awaiting == "draw" and self.drawn):
            self.play_pressed = True
            return
        if self.awaiting == "draw":
            raise GameError("it is your turn: draw your move (click a cell), then click Play")
        raise GameError(f"Play is not taken now: {self.game.message}")

    def _remote_wait(self, what: str, symbol: str) -> Wait:
        """Wait for the person's Play click, or the symbols to change before the first move, or Stop."""
        return Wait(lambda: self.play_pressed or self.person_symbol != symbol or self._stopped(),
                    PERSON_WAIT_S, what)
