"""``on`` actions of a state, declared like transitions: Stateflow's ``on E: action``.

In Stateflow a state lists what it does on an event without leaving
(``on button: ignored++``) or on a temporal condition (``on after(3, tick):
blink``).  Here that is :func:`action_on`::

    button = wait.to(drawing, cond="ready") | action_on(busy, "ignore_button")
    action_on(blinking, "toggle", cond=every(5))

It runs in the state's during phase: after the state's during action, when
the chart wakes on that event (or, without an event, at any wake-up) and its
condition holds; the state is neither left nor entered.  To python-statemachine
it is a transition without a target, which is how the diagrams list it inside
its state.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from statemachine.state import State
from statemachine.transition_list import TransitionList


def action_on(states: State | type | Sequence[State | type], action: str | Callable[..., Any],
              cond: Any = None) -> TransitionList:
    """The ``on`` action of a state (or of each of several): run `action` in its during phase when
    the event (or `cond`) matches.

    Assign it to an event name (``button = action_on(busy, "ignore_button")``, or
    joined with ``|`` to that event's transitions) for ``on button:``; leave it
    unassigned with a temporal `cond` for ``on after(3, tick):`` or ``on every(...)``.
    """
    # (a compound state written as a class body is a State to the library, a type to a type checker)
    many = [states] if isinstance(states, (State, type)) else list(states)
    if not many or not all(isinstance(s, State) for s in many):
        raise TypeError(f"action_on(states, action): {states!r} is not a state or a sequence of states")
    kwargs: dict[str, Any] = {"on": action}
    if cond is not None:
        kwargs["cond"] = cond
    result = TransitionList()
    for state in many:
        result = result | state.to(None, **kwargs)  # type: ignore[arg-type,union-attr]  # a targetless transition
    return result
