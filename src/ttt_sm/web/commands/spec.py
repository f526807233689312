"""A cockpit command declared once: its fields and its handler together (:func:`command`).

::

    @command("step", n=optional(integer(1, MAX_COUNT), 1))
    def step(session: Cockpit, cid: int, n: int) -> Reply:
        \"\"\"Control steps (``n`` of them, 1 ms each).\"\"\"
        ...

declares the message ``{"type": "step", "n": 3}``: :mod:`..protocol` checks
every message against the fields its command declares (a bare check is a field
a message must carry, :func:`~..fields.optional` one it may leave out), and the
session calls the handler with the checked fields, in its simulation thread
between two control steps.  A handler returns the reply's fields (``{"text":
...}``; the session adds ``type``, ``id``, ``command`` and ``ok``), or None to
send no reply; it refuses by raising ``ValueError`` (or the debugger's
``DebugError``, the coverage's ``CoverageError``) with a message that says why.

A handler sees the session through :class:`Cockpit`: what a command may read
and change of it, and nothing of its thread or its pages.
"""

from __future__ import annotations

import inspect
import types
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import AbstractContextManager
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Protocol

from ..fields import Check, Field

if TYPE_CHECKING:
    from ...debug.debugger import Debugger
    from ...debug.records import StopReason
    from ...sched.clock import PacedClock
    from ..coverage import CoverageRuns
    from ..frames import Frames
    from ..operate import Operate

#: A reply's fields (``text`` and whatever the command adds), or None: no reply.
Reply = dict[str, Any]


class Cockpit(Protocol):
    """What a command's handler may read and change of the session (:class:`~ttt_sm.web.session.Session`)."""

    debugger: Debugger
    #: What the session runs, as a page gets it when it joins (charts, signals, scenarios, the arm's scene).
    info: dict[str, Any]
    #: ``"running"`` or ``"paused"``.
    mode: str
    #: Times real time, or None: as fast as it goes.
    speed: float | None
    #: Why the run stopped last (a frame's ``stop``), or None while it runs.
    last_stop: dict[str, Any] | None
    #: Why the robot may not run on (a chart raised while it ran), or None.
    fault: str | None
    clock: PacedClock
    frames: Frames
    operate: Operate
    coverage: CoverageRuns

    def join(self, cid: int, page: str) -> None:
        """Page ``cid`` joins: it gets what runs, a full frame, the coverage shown, then every frame."""

    def send_to(self, cid: int, message: dict[str, Any]) -> None:
        """Send one page a message."""

    def publish(self) -> None:
        """Send every page a frame now."""

    def note_stop(self, reason: StopReason) -> None:
        """Keep why the run stopped, for the frames."""

    def robot_raised(self, exc: BaseException) -> None:
        """A chart raised while the robot ran: hold the arm where it stands, run that robot no more."""

    def robot_replaced(self, *, replaying: bool) -> AbstractContextManager[None]:
        """Around a call that gives the debugger a new robot (a replay, a new game)."""


Handler = Callable[..., Reply | None]


@dataclass(frozen=True)
class CommandSpec:
    """A declared command: its type on the wire, its fields, its handler."""

    type: str
    fields: Mapping[str, Field]
    handler: Handler
    #: False: handled at once in the server's thread (``ack``: it only notes a time), not queued for the
    #: simulation thread.
    queued: bool = True


def command(type_: str, *, queued: bool = True, **fields: Check | Field) -> Callable[[Handler], CommandSpec]:
    """Declare the decorated function the handler of command ``type_``, whose fields are ``fields``.

    Each field is a check from :mod:`..fields` (the message must carry it) or
    a :class:`~..fields.Field` (``optional(check, default)``).  The handler is
    called as ``handler(session, cid, **fields)``: the :class:`Cockpit`, the
    page's connection and the checked fields.
    """
    declared = types.MappingProxyType({name: f if isinstance(f, Field) else Field(f) for name, f in fields.items()})

    def declare(handler: Handler) -> CommandSpec:
        params = list(inspect.signature(handler).parameters)[2:]
        if params != list(declared):
            raise TypeError(f"command {type_!r}: {handler.__qualname__} takes {', '.join(params) or 'no fields'}"
                            f" after (session, cid); its declared fields are {', '.join(declared) or 'none'}")
        return CommandSpec(type_, declared, handler, queued)
    return declare


def collect(modules: Iterable[types.ModuleType]) -> Mapping[str, CommandSpec]:
    """The commands the modules declare, by type, in the modules' order (each in the order it is written)."""
    found: dict[str, CommandSpec] = {}
    for spec in _specs(modules):
        if spec.type in found:
            raise TypeError(f"command {spec.type!r} is declared twice")
        found[spec.type] = spec
    return types.MappingProxyType(found)


def _specs(modules: Iterable[types.ModuleType]) -> Iterator[CommandSpec]:
    for module in modules:
        yield from (v for v in vars(module).values() if isinstance(v, CommandSpec))
