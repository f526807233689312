"""The thesis' Stateflow charts, written on :mod:`ttt_sm.runtime`.

Charts import the runtime only; the application (`ttt_sm.app`) wires them to
the twin, the scheduler and the game.
"""

from .control import Control
from .drive_init import INIT_CHARTS, DriveInit1, DriveInit2, DriveInit3
from .game import AlgorithmActivator, Game
from .safety import Safety

#: Every chart of the project, in the order the diagrams list them.
ALL_CHARTS = (*INIT_CHARTS, Control, AlgorithmActivator, Game, Safety)

__all__ = ["ALL_CHARTS", "INIT_CHARTS", "AlgorithmActivator", "Control", "DriveInit1", "DriveInit2",
           "DriveInit3", "Game", "Safety"]
