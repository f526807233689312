"""Declared chart data: inputs, outputs and local data with name, unit, default and doc.

A chart lists its data in three class attributes, as Stateflow's Model Explorer
does::

    inputs = (Data("pos_in", "rad", 0.0, "joint coordinate to pass through"),)
    outputs = (Data("pos_out", "rad", 0.0, "joint setpoint"),)
    local = (Data("n", "1", 0, "ticks spent searching"),)

Each datum is a plain attribute of the chart instance (``chart.pos_in``), so guards
and actions read like the thesis' equations.  Every output ``X`` also has ``X_p``,
its value one chart tick earlier, so a during action writes ``X = X_p + inc``.
A debugger, a trace or a GUI lists the declarations with :func:`declarations`
without reading code.

A chart class with ``buffered = True`` keeps its numeric data (a number or a
flag by default: every datum but text) in one float buffer instead of plain
attributes, each datum a :class:`Slot` of it: chart code still reads and
writes ``chart.err_1``, and compiled code of the chart's wiring reads and
writes the same numbers in place (:meth:`TickChart.data_buffer`,
:meth:`TickChart.data_slots`), with no Python assignment per datum and chart
step (docs/runtime.md, "Data in a buffer").
"""

from __future__ import annotations

import copy
import keyword
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any, Literal

from .errors import ChartDefinitionError

Kind = Literal["input", "output", "local"]

#: Class attribute that holds the declarations of each kind.
KIND_ATTRS: dict[Kind, str] = {"input": "inputs", "output": "outputs", "local": "local"}

#: Suffix of the attribute holding an output's value one chart tick earlier.
PREVIOUS_SUFFIX = "_p"

#: Instance attributes of a chart (python-statemachine's and the runtime's): not data names.
RESERVED_NAMES = frozenset({
    "model", "state_field", "history_values", "start_configuration_values", "chart_name",
})


@dataclass(frozen=True)
class Data:
    """One datum of a chart: what a debugger shows for it.

    Parameters
    ----------
    name : str
        Attribute name on the chart, as in the thesis (``X_out``, ``ini_23``).
    unit : str
        SI unit (``"m"``, ``"rad"``, ``"s"``), ``"1"`` for counts, ``"bool"`` for flags.
    default : Any
        Value at construction and after :meth:`TickChart.reset_data`.  Mutable defaults
        are copied, so instances never share a list.
    doc : str
        One line saying what the datum means.
    kind : {"input", "output", "local"}
        Filled in by the chart class from the attribute the datum is listed in.
    limits : (low, high), optional
        The values an input may be given from outside (the debugger's ``set`` and
        ``force``, the cockpit's): one beyond them is refused, not taken to a state
        the chart cannot leave (a cell's row of 1e12).  The wiring is not checked.
    """

    name: str
    unit: str = "1"
    default: Any = 0.0
    doc: str = ""
    kind: Kind | Literal[""] = field(default="", compare=False)
    limits: tuple[float, float] | None = field(default=None, compare=False)

    def fresh_default(self) -> Any:
        """The default value, copied when it is mutable."""
        value = self.default
        if isinstance(value, (int, float, str, bool, bytes, type(None), complex, tuple, frozenset)):
            return value
        return copy.deepcopy(value)


def buffers(decl: Data) -> bool:
    """Whether a buffered chart keeps `decl` in its float buffer: a number or a flag by default."""
    return type(decl.default) in (bool, int, float)


class Slot:
    """A datum of a buffered chart: reads and writes its place in the chart's float buffer.

    A data descriptor of the chart class, so it takes the place of the plain
    attribute; the chart instance's ``_data_view`` (a memoryview of the buffer)
    holds the number.  A float datum reads as the float, a flag as a bool, a
    count as an int.  Only a real number (or a bool) can be written.
    """

    __slots__ = ("name", "index", "owner")

    def __init__(self, name: str, index: int, owner: str) -> None:
        self.name = name
        self.index = index
        self.owner = owner

    def __get__(self, instance: Any, owner: type | None = None) -> Any:
        if instance is None:
            return self
        return instance.__dict__["_data_view"][self.index]

    def __set__(self, instance: Any, value: Any) -> None:
        try:
            instance.__dict__["_data_view"][self.index] = value
        except TypeError:
            raise TypeError(f"{self.owner}.{self.name} is a number in the chart's data buffer;"
                            f" got {value!r} ({type(value).__name__})") from None


class BoolSlot(Slot):
    """A flag of a buffered chart: 1.0 or 0.0 in the buffer, True or False to read."""

    __slots__ = ()

    def __get__(self, instance: Any, owner: type | None = None) -> Any:
        if instance is None:
            return self
        return instance.__dict__["_data_view"][self.index] != 0.0


class IntSlot(Slot):
    """A count of a buffered chart: an exact integer in the buffer (to 2**53), an int to read."""

    __slots__ = ()

    def __get__(self, instance: Any, owner: type | None = None) -> Any:
        if instance is None:
            return self
        return int(instance.__dict__["_data_view"][self.index])


def make_slot(decl: Data, index: int, owner: str, name: str | None = None) -> Slot:
    """The slot of `decl` (or of its previous value `name`) at `index` of the buffer."""
    kind = type(decl.default)
    cls = BoolSlot if kind is bool else IntSlot if kind is int else Slot
    return cls(name or decl.name, index, owner)


def collect_declarations(cls: type) -> tuple[Data, ...]:
    """Read and check the data declarations of a chart class, kinds filled in.

    Raises
    ------
    ChartDefinitionError
        If an entry is not a :class:`Data`, a name is not an identifier, a name is
        declared twice, or a name (or an output's ``_p`` name) clashes with a state,
        an event or another attribute of the chart.
    """
    decls: list[Data] = []
    seen: dict[str, str] = {}
    for kind, attr in KIND_ATTRS.items():
        entries = getattr(cls, attr, ()) or ()
        if isinstance(entries, Data):
            entries = (entries,)
        for entry in entries:
            if not isinstance(entry, Data):
                raise ChartDefinitionError(
                    f"{cls.__name__}.{attr}: {entry!r} is not a Data(name, unit, default, doc)"
                )
            _check_name(cls, entry.name, attr, seen)
            if kind == "output":
                _check_name(cls, entry.name + PREVIOUS_SUFFIX, attr, seen)
            decls.append(replace(entry, kind=kind))
    return tuple(decls)


def _check_name(cls: type, name: str, attr: str, seen: dict[str, str]) -> None:
    where = f"{cls.__name__}.{attr}"
    if not isinstance(name, str) or not name.isidentifier() or keyword.iskeyword(name):
        raise ChartDefinitionError(f"{where}: data name {name!r} is not a Python identifier")
    if name.startswith("_"):
        raise ChartDefinitionError(f"{where}: data name {name!r} must not start with '_'")
    if name in seen:
        raise ChartDefinitionError(f"{where}: data name {name!r} is already declared in {seen[name]}")
    if name in RESERVED_NAMES:
        raise ChartDefinitionError(f"{where}: data name {name!r} is used by the chart itself; rename it")
    states_map = getattr(cls, "states_map", {})
    if any(getattr(s, "id", None) == name for s in states_map.values()):
        raise ChartDefinitionError(f"{where}: data name {name!r} is also a state; rename one")
    if hasattr(cls, name) and not isinstance(cls.__dict__.get(name, getattr(cls, name)), Slot):
        raise ChartDefinitionError(
            f"{where}: data name {name!r} clashes with the chart attribute {cls.__name__}.{name}"
            " (a method, event or class attribute); rename one"
        )
    seen[name] = where


def check_values(cls_name: str, decls: Iterable[Data], values: Mapping[str, Any], kinds: set[str]) -> None:
    """Raise :class:`UnknownDataError` if ``values`` names data not declared with one of ``kinds``."""
    from .errors import UnknownDataError

    known = {d.name for d in decls if d.kind in kinds}
    unknown = sorted(set(values) - known)
    if unknown:
        raise UnknownDataError(
            f"{cls_name} declares no {'/'.join(sorted(kinds))} named {', '.join(unknown)};"
            f" declared: {', '.join(sorted(known)) or '(none)'}"
        )
