"""Step-through debugger for the robot's charts: the API under ``ttt-sm debug``.

>>> dbg = Debugger.build(load_params())            # doctest: +SKIP
>>> dbg.add_breakpoint("enter DriveInit1.turn_back")  # doctest: +SKIP
>>> dbg.run(10.0).describe()                        # doctest: +SKIP

See docs/debugger.md.
"""

from .breakpoints import Breakpoint, Hit
from .debugger import Debugger
from .errors import DebugError
from .records import Action, DataChange, DataDiff, StopReason
from .replay import GameRecipe, ReplayResult, RobotRecipe
from .timeline import Interval, Timeline, TimelineWindow

__all__ = ["Action", "Breakpoint", "DataChange", "DataDiff", "DebugError", "Debugger", "GameRecipe", "Hit",
           "Interval", "ReplayResult", "RobotRecipe", "StopReason", "Timeline", "TimelineWindow"]
