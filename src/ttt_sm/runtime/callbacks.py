"""How a chart's callbacks are called: python-statemachine's conventions at Stateflow's speed.

The engine (:mod:`.engine`) runs a chart's entry, during, exit and
transition actions, and every listener's hooks (``on_enter_state``,
``after_transition``, ...), in Stateflow's order.  :class:`LibraryCallbacks`
(a mixin of :class:`~.engine.Execution`) turns each of the library's callback
keys into one function of a context ``(transition, state, event)``: the
chart's own methods that take no argument are called directly (what keeps a
quiet tick under a microsecond); anything else gets the keyword arguments the
library would pass (``event_data``, ``source``, ``target``, an event's data),
built once per call.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from statemachine.callbacks import allways_true
from statemachine.event import Event
from statemachine.event_data import EventData, TriggerData
from statemachine.state import State
from statemachine.transition import Transition

from .program import Program

Action = Callable[[Any], None]


def no_action(_ctx: Any) -> None:
    return None


class LibraryCallbacks:
    """The library's callbacks of a :class:`~.chart.TickChart` instance, as plain calls (a mixin of it).

    ``_runners`` (in ``__dict__``) keeps one function per callback key; a
    change of listeners forgets them (:meth:`_forget_runners`).
    """

    _program: Program
    _callbacks: Any

    def _runner(self, key: str) -> Action:
        """What the library would call for a callback key, as one function of a context.

        The chart's own methods that take no argument are called directly; anything
        else (a listener's hook, a method asking for ``event_data``) gets the keyword
        arguments the library passes, built once per call from the context
        ``(transition, state, event)``.
        """
        runners = self.__dict__["_runners"]
        run = runners.get(key)
        if run is not None:
            return run  # type: ignore[no-any-return]
        if key not in self._callbacks:
            runners[key] = no_action
            return no_action
        mine = f"@{id(self)}"
        calls: list[tuple[bool, Any]] = []
        for wrapper in self._callbacks[key]:
            fast = None
            name, _, owner = wrapper.unique_key.rpartition("@")
            if wrapper.condition is allways_true and f"@{owner}" == mine and wrapper.expected_value is None:
                bound = getattr(self, name, None)
                if callable(bound) and _takes_no_arguments(bound):
                    fast = bound
            calls.append((True, fast) if fast is not None else (False, wrapper))
        if all(fast for fast, _ in calls):
            fns = tuple(fn for _, fn in calls)
            if len(fns) == 1:
                only = fns[0]

                def run_one(_ctx: Any) -> None:
                    only()

                run = run_one
            else:
                def run_all(_ctx: Any) -> None:
                    for fn in fns:
                        fn()

                run = run_all
        else:
            def run_mixed(ctx: Any) -> None:
                kwargs = None
                for fast_call, item in calls:
                    if fast_call:
                        item()
                    else:
                        if kwargs is None:
                            kwargs = self._kwargs(ctx)
                        if item.condition(**kwargs):
                            item.call(**kwargs)

            run = run_mixed
        runners[key] = run
        return run

    def _kwargs(self, ctx: tuple[Transition | None, State | None, Any]) -> dict[str, Any]:
        """The keyword arguments python-statemachine gives a callback, for a context."""
        transition, state, event = ctx[:3]
        role = ctx[3] if len(ctx) > 3 else None
        d = self.__dict__
        if isinstance(event, str):
            event = self._program.events.get(event) or Event(event)
        trigger = TriggerData(machine=self, event=event, kwargs=dict(d["_event_kwargs"]))  # type: ignore[arg-type]
        if transition is None:
            transition = _NO_TRANSITION
        data = EventData(trigger_data=trigger, transition=transition)
        # as the library does: an entered state is also the `target`, an exited one the `source`
        if state is not None:
            data.state = state
            if role == "enter":
                data.target = state
            elif role == "exit":
                data.source = state
        return data.extended_kwargs

    def _forget_runners(self) -> None:
        """Listeners changed: callbacks are looked up again (and the tick plans rebuilt)."""
        self.__dict__["_runners"].clear()
        self.__dict__["_plans"].clear()
        self.__dict__["_plan_key"] = object()


class _NoTransition:
    """Stands for the transition in the callbacks of an entry or exit that belongs to none (activation)."""

    source = target = None
    internal = False

    def __repr__(self) -> str:
        return "(no transition)"


_NO_TRANSITION: Any = _NoTransition()


def _takes_no_arguments(fn: Callable[..., Any]) -> bool:
    import inspect

    try:
        params = inspect.signature(fn).parameters.values()
    except (TypeError, ValueError):
        return False
    # a parameter, even with a default, may be one the library fills (an event's data, `state`)
    return not params
