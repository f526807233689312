"""Exceptions of the chart runtime: each says what was wrong, where, and what to do."""

from __future__ import annotations

import difflib
from collections.abc import Iterable

from statemachine.exceptions import InvalidDefinition


def suggest(word: object, options: Iterable[str]) -> str:
    """`` (did you mean 'x'?)`` for a near miss of ``word`` among ``options``, else ``""``.

    The one name-suggestion helper of the package: the debugger and the
    scenario loader name a chart, state, event or datum the same way.
    """
    if not isinstance(word, str) or len(word) > 100:  # no name is that long: nothing to compare
        return ""
    close = difflib.get_close_matches(word, list(options), n=1, cutoff=0.6)
    return f" (did you mean {close[0]!r}?)" if close else ""


class ChartDefinitionError(InvalidDefinition):
    """A chart class is declared wrongly (data names, during actions, temporal guards).

    Raised when the class is created, so a typo shows at import time, not mid-run.
    It is an ``InvalidDefinition`` of python-statemachine, so code that catches the
    library's definition errors catches ours too.
    """


class UnknownEventError(KeyError):
    """An event was posted to a chart that has no transition for it."""

    def __str__(self) -> str:  # KeyError would print the message in quotes
        return str(self.args[0]) if self.args else ""


class EventDataError(UnknownEventError):
    """An event's data under a name the chart's callbacks cannot take (one python-statemachine gives them
    itself: :data:`~ttt_sm.runtime.chart.RESERVED_EVENT_DATA`)."""


class UnknownDataError(KeyError):
    """A data name was given that the chart does not declare."""

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""


class TemporalLogicError(RuntimeError):
    """A temporal guard cannot be evaluated, e.g. ``after_s`` on a chart without a tick period."""


class ChartExecutionError(RuntimeError):
    """A chart cannot go on as Stateflow would: no valid default transition, endless local events."""


class GraphvizMissingError(RuntimeError):
    """Graphviz ``dot`` is needed for SVG/PNG output and is not installed."""
