"""Generic Stateflow-clock layer over python-statemachine: no robot code here.

Charts subclass :class:`TickChart`, declare their data with :class:`Data`, use
:func:`after` / :func:`after_s` as temporal guards, and are observed through
listeners (:class:`Trace`, :class:`Coverage`).  :mod:`.diagram` draws them.
"""

from .action_text import does
from .chart import ChartActions, TickChart
from .chart_class import TickChartMeta
from .data import Data
from .errors import (
    ChartDefinitionError,
    ChartExecutionError,
    EventDataError,
    GraphvizMissingError,
    TemporalLogicError,
    UnknownDataError,
    UnknownEventError,
)
from .junction import Junction
from .state_actions import action_on
from .structure import ChartStructure, StateInfo, TransitionInfo, states_entered_by
from .temporal import after, after_s, at, before, duration, every

__all__ = [
    "ChartDefinitionError",
    "ChartExecutionError",
    "Junction",
    "action_on",
    "at",
    "before",
    "duration",
    "every",
    "EventDataError",
    "ChartActions",
    "ChartStructure",
    "Data",
    "GraphvizMissingError",
    "StateInfo",
    "TemporalLogicError",
    "TickChart",
    "TickChartMeta",
    "TransitionInfo",
    "UnknownDataError",
    "UnknownEventError",
    "after",
    "after_s",
    "does",
    "states_entered_by",
]
