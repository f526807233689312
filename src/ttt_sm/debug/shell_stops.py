"""The ``ttt-sm debug`` commands that say where a run stops and what is shown when it does.

``break``, ``delete``, ``enable``, ``disable`` (the breakpoints: docs/debugger.md, "Breakpoints") and
``display``/``watch``, ``undisplay`` (expressions shown after every stop), mixed into
:class:`~.shell.DebugShell`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from . import views
from .debugger import Debugger
from .errors import DebugError
from .expr import Condition, parse_condition


class StopCommands:
    """Breakpoints and displays, for :class:`~.shell.DebugShell`."""

    dbg: Debugger
    #: ``display``: expressions shown after each stop, by number.
    displays: dict[int, Condition]
    _next_display: int

    if TYPE_CHECKING:
        def say(self, *lines: str) -> None: ...

    # -- display ------------------------------------------------------------------

    def do_display(self, arg: str) -> None:
        """display EXPR: show EXPR after every stop (run, step, tick, next, back, replay);
        display alone shows them now.  EXPR as in break when: DriveInit1.pos_out, q_true[1],
        DriveInit1.pos_out - DriveInit1.pos_Encoder, DriveInit1.index and not DriveInit1.stop.
        watch is the same command; undisplay N removes one."""
        if not arg.strip():
            self.say(*(self.display_lines() or ["  (nothing displayed: display EXPR adds one)"]))
            return
        condition = parse_condition(arg, self.dbg.names)
        n = self._next_display
        self._next_display += 1
        self.displays[n] = condition
        self.say(*self._display_line(n, condition))

    do_watch = do_display

    def do_undisplay(self, arg: str) -> None:
        """undisplay N... | undisplay all: stop showing display expressions."""
        if arg.strip() == "all":
            self.displays.clear()
            self.say("nothing displayed now")
            return
        for n in self._ids(arg, "undisplay"):
            if self.displays.pop(n, None) is None:
                raise DebugError(f"undisplay: no display {n}; displays: "
                                 f"{', '.join(map(str, self.displays)) or 'none'}")
            self.say(f"display {n} removed")

    def display_lines(self) -> list[str]:
        return [line for n, c in self.displays.items() for line in self._display_line(n, c)]

    def _display_line(self, n: int, condition: Condition) -> list[str]:
        try:
            value = condition.value()
        except DebugError as exc:
            return [f"  {n}: {condition.text} = ? ({exc})"]
        chart, dot, name = condition.text.partition(".")
        unit = ""
        if dot and chart in self.dbg.robot.charts and name.isidentifier():
            unit = self.dbg.datum_decl(chart, name).unit
        return [f"  {n}: {condition.text} = {views.fmt_value(value, unit)}"]

    # -- breakpoints --------------------------------------------------------------

    def do_break(self, arg: str) -> None:
        """break KIND SPEC: add a breakpoint; break alone lists them.
        break enter Chart.state | break exit Chart.state
        break transition Chart source->target   (* for any state)
        break event Chart.event                 (tick: any tick transition)
        break when CONDITION   e.g. DriveInit1.pos_Encoder > 1.0 and not DriveInit1.index
                               (hits when it becomes true; signals: q_true[1], t, ...;
                                numbers may carry deg, mm, ms)"""
        if not arg.strip():
            self.say(*views.breakpoint_lines(self.dbg.breakpoints))
            return
        bp = self.dbg.add_breakpoint(arg)
        self.say(f"breakpoint {bp.id}: {bp.spec}")

    def _ids(self, arg: str, what: str) -> list[int]:
        try:
            ids = [int(a) for a in arg.split()]
        except ValueError:
            raise DebugError(f"{what}: expected breakpoint numbers, got {arg.strip()!r}") from None
        if not ids:
            raise DebugError(f"{what}: which breakpoint? (break lists them)")
        return ids

    def do_delete(self, arg: str) -> None:
        """delete ID... | delete all: remove breakpoints."""
        if arg.strip() == "all":
            self.dbg.delete(None)
            self.say("all breakpoints deleted")
            return
        for bp_id in self._ids(arg, "delete"):
            self.dbg.delete(bp_id)
            self.say(f"breakpoint {bp_id} deleted")

    def do_enable(self, arg: str) -> None:
        """enable ID...: enable breakpoints."""
        for bp_id in self._ids(arg, "enable"):
            self.dbg.enable(bp_id)
            self.say(f"breakpoint {bp_id} enabled")

    def do_disable(self, arg: str) -> None:
        """disable ID...: disable breakpoints (kept, not checked)."""
        for bp_id in self._ids(arg, "disable"):
            self.dbg.disable(bp_id)
            self.say(f"breakpoint {bp_id} disabled")
