"""The ``ttt-sm debug`` commands that change what the robot gets: ``set``, ``force``, ``release``, ``post``,
and ``replay`` (the same inputs again, up to a tick: docs/debugger.md, "Inputs and replay"), mixed into
:class:`~.shell.DebugShell`.
"""

from __future__ import annotations

import shlex
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from . import views
from .debugger import Debugger
from .errors import DebugError
from .shell_args import parse_chart_dot, parse_count


class InputCommands:
    """Inputs set, forced, released and posted, and the replay, for :class:`~.shell.DebugShell`."""

    dbg: Debugger

    if TYPE_CHECKING:
        def say(self, *lines: str) -> None: ...
        def stopped(self, lines: Iterable[str]) -> None: ...

    # -- changing things ------------------------------------------------------------

    def _set(self, arg: str, force: bool) -> None:
        what = "force" if force else "set"
        words = arg.split()
        if len(words) != 2:
            raise DebugError(f"{what}: expected Chart.input VALUE, e.g. {what} DriveInit1.stop 1")
        chart, name = parse_chart_dot(words[0], what)
        value = self.dbg.set_input(chart, name, words[1], force=force)
        decl = self.dbg.datum_decl(chart, name)
        note = " (forced until release)" if force else ""
        self.say(f"{chart}.{name} = {views.fmt_value(value, decl.unit)}{note}")

    def do_set(self, arg: str) -> None:
        """set Chart.input VALUE: set a chart input (1/0 for flags; numbers may carry deg, mm).
        Inputs the wiring feeds every chart step (index, pos_Encoder, ...) are overwritten
        at the next one: force them instead."""
        self._set(arg, False)

    def do_force(self, arg: str) -> None:
        """force Chart.input VALUE: set an input and keep it against the wiring until release."""
        self._set(arg, True)

    def do_release(self, arg: str) -> None:
        """release [Chart.input]: stop forcing one input, or all of them."""
        if arg.strip():
            chart, name = parse_chart_dot(arg.strip(), "release")
            released = self.dbg.release(chart, name)
        else:
            released = self.dbg.release()
        names = ", ".join(f"{c}.{n}" for c, n in released)
        self.say(f"released {names}" if released else "nothing was forced")

    def do_post(self, arg: str) -> None:
        """post CHART EVENT [NAME=VALUE ...]: post an event, handled at the chart's next tick."""
        try:
            words = shlex.split(arg)
        except ValueError as exc:  # an unclosed quote
            raise DebugError(f"post: {exc} in {arg!r}") from None
        if len(words) < 2:
            raise DebugError("post: expected CHART EVENT, e.g. post Homing stop")
        data: dict[str, Any] = {}
        for item in words[2:]:
            key, eq, text = item.partition("=")
            if not eq or not key.isidentifier():
                raise DebugError(f"post: event data must be NAME=VALUE, got {item!r}")
            try:
                data[key] = float(text)
            except ValueError:
                data[key] = text
        self.dbg.post(words[0], words[1], **data)
        self.say(f"posted {words[1]} to {words[0]}; handled at its next tick")

    def do_replay(self, arg: str) -> None:
        """replay TICK | replay step N [--drop]: rebuild the robot and run it again to chart tick TICK.
        The robot is rebuilt from its parameters, seed and start pose; the inputs you set,
        forced and posted up to there are re-applied at the same control steps, and the state
        reached is compared with the one the session saw there before: configurations, chart
        data and twin state, float for float.  The inputs you gave after it are kept: a run
        forward applies them again at their steps (show inputs lists them as ahead);
        --drop drops them instead."""
        words = arg.split()
        drop = "--drop" in words
        words = [w for w in words if w != "--drop"]
        if not words:
            raise DebugError("replay: to which chart tick? e.g. replay 1510 (or replay step 3021)")
        if words[0] == "step":
            if len(words) != 2:
                raise DebugError("replay step: which control step? e.g. replay step 3021")
            self.stopped([self.dbg.replay_to_step(parse_count(words[1], "replay step"), drop=drop).describe()])
            return
        if len(words) != 1:
            raise DebugError(f"replay: expected TICK [--drop], got {arg.strip()!r}")
        self.stopped([self.dbg.replay(parse_count(words[0], "replay"), drop=drop).describe()])
