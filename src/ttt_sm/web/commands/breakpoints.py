"""Breakpoints, as ``ttt-sm debug`` writes them: added, deleted, switched on and off."""

from __future__ import annotations

from ..fields import bp_id, flag, integer, text
from .spec import Cockpit, Reply, command


@command("break", spec=text())
def add(session: Cockpit, cid: int, spec: str) -> Reply:
    """A breakpoint (``enter Control.wait_1``, ``when q_true[1] > 90deg``); the reply says its number."""
    bp = session.debugger.add_breakpoint(spec)
    return {"text": f"breakpoint {bp.id}: {bp.spec}", "breakpoint": bp.id}


@command("break_delete", breakpoint=bp_id)
def delete(session: Cockpit, cid: int, breakpoint: int | None) -> Reply:
    """Delete breakpoint ``breakpoint``, or ``"all"`` of them."""
    session.debugger.delete(breakpoint)
    return {"text": "all breakpoints deleted" if breakpoint is None else f"breakpoint {breakpoint} deleted"}


@command("break_enable", breakpoint=integer(1, 10**9), enabled=flag)
def enable(session: Cockpit, cid: int, breakpoint: int, enabled: bool) -> Reply:
    """Switch breakpoint ``breakpoint`` on (``enabled``: true) or off."""
    session.debugger.enable(breakpoint, enabled)
    return {"text": f"breakpoint {breakpoint} {'enabled' if enabled else 'disabled'}"}
