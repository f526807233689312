"""The game's charts: the algorithm activator (thesis fig. 3.30) and the game flow (section 3.7).

- ``AlgorithmActivator``: "compares the coordinates of the moves made by the
  opponent in the current time step to the same coordinates in the previous
  time step, and allows the user to activate the Tic-tac-toe algorithm using
  the manual switch only once as long as the coordinates are the same".  Its
  output `enable` is true for exactly one chart tick per activation.
- ``Game``: whose turn it is, when the manipulator draws, the result, erasing
  and turning off, with the messages of the thesis' Tic-tac-toe GUI as its
  `message` output.
"""

from __future__ import annotations

from statemachine import State

from ..runtime import Data, TickChart, action_on, after, after_s, does

#: The Tic-tac-toe GUI's messages (thesis section 3.7, Text box2), and the results.
MSG_COMPILING = "Wait for the model to be compiled."
MSG_INITIALISING = "The compilation is done wait for the manipulator to be initialized."
MSG_YOUR_TURN = "If it is your turn to play draw your next move, otherwise click for the manipulator to play"
MSG_DRAWING = "The manipulator is drawing."
MSG_ERASING = "The manipulator is erasing."
MSG_TURNING_OFF = "The manipulator is being turned off."
#: 4 is not the thesis': its GUI had no way to give up; ``ttt-sm play`` has (``q``), and says so.
RESULT_MESSAGES = {1: "The manipulator wins.", 2: "You win.", 3: "Draw: the board is full.",
                   4: "You gave up: the manipulator erases the board."}


class AlgorithmActivator(TickChart):
    """Fig. 3.30: the Play trigger activates the game algorithm once per change of o_pos."""

    activations: int  # for type checkers: counts up from its own value
    ignored_triggers: int

    inputs = (
        Data("o_pos", "1", 0, "the opponent's moves: bit 5*(row-1)+(column-1) set per occupied cell"),
        Data("hold", "bool", False, "a new game: forget the moves the algorithm was last run for"),
    )
    outputs = (
        Data("enable", "bool", False, "enables the game algorithm's sub-system for this one tick"),
    )
    local = (
        Data("o_pos_used", "1", -1, "o_pos when the algorithm was last enabled (-1: never)"),
        Data("activations", "1", 0, "times the algorithm was enabled"),
        Data("ignored_triggers", "1", 0, "Play clicks while the opponent's moves had not changed"),
    )

    armed = State(initial=True)
    enabled = State()
    spent = State()

    # A click in `spent` counts if the moves changed by then (spent's transitions in the order written:
    # the click's own first).  A click that no transition takes is ignored and counted (`on trigger`);
    # so is one in the step that ends the pulse, which leaves `enabled` as the pulse's end would.
    trigger = (armed.to(enabled)
               | spent.to(enabled, cond="o_pos != o_pos_used or hold")
               | enabled.to(spent, cond=after(1), on="ignore_trigger")
               | action_on((enabled, spent), "ignore_trigger"))
    enabled.to(spent, cond=after(1))  # the enable pulse lasts one chart tick
    spent.to(armed, cond="o_pos != o_pos_used or hold")

    def on_enter_enabled(self) -> None:
        self.enable = True
        self.o_pos_used = self.o_pos
        self.activations = self.activations + 1

    def on_enter_spent(self) -> None:
        self.enable = False

    @does("o_pos_used = -1 if hold else o_pos_used")
    def on_enter_armed(self) -> None:
        if self.hold:
            self.o_pos_used = -1

    @does("ignored_triggers += 1")
    def ignore_trigger(self) -> None:
        self.ignored_triggers = self.ignored_triggers + 1


class Game(TickChart):
    """The game flow behind the Tic-tac-toe GUI: turns, drawing, result, erasing, turning off."""

    timed = True  # the result shows for 2 s of chart time (after_s)

    inputs = (
        Data("initialised", "bool", False, "every drive is initialised (init charts)"),
        Data("ready", "bool", False, "the Control chart waits in wait_1 with the field drawn"),
        Data("busy", "bool", False, "the Control chart is drawing, erasing or moving"),
        Data("result", "1", 0, "0: game on; 1: the manipulator won; 2: the person won; 3: draw; 4: the person gave up"),
        Data("erased", "bool", False, "the Control chart has erased the board and left Erase"),
        Data("sponge", "bool", False, "the Control chart erases (a full board set the erase flag itself)"),
        Data("play_again", "bool", False, "start a new game after erasing instead of turning off"),
        Data("finished", "bool", False, "the Control chart is back at its start pose"),
    )
    outputs = (
        Data("message", "text", MSG_COMPILING, "what the Tic-tac-toe GUI shows (thesis section 3.7)"),
        Data("erase", "bool", False, "ask the Control chart to erase the board"),
        Data("finish", "bool", False, "ask the Control chart to finish and return to its start pose"),
        Data("ended", "bool", False, "off: the game is over and the arm back at its start pose"),
    )
    local = (
        Data("games", "1", 0, "games finished"),
    )

    compiling = State(initial=True)
    initialising = State()

    class playing(State.Compound):
        your_turn = State(initial=True)
        drawing = State()
        your_turn.to(drawing, cond="busy")
        drawing.to(your_turn, cond="ready")

    game_over = State()
    erasing = State()
    turning_off = State()
    off = State(final=True)

    # stop from any phase: written first, so it goes before the phase's own transitions
    stop = turning_off.from_(compiling, initialising, playing, game_over, erasing)
    compiling.to(initialising)
    initialising.to(playing, cond="ready")
    # ready: the last drawing is done; erasing: a full board erases at once (thesis section 3.6.1)
    playing.to(game_over, cond="result != 0 and (ready or sponge)")
    game_over.to(erasing, cond=after_s(2.0))  # the result stays on show for 2 s
    erasing.to(playing, cond="erased and ready and play_again", on="new_game")
    erasing.to(turning_off, cond="erased and not play_again")
    turning_off.to(off, cond="finished")

    #: What the action texts on the diagrams name besides the chart's data (docs/runtime.md, "What an action does").
    action_helpers = {"result_message(r)": "the result's message: " + "; ".join(
        f"{k}: {text!r}" for k, text in RESULT_MESSAGES.items())}

    @does(f"message = {MSG_INITIALISING!r}", summary="message = 'The compilation is done'")
    def on_enter_initialising(self) -> None:
        self.message = MSG_INITIALISING

    @does(f"message = {MSG_YOUR_TURN!r}", summary="message = 'If it is your turn to play'")
    def on_enter_your_turn(self) -> None:
        self.message = MSG_YOUR_TURN

    @does(f"message = {MSG_DRAWING!r}")
    def on_enter_drawing(self) -> None:
        self.message = MSG_DRAWING

    @does("message = result_message(result); games = games + 1")
    def on_enter_game_over(self) -> None:
        self.message = RESULT_MESSAGES.get(self.result, "Game over.")
        self.games = self.games + 1

    @does(f"message = {MSG_ERASING!r}; erase = True")
    def on_enter_erasing(self) -> None:
        self.message = MSG_ERASING
        self.erase = True

    def on_exit_erasing(self) -> None:
        self.erase = False

    def new_game(self) -> None:
        self.result = 0

    @does(f"message = {MSG_TURNING_OFF!r}; finish = True")
    def on_enter_turning_off(self) -> None:
        self.message = MSG_TURNING_OFF
        self.finish = True

    def on_enter_off(self) -> None:
        self.ended = True

    games: int  # for type checkers: counts up from its own value
