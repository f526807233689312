"""Back in time, on the chart cockpit: replay to a chart tick (the time slider), a chart's timeline."""

from __future__ import annotations

from ...debug.errors import DebugError
from ..fields import flag, identifier, integer, number, optional
from .spec import Cockpit, Reply, command


@command("replay", tick=integer(0, 10**9), drop=optional(flag, False))
def replay(session: Cockpit, cid: int, tick: int, drop: bool) -> Reply:
    """Go back (or forward, as far as the run has been) to chart tick ``tick``: the run replayed from power-on.

    The inputs given after ``tick`` are kept and applied again when the run reaches them (as ``replay`` in
    ``ttt-sm debug``); ``drop``: they are dropped (``replay --drop``)."""
    dbg = session.debugger
    if tick > dbg.furthest_tick:
        raise DebugError(f"replay: chart tick {tick} lies beyond where this session has been (chart tick"
                         f" {dbg.furthest_tick}); replay goes back, run goes forward")
    session.mode = "paused"
    session.last_stop = {"kind": "replaying", "text": f"replaying to chart tick {tick} ...", "tick": tick,
                         "hits": []}
    session.publish()
    with session.robot_replaced(replaying=True):
        result = dbg.replay(tick, drop=drop)
    session.last_stop = {"kind": "replay", "text": result.describe(), "tick": result.tick, "hits": []}
    return {"text": result.describe(), "identical": result.identical}


@command("timeline", chart=identifier, seconds=optional(number(0.01, 3600.0), 20.0))
def timeline(session: Cockpit, cid: int, chart: str, seconds: float) -> None:
    """When ``chart``'s states were active in the last ``seconds``: a ``timeline`` message to this page."""
    window = session.debugger.timeline(chart, seconds)
    qnames = {s["id"]: s["qname"] for c in session.info["charts"] if c["name"] == chart for s in c["states"]}
    rows: dict[str, list[tuple[int, int | None]]] = {}
    for state in session.debugger.state_history.states(chart):
        rows[state] = []
    for iv in window.intervals:
        rows.setdefault(iv.state, []).append((max(iv.entered, window.first), iv.left))
    session.send_to(cid, {"type": "timeline", "chart": chart, "first": window.first, "last": window.last,
                          "period_s": window.period_s, "dropped": window.dropped,
                          "rows": [{"state": st, "qname": qnames.get(st, st), "intervals": ivs}
                                   for st, ivs in rows.items() if ivs]})
