"""The game: 5x5 tic-tac-toe, four in a row wins (thesis 3.6.2), and the engines that play it.

``rules`` (boards, moves, who won), ``thesis_engine`` (the thesis' three-ply
minimax), ``strong_engine`` (never loses: ``book`` + ``solver``) and ``bench``;
the ``ttt-sm ai`` command is :mod:`ttt_sm.cli.ai`.  Nothing here imports robot code.
"""

from .engine import Engine, GameOver, Move
from .rules import (
    Board,
    BoardError,
    GameError,
    MoveError,
    apply_move,
    format_board,
    is_draw,
    is_full,
    is_over,
    legal_moves,
    parse_board,
    whose_turn,
    winner,
)

__all__ = [
    "Board", "BoardError", "Engine", "GameError", "GameOver", "Move", "MoveError", "apply_move",
    "format_board", "is_draw", "is_full", "is_over", "legal_moves", "parse_board", "whose_turn", "winner",
]
