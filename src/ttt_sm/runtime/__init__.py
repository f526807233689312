"""Generic Stateflow-clock layer over python-statemachine: no robot code here.

Charts subclass :class:`TickChart`, declare their data with :class:`Data`, use
:func:`after` / :func:`after_s` as temporal guards, and are observed through
listeners (:class:`Trace`, :class:`Coverage`).  :mod:`.diagram` draws them.
"""

from .chart import TickChart, TickChartMeta
from .data import Data
from .errors import (
    ChartDefinitionError,
    GraphvizMissingError,
    GuardMismatchError,
    TemporalLogicError,
    UnknownDataError,
    UnknownEventError,
)
from .structure import ChartStructure, StateInfo, TransitionInfo, priority_conflicts, states_entered_by
from .temporal import after, after_s

__all__ = [
    "ChartDefinitionError",
    "ChartStructure",
    "Data",
    "GraphvizMissingError",
    "GuardMismatchError",
    "StateInfo",
    "TemporalLogicError",
    "TickChart",
    "TickChartMeta",
    "TransitionInfo",
    "UnknownDataError",
    "UnknownEventError",
    "after",
    "after_s",
    "priority_conflicts",
    "states_entered_by",
]
