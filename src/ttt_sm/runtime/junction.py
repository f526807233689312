"""Connective junctions: Stateflow's decision points, declared like states.

A :class:`Junction` is written among the states it sits between and joined to
them with ordinary transitions, so a chart with a decision reads like its
Stateflow picture::

    class Dispatch(TickChart):
        idle = State(initial=True)
        fast = State()
        slow = State()
        j = Junction()

        go = idle.to(j, before="count")    # go{count}: on event go, a condition action
        j.to(fast, cond="speed > 1")       # 1: [speed > 1]
        j.to(slow)                         # 2: otherwise

A junction is never active: the runtime follows a path through it within one
transition (docs/runtime.md, "Junctions").  Its outgoing segments are tried
in the order written; a junction with none is a *terminal junction* (the end
of a flow chart).  ``Junction(initial=True)`` is the target of a compound
state's default transition, for a default transition that decides (or that
has actions).

To python-statemachine a junction is a state (a subclass of ``State``): that
is what lets ``.to()`` reach it and keeps its diagrams, listeners and graph
checks working.  The runtime never puts one in the configuration.
"""

from __future__ import annotations

from typing import Any

from statemachine import State


class Junction(State):
    """A connective junction: a point where transition segments meet and decide."""

    is_junction = True

    def __init__(self, name: str = "", initial: bool = False, **kwargs: Any) -> None:
        if kwargs.keys() - {"value"}:
            raise TypeError(f"Junction() takes a name and initial= only, not {', '.join(sorted(kwargs))}")
        super().__init__(name=name, initial=initial, **kwargs)


def is_junction(state: Any) -> bool:
    """Whether `state` (a library state) is a :class:`Junction`."""
    return getattr(state, "is_junction", False) is True
