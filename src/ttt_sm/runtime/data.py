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
    """

    name: str
    unit: str = "1"
    default: Any = 0.0
    doc: str = ""
    kind: Kind | Literal[""] = field(default="", compare=False)

    def fresh_default(self) -> Any:
        """The default value, copied when it is mutable."""
        value = self.default
        if isinstance(value, (int, float, str, bool, bytes, type(None), complex, tuple, frozenset)):
            return value
        return copy.deepcopy(value)


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
    if hasattr(cls, name):
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
