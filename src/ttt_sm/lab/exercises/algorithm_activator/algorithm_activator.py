"""AlgorithmActivator, your version (thesis section 3.6.2, fig. 3.30).

"allows the user to activate the Tic-tac-toe algorithm using the manual switch
only once as long as the coordinates are the same."  Fill in the TODOs.
"""

from __future__ import annotations

from statemachine import State

from ttt_sm.runtime import Data, TickChart


class MyActivator(TickChart):
    """The Play trigger enables the game algorithm for one chart step per change of o_pos."""

    inputs = (
        Data("o_pos", "1", 0, "the opponent's moves: one bit per occupied cell"),
        Data("hold", "bool", False, "a new game: forget the moves the algorithm was last run for"),
    )
    outputs = (
        Data("enable", "bool", False, "enables the game algorithm for this one chart step"),
    )
    local = (
        Data("ignored_triggers", "1", 0, "Play clicks while the opponent's moves had not changed"),
    )

    armed = State(initial=True)
    enabled = State()

    # TODO: after one step enabled, wait (a third state) until o_pos changes; count clicks meanwhile
    trigger = armed.to(enabled) | enabled.to(enabled)

    def on_enter_enabled(self) -> None:
        self.enable = True
