"""A real-time scheduling priority for a loop that must keep its period, as a board's control loop does."""

from __future__ import annotations

import os


def realtime_priority(priority: int = 10) -> str | None:
    """Run this process's threads (those made from now on, too) at ``SCHED_FIFO`` `priority`, as a board's
    control loop runs before anything else.  Linux only, with the right (root or ``CAP_SYS_NICE``); returns
    None when it took, else why not.  The loops it is for wait in ``select``: they do not spin."""
    setter = getattr(os, "sched_setscheduler", None)
    if setter is None:
        return "no SCHED_FIFO on this system"
    try:
        setter(0, os.SCHED_FIFO, os.sched_param(priority))
    except (OSError, ValueError) as exc:
        return f"SCHED_FIFO refused: {getattr(exc, 'strerror', None) or exc}"
    return None


__all__ = ["realtime_priority"]
