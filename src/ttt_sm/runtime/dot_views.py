"""Which pictures a chart is drawn in: the whole chart, an overview, one per sub-chart (:class:`View`).

A chart whose top level holds compound states (its *sub-charts*: Control's
``start_stop``, ``Drawing_X``, ...) is drawn the way Stateflow shows a chart
with subcharts: an overview with them closed, one picture per sub-chart, and
the whole chart; a live view opens sub-charts in the overview
(:func:`overview_with`).  :mod:`.dot` draws a view.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from statemachine import StateChart

from .diagram import structure_of


@dataclass(frozen=True)
class View:
    """Which part of a chart a picture shows.

    ``key`` names the picture: ``""`` the whole chart, ``"overview"``, or the id of
    the sub-chart (a top-level compound state) it shows alone (``root``).
    ``closed`` are the compound states drawn as closed boxes.
    """

    key: str = ""
    root: str | None = None
    closed: frozenset[str] = frozenset()
    #: sub-charts drawn open in an overview (:func:`overview_with`), for the title
    opened: tuple[str, ...] = ()

    def file_stem(self, chart_name: str) -> str:
        """``Control``, ``Control.overview``, ``Control.Drawing_X``."""
        return f"{chart_name}.{self.key}" if self.key else chart_name

    def title(self, chart_name: str) -> str:
        if self.root is not None:
            return f"{chart_name} — sub-chart {self.root}"
        if self.opened:
            return f"{chart_name} — overview, {', '.join(self.opened)} open"
        if self.closed:
            return f"{chart_name} — overview, sub-charts closed"
        return chart_name


WHOLE = View()
OVERVIEW = "overview"


def subcharts(chart: StateChart | type[StateChart]) -> tuple[str, ...]:
    """Ids of the chart's top-level compound states: its sub-charts."""
    return tuple(s.id for s in structure_of(chart).states if s.parent is None and s.is_compound)


def views(chart: StateChart | type[StateChart]) -> tuple[View, ...]:
    """The pictures of a chart: overview, one per sub-chart, the whole chart.

    A chart without sub-charts has one picture, the whole chart.
    """
    subs = subcharts(chart)
    if not subs:
        return (WHOLE,)
    if OVERVIEW in subs:
        raise ValueError(f"{structure_of(chart).name}: a sub-chart named {OVERVIEW!r} would share"
                         " its picture's name with the overview; rename the state")
    return (View(OVERVIEW, closed=frozenset(subs)), *(View(s, root=s) for s in subs), WHOLE)


def overview_with(chart: StateChart | type[StateChart], opened: Iterable[str] = ()) -> View:
    """The overview with the sub-charts ``opened`` drawn open in place, the others closed.

    Stateflow opens a subchart where it stands; a live view (the browser
    cockpit) offers the same, one picture per set of open sub-charts.
    """
    subs = subcharts(chart)
    wanted = tuple(s for s in subs if s in set(opened))
    unknown = sorted(set(opened) - set(subs))
    if unknown:
        raise ValueError(f"{structure_of(chart).name} has no sub-chart {unknown[0]!r};"
                         f" sub-charts: {', '.join(subs) or 'none'}")
    if not wanted:
        return View(OVERVIEW, closed=frozenset(subs))
    return View("+".join((OVERVIEW, *wanted)), closed=frozenset(subs) - set(wanted), opened=wanted)
