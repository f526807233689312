"""Tab completion of the ``ttt-sm debug`` commands on a terminal: breakpoint kinds, ``Chart.state``,
``Chart.event``, ``Chart.datum`` and chart names from the robot the session runs, mixed into
:class:`~.shell.DebugShell` (:mod:`cmd` calls ``complete_COMMAND``).
"""

from __future__ import annotations

from collections.abc import Iterable

from .debugger import Debugger

#: What ``show`` shows (completed after ``show``).
SHOW = ("charts", "data", "signals", "trace", "breakpoints", "inputs", "snapshot", "timeline", "game")


class Completion:
    """``complete_*`` for :class:`~.shell.DebugShell`."""

    dbg: Debugger

    def _states(self) -> list[str]:
        index = self.dbg.watch.index
        return [f"{c}.{s}" for c in self.dbg.chart_names for s in index.states(c)]

    def _data(self, inputs_only: bool = False) -> list[str]:
        out = []
        for name, chart in self.dbg.robot.charts.items():
            out += [f"{name}.{d.name}" for d in chart.declarations() if not inputs_only or d.kind == "input"]
        return out

    def _events(self) -> list[str]:
        index = self.dbg.watch.index
        return [f"{c}.{e}" for c in self.dbg.chart_names for e in index.events(c)]

    @staticmethod
    def _matching(text: str, names: Iterable[str]) -> list[str]:
        return [n for n in names if n.startswith(text)]

    def complete_break(self, text: str, line: str, begidx: int, endidx: int) -> list[str]:
        """Tab: the kind, then Chart.state (enter, exit), Chart.event, Chart.datum (when), a state (transition)."""
        words = line[:begidx].split()
        if len(words) <= 1:
            return self._matching(text, ("enter", "exit", "transition", "event", "when"))
        kind = words[1]
        if kind in ("enter", "exit"):
            return self._matching(text, self._states())
        if kind == "event":
            return self._matching(text, self._events())
        if kind == "when":
            return self._matching(text, self._data())
        if kind == "transition":
            if len(words) == 2:
                return self._matching(text, self.dbg.chart_names)
            return self._matching(text, [*self.dbg.watch.index.states(words[2]), "*"]) \
                if words[2] in self.dbg.chart_names else []
        return []

    def complete_display(self, text: str, line: str, begidx: int, endidx: int) -> list[str]:
        return self._matching(text, self._data())

    complete_watch = complete_display

    def complete_set(self, text: str, line: str, begidx: int, endidx: int) -> list[str]:
        return self._matching(text, self._data(inputs_only=True)) if len(line[:begidx].split()) <= 1 else []

    complete_force = complete_release = complete_set

    def complete_show(self, text: str, line: str, begidx: int, endidx: int) -> list[str]:
        words = line[:begidx].split()
        if len(words) <= 1:
            return self._matching(text, SHOW)
        return self._matching(text, self.dbg.chart_names) if words[1] in ("data", "timeline") else []

    def complete_diagram(self, text: str, line: str, begidx: int, endidx: int) -> list[str]:
        return self._matching(text, self.dbg.chart_names) if len(line[:begidx].split()) <= 1 else []

    complete_post = complete_diagram
