"""Step-through debugger for the robot's charts: the API under ``ttt-sm debug``.

>>> dbg = Debugger.build(load_params())            # doctest: +SKIP
>>> dbg.add_breakpoint("enter DriveInit1.turn_back")  # doctest: +SKIP
>>> dbg.run(10.0).describe()                        # doctest: +SKIP

See docs/debugger.md.
"""

from .breakpoints import Breakpoint, Hit
from .debugger import Debugger
from .errors import DebugError
from .records import Action, StopReason
from .replay import ReplayResult, RobotRecipe

__all__ = ["Action", "Breakpoint", "DebugError", "Debugger", "Hit", "ReplayResult", "RobotRecipe",
           "StopReason"]
