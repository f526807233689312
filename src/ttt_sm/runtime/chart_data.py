"""A chart's declared data, read and written by name: inputs, outputs (and their values a tick ago), locals.

A mixin of :class:`~.chart.TickChart`.  The declarations are collected once per
chart class (:mod:`.data`); a *buffered* chart keeps its numbers in one float
buffer that compiled code reads in place, and :meth:`ChartData.data_mapping`
shows either kind as one mapping by name.
"""

from __future__ import annotations

from array import array
from collections.abc import Iterator, MutableMapping
from typing import Any, ClassVar

from .data import PREVIOUS_SUFFIX, Data, check_values
from .structure import ChartStructure


class ChartData:
    """The declared data of a :class:`~.chart.TickChart` (a mixin of it), and its structure, by name."""

    # what the chart class gives the mixin (its metaclass fills them in per chart class)
    chart_name: str
    _structure: ClassVar[ChartStructure]
    _data_decls: ClassVar[tuple[Data, ...]] = ()
    _prev_pairs: ClassVar[tuple[tuple[str, str], ...]] = ()
    _slots: ClassVar[dict[str, int]] = {}

    @classmethod
    def declarations(cls) -> tuple[Data, ...]:
        """The chart's inputs, outputs and local data, in declaration order."""
        return cls._data_decls

    @classmethod
    def structure(cls) -> ChartStructure:
        """States and transitions of the chart, as diagrams and coverage read them."""
        return cls._structure

    def snapshot(self, kinds: tuple[str, ...] = ("input", "output", "local")) -> dict[str, Any]:
        """Current values of the declared data of the given kinds, by name."""
        d = self.data_mapping()
        return {decl.name: d[decl.name] for decl in self._data_decls if decl.kind in kinds}

    def previous_outputs(self) -> dict[str, Any]:
        """Each output's value one chart tick earlier, by output name."""
        d = self.data_mapping()
        return {name: d[prev] for name, prev in self._prev_pairs}

    def set_inputs(self, **values: Any) -> None:
        """Set inputs by name; an unknown name raises :class:`UnknownDataError`."""
        check_values(type(self).__name__, self._data_decls, values, {"input"})
        self.data_mapping().update(values)

    def reset_data(self, kinds: tuple[str, ...] = ("input", "output", "local")) -> None:
        """Put the declared data of the given kinds back to their defaults."""
        for decl in self._data_decls:
            if decl.kind in kinds:
                setattr(self, decl.name, decl.fresh_default())
                if decl.kind == "output":
                    setattr(self, decl.name + PREVIOUS_SUFFIX, decl.fresh_default())

    def data_mapping(self) -> MutableMapping[str, Any]:
        """The chart's data (and each output's previous value) as a mapping by name, read and written live.

        The instance's ``__dict__`` itself, where the data are plain attributes; for a
        buffered chart, a view that reads and writes its buffer's numbers by name.
        """
        return self.__dict__ if not self._slots else _BufferedData(self)

    def data_buffer(self) -> array:
        """A buffered chart's float buffer (``array('d')``): :meth:`data_slots` says which datum is where.

        Compiled code wraps it without a copy (``numpy.frombuffer``) and reads and writes
        the chart's numbers in place; a flag is 1.0 or 0.0.
        """
        if not self._slots:
            raise TypeError(f"{self.chart_name}: the chart is not buffered (buffered = True keeps its"
                            " numbers in one buffer)")
        return self.__dict__["_data_buffer"]  # type: ignore[no-any-return]

    @classmethod
    def data_slots(cls) -> dict[str, int]:
        """Where each number of a buffered chart lies in :meth:`data_buffer`, by datum (``X_p`` too)."""
        return dict(cls._slots)


class _BufferedData(MutableMapping[str, Any]):
    """A buffered chart's data as a mapping: a number by its slot, anything else in the instance dict."""

    __slots__ = ("_chart", "_d")

    def __init__(self, chart: ChartData) -> None:
        self._chart = chart
        self._d = chart.__dict__

    def __getitem__(self, name: str) -> Any:
        if name in self._chart._slots:
            return getattr(self._chart, name)
        return self._d[name]

    def __setitem__(self, name: str, value: Any) -> None:
        if name in self._chart._slots:
            setattr(self._chart, name, value)
        else:
            self._d[name] = value

    def __delitem__(self, name: str) -> None:
        raise TypeError(f"{self._chart.chart_name}: a chart's data cannot be deleted ({name})")

    def __contains__(self, name: object) -> bool:
        return name in self._chart._slots or name in self._d

    def __iter__(self) -> Iterator[str]:
        yield from self._chart._slots
        yield from (k for k in self._d if k not in self._chart._slots)

    def __len__(self) -> int:
        return len(self._chart._slots) + sum(k not in self._chart._slots for k in self._d)
