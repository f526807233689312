"""A chart's inputs and events, from the chart cockpit: set or forced, released, posted (all recorded)."""

from __future__ import annotations

from typing import Any

from ...debug.views import fmt_value
from ..fields import event_data, flag, identifier, optional, scalar
from .spec import Cockpit, Reply, command


@command("set", chart=identifier, name=identifier, value=scalar, force=optional(flag, False))
def set_input(session: Cockpit, cid: int, chart: str, name: str, value: Any, force: bool) -> Reply:
    """Set (or with ``force``: hold) input ``chart.name`` to ``value``, text as typed, a number or a flag."""
    typed = ("1" if value else "0") if isinstance(value, bool) else str(value)
    got = session.debugger.set_input(chart, name, typed, force=force)
    decl = session.debugger.datum_decl(chart, name)
    return {"text": f"{'forced' if force else 'set'} {chart}.{name} = {fmt_value(got, decl.unit)}"}


@command("release", chart=optional(identifier), name=optional(identifier))
def release(session: Cockpit, cid: int, chart: str | None, name: str | None) -> Reply:
    """Release one forced input (``chart`` and ``name``), or all of them (neither)."""
    if (chart is None) != (name is None):
        raise ValueError("give both 'chart' and 'name' to release one input, or neither to release all")
    released = session.debugger.release(chart, name)
    return {"text": "released " + (", ".join(f"{c}.{n}" for c, n in released) or "nothing")}


@command("post", chart=identifier, event=identifier, data=optional(event_data, {}))
def post(session: Cockpit, cid: int, chart: str, event: str, data: dict[str, Any]) -> Reply:
    """Post event ``event`` to ``chart`` with ``data`` {name: number/text/flag}."""
    session.debugger.chart(chart)
    # As `post CHART EVENT NAME=VALUE` in ttt-sm debug: a number where it reads as one.
    data = {k: _number_or_text(v) for k, v in data.items()}
    session.debugger.post(chart, event, **data)
    return {"text": f"posted {chart} {event}" + "".join(f" {k}={v}" for k, v in data.items())}


def _number_or_text(value: Any) -> Any:
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            return value
    return value
