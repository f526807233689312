"""What a session runs, described once for the pages: charts, states, transitions, data, signals.

The pages name everything by what the charts declare (``Chart.structure()``,
``Chart.declarations()``) and the robot's signals: a state by its qualified
name (``Control.start_stop.wait_1``, chart then the state's ancestors), a
transition as ``Chart.source->target`` (as ``break transition`` writes it),
with its index in the chart's structure, the number its diagram edge carries
(``tr-<index>``).  Nothing is read from chart code.
"""

from __future__ import annotations

import math
from typing import Any

from ..debug.debugger import Debugger
from ..debug.views import SIGNAL_DOCS, SIGNAL_UNITS
from ..runtime import Data, TickChart
from ..runtime.dot_views import subcharts, views
from ..runtime.structure import ChartStructure

#: Signals that only a simulation has (the twin's ground truth): labelled so in the pages.
SIMULATION_ONLY = ("q_true", "tool_true")


def qualified_names(chart_name: str, structure: ChartStructure) -> dict[str, str]:
    """State id -> qualified name: the chart, then the state's ancestors, then the state."""
    by_id = {s.id: s for s in structure.states}
    out = {}
    for s in structure.states:
        chain = [s.id]
        parent = s.parent
        while parent is not None:
            chain.insert(0, parent)
            parent = by_id[parent].parent
        out[s.id] = ".".join([chart_name, *chain])
    return out


def transition_name(chart_name: str, source: str, target: str | None) -> str | None:
    """``Chart.source->target``, as a transition breakpoint names it (None: a targetless handler)."""
    return None if target is None else f"{chart_name}.{source}->{target}"


def input_placeholder(decl: Data) -> str:
    """What an input's box shows before anything is typed: a typical value of it, with its unit, as
    ``set`` takes it (``0deg`` for an angle, ``20mm/s`` for a speed, ``1 / 0`` for a flag).

    The typical value is the declared default (within the declared limits); angles in degrees and
    lengths in millimetres, as a person types them (:func:`~ttt_sm.debug.names.parse_input_value`).
    """
    unit = decl.unit
    if unit == "bool":
        return "1 / 0"
    value = decl.default
    if not isinstance(value, (int, float)):
        return ""
    if decl.limits is not None and not decl.limits[0] <= value <= decl.limits[1]:
        value = decl.limits[0]
    base, rate = (unit[:-2], "/s") if unit.endswith("/s") else (unit, "")
    if base == "rad":
        return f"{math.degrees(value):.4g}deg{rate}"
    if base == "m":
        return f"{value * 1000:.4g}mm{rate}"
    number = str(value) if isinstance(value, int) else f"{value:.4g}"
    return number if unit in ("1", "") else f"{number}{unit}"


def input_title(decl: Data) -> str:
    """An input box's tooltip: its unit, the units it may be typed in, its limits."""
    if decl.unit == "bool":
        return "a flag: 1 or 0 (true / false)"
    parts = [f"unit {decl.unit}" if decl.unit not in ("1", "") else "a number"]
    base, rate = (decl.unit[:-2], "/s") if decl.unit.endswith("/s") else (decl.unit, "")
    if base == "rad":
        parts.append(f"type deg{rate} or rad{rate}")
    elif base == "m":
        parts.append(f"type mm{rate} or m{rate}")
    if decl.limits is not None:
        parts.append(f"from {decl.limits[0]:g} to {decl.limits[1]:g}")
    return ", ".join(parts)


def describe_datum(d: Data) -> dict[str, Any]:
    """One datum as the pages list it; an input also with its box's placeholder and tooltip."""
    out = {"name": d.name, "kind": d.kind, "unit": d.unit, "doc": d.doc}
    if d.kind == "input":
        out["placeholder"] = input_placeholder(d)
        out["title"] = input_title(d)
    return out


def view_list(chart: TickChart | type[TickChart]) -> list[dict[str, str]]:
    """The pictures of a chart (:func:`~ttt_sm.runtime.dot_views.views`) as the pages offer them."""
    out = []
    cls = chart if isinstance(chart, type) else type(chart)
    for v in views(cls):
        key = v.key or "whole"
        title = {"overview": "overview", "whole": "whole chart"}.get(key, f"{key} on its own")
        out.append({"key": key, "title": title})
    return out


def describe_chart(name: str, chart: TickChart) -> dict[str, Any]:
    """One chart: its states, transitions, data and events, and its pictures."""
    structure = type(chart).structure()
    qnames = qualified_names(name, structure)
    return {
        "name": name,
        "class": type(chart).__name__,
        "doc": (type(chart).__doc__ or "").strip().splitlines()[0] if type(chart).__doc__ else "",
        "states": [{"id": s.id, "qname": qnames[s.id], "parent": s.parent, "compound": s.is_compound,
                    "history": bool(s.history)} for s in structure.states],
        "transitions": [{"index": t.index, "source": t.source, "target": t.target,
                         "name": transition_name(name, t.source, t.target), "label": t.label,
                         "trigger": t.trigger} for t in structure.transitions],
        "data": [describe_datum(d) for d in chart.declarations()],
        "events": list(structure.user_events),
        "subcharts": list(subcharts(type(chart))),
        "views": view_list(chart),
    }


def describe_session(debugger: Debugger) -> dict[str, Any]:
    """Everything static a page needs: the charts (in the robot's order) and the signals."""
    robot = debugger.robot
    signals = []
    for key in robot.signal_values():
        unit = SIGNAL_UNITS.get(key, "")
        signals.append({"name": key, "unit": unit if isinstance(unit, str) else " ".join(unit),
                        "doc": SIGNAL_DOCS.get(key, ""), "simulation_only": key in SIMULATION_ONLY})
    return {
        "charts": [describe_chart(name, chart) for name, chart in robot.charts.items()],
        "signals": signals,
        "dt": robot.params.control.dt,
        "chart_dt": robot.params.control.chart_dt,
        "seed": getattr(debugger.recipe, "seed", None),
        "max_run_s": debugger.max_run_s,
    }
