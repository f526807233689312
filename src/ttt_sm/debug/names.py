"""The robot's charts, data and signals by name: what commands and conditions check and read."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from ..app.robot import Robot
from ..runtime import Data
from ..runtime.conditions import UNITS
from ..runtime.errors import suggest
from .errors import DebugError


def datum_decl(robot: Robot, chart: str, name: str) -> Data:
    """The declaration of a chart datum; :class:`DebugError` lists the charts or data there are."""
    c = robot.charts.get(chart)
    if c is None:
        raise DebugError(f"no chart {chart!r}{suggest(chart, robot.charts)};"
                         f" charts: {', '.join(robot.charts)}")
    decls = {d.name: d for d in c.declarations()}
    if name not in decls:
        raise DebugError(f"{chart} has no datum {name!r}{suggest(name, decls)}; data: {', '.join(decls)}")
    return decls[name]


def parse_input_value(decl: Data, label: str, text: str) -> Any:
    """A value typed for a datum: ``1``/``0``/``true``/``false``/``on``/``off`` for flags,
    else a number with an optional unit (``170deg``, ``20mm``, a rate ``20mm/s``, the datum's own
    unit ``0.5A``), converted to SI."""
    word = text.strip().lower()
    if decl.unit == "bool":
        flags = {"1": True, "0": False, "true": True, "false": False, "on": True, "off": False}
        if word not in flags:
            raise DebugError(f"{label} is a flag: give 1 or 0 (true/false), not {text!r}")
        return flags[word]
    own = decl.unit.lower()
    if own.endswith("/s") and word.endswith("/s"):  # a rate typed with its time unit: 20mm/s, 5deg/s
        word, own = word[:-2].rstrip(), own[:-2]
    if own not in UNITS and own not in ("1", "") and word.endswith(own):  # its own unit, SI already: 0.5A
        word = word[:-len(own)].rstrip()
    number, factor = word, 1.0
    for suffix in sorted(UNITS, key=len, reverse=True):
        if word.endswith(suffix):
            number, factor = word[:-len(suffix)].strip(), UNITS[suffix]
            break
    try:
        value = float(number) * factor
    except ValueError:
        raise DebugError(f"{label} ({decl.unit}): {text!r} is not a number"
                         f" (units: {', '.join(UNITS)})") from None
    if not math.isfinite(value):
        raise DebugError(f"{label} ({decl.unit}): {text!r} is not a finite number")
    if isinstance(decl.default, int) and not isinstance(decl.default, bool) and value.is_integer():
        return int(value)
    return value


class RobotNames:
    """Chart data and signals of the current robot, for conditions (see :mod:`.expr`).

    ``robot`` is asked for the robot at each use: a replay replaces it.
    Signals are read once per control step, and only if a condition names one.
    """

    def __init__(self, robot: Callable[[], Robot]) -> None:
        self._robot = robot
        self._signals: dict[str, Any] | None = None
        self._signals_at = -1

    def check_datum(self, chart: str, name: str) -> None:
        datum_decl(self._robot(), chart, name)

    def check_signal(self, name: str, index: int | None) -> None:
        signals = self._values()
        if name not in signals:
            data = {d.name for c in self._robot().charts.values() for d in c.declarations()}
            hint = " (chart data are written Chart.datum)" if name in data else suggest(name, signals)
            raise DebugError(f"no signal {name!r}{hint}; signals: {', '.join(signals)}")
        value = signals[name]
        if index is not None:
            if not isinstance(value, (list, tuple)):
                raise DebugError(f"signal {name!r} is a single value: write it without [{index}]")
            if not 1 <= index <= len(value):
                raise DebugError(f"{name}[{index}] does not exist: {name} has elements"
                                 f" 1..{len(value)} (numbered from 1, as the joints)")
        elif isinstance(value, (list, tuple)):
            raise DebugError(f"signal {name!r} has {len(value)} elements: pick one,"
                             f" e.g. {name}[1] (numbered from 1, as the joints)")

    def datum(self, chart: str, name: str) -> Any:
        return self._robot().charts[chart].data_mapping()[name]

    def signal(self, name: str, index: int | None) -> Any:
        value = self._values()[name]
        return value if index is None else value[index - 1]

    def _values(self) -> dict[str, Any]:
        robot = self._robot()
        if self._signals is None or self._signals_at != robot.steps:
            self._signals = robot.signal_values()
            self._signals_at = robot.steps
        return self._signals

    def forget(self) -> None:
        """Read the signals afresh at the next use (the robot was changed or replaced)."""
        self._signals = None
