"""Building a chart class: what :class:`TickChartMeta` adds to python-statemachine's when a chart is defined.

When a :class:`~.chart.TickChart` subclass is defined, its metaclass lets the
library build the chart, then tags the transitions without an event as tick
transitions, reads the chart's structure and its data declarations, compiles
its program (:mod:`.program`), checks that every ``during_<state>`` names a
state, lays out the buffered data in slots and guards each state name
against assignment (:class:`_StateName`).
"""

from __future__ import annotations

from typing import Any

from statemachine.exceptions import StateMachineError
from statemachine.factory import StateMachineMetaclass

from .data import PREVIOUS_SUFFIX, buffers, collect_declarations, make_slot
from .errors import ChartDefinitionError
from .plan import previous_copier
from .program import build_program
from .structure import DURING_PREFIX, ChartStructure, build_structure, tag_tick_transitions


class TickChartMeta(StateMachineMetaclass):
    """Builds the library's chart, then tags tick transitions and reads data and structure."""

    def __init__(cls, name: str, bases: tuple[type], attrs: dict[str, Any]) -> None:
        super().__init__(name, bases, attrs)
        if not cls.states:  # the abstract TickChart itself
            return
        tag_tick_transitions(cls)  # type: ignore[arg-type]
        structure = build_structure(cls)  # type: ignore[arg-type]
        decls = collect_declarations(cls)
        _check_during_names(cls, structure)
        cls._structure = structure
        cls._program = build_program(cls, structure)
        events = getattr(cls, "_events", {})
        for state in structure.states:
            # (a state named like an event is reached through the event, as in the library)
            if state.id not in events and not isinstance(cls.__dict__.get(state.id), _StateName):
                setattr(cls, state.id, _StateName(state.id, getattr(cls, state.id, state)))
        cls._data_decls = decls
        cls._prev_pairs = tuple(
            (d.name, d.name + PREVIOUS_SUFFIX) for d in decls if d.kind == "output"
        )
        slots: dict[str, int] = {}
        if cls.buffered:  # type: ignore[attr-defined]
            for decl in decls:
                if buffers(decl):
                    names = [decl.name] + [decl.name + PREVIOUS_SUFFIX] * (decl.kind == "output")
                    for datum in names:
                        slots[datum] = len(slots)
                        setattr(cls, datum, make_slot(decl, slots[datum], name, datum))
        cls._slots = slots
        cls._slot_prev_pairs = tuple((slots[o], slots[p]) for o, p in cls._prev_pairs if o in slots)
        cls._dict_prev_pairs = tuple((o, p) for o, p in cls._prev_pairs if o not in slots)
        cls._copy_previous = staticmethod(previous_copier(name, cls._dict_prev_pairs, cls._slot_prev_pairs))


def _check_during_names(cls: type, structure: ChartStructure) -> None:
    state_ids = {s.id for s in structure.states}
    for attr in dir(cls):
        if attr.startswith(DURING_PREFIX) and callable(getattr(cls, attr, None)):
            if attr[len(DURING_PREFIX):] not in state_ids:
                raise ChartDefinitionError(
                    f"{cls.__name__}.{attr}: no state {attr[len(DURING_PREFIX):]!r} to run it in;"
                    f" states: {', '.join(sorted(state_ids))}"
                )


class _StateName:
    """A chart class's attribute named after a state: reads as the state, refuses assignment.

    python-statemachine refuses ``chart.some_state = value`` in a Python-level
    ``__setattr__``, which every attribute assignment then pays for (0.4 us:
    during actions assign outputs on every tick).  A data descriptor per state
    name gives the same protection and leaves every other assignment plain.
    """

    __slots__ = ("name", "state")

    def __init__(self, name: str, state: Any) -> None:
        self.name = name
        self.state = state

    def __get__(self, instance: Any, owner: type | None = None) -> Any:
        if instance is None:
            return self.state
        # the library keeps each instance's own copy of the state in its __dict__
        return instance.__dict__.get(self.name, self.state)

    def __set__(self, instance: Any, value: Any) -> None:
        raise StateMachineError(
            f"State overriding is not allowed. Trying to add {value!r} to {self.name}")
