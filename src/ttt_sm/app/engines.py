"""The game algorithm the robot plays with, chosen by name (``ttt-sm play --engine``, the GUI's Engine button)."""

from __future__ import annotations

from collections.abc import Callable

from .game_outcome import GameError
from .person import Cell


def engine_for(name: str) -> Callable[[str, str], Cell]:
    """The game algorithm called `name` ("strong" or "thesis") as a function (board text, symbol) -> cell."""
    from ..game.engine import GameOver
    from ..game.strong_engine import StrongEngine
    from ..game.thesis_engine import ThesisEngine

    engines = {"strong": StrongEngine, "thesis": ThesisEngine}
    if name not in engines:
        raise ValueError(f"unknown engine {name!r}; choose from {', '.join(engines)}")
    engine = engines[name]()

    def move(board: str, symbol: str) -> Cell:
        answer = engine.move(board, symbol)
        if isinstance(answer, GameOver):
            raise GameError(f"the {name} engine was asked to move after the end: {answer.reason}")
        return answer.row, answer.column

    return move
