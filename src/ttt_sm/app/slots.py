"""Chart slots: which class runs in each replaceable chart's place, and the contract it must meet.

The robot runs the thesis' charts by default.  A student's chart can take the
place of one of them (``ttt-sm --chart DriveInit3=mine.py:MyInit3 play``): the
robot is built the same, with the student's class in that *slot*.  Six charts
are slots: the three drive-initialisation charts, Control, and the game's Game
and AlgorithmActivator.  The Safety chart is not: it stays on underneath
whatever a student writes (docs/safety.md).

A slot's contract is what the robot connects to the chart: the inputs the
wiring tables (:mod:`.wires`) feed and the outputs they read, the data the
application sets or reads besides (the Control chart's cell and symbol, the
parameters the builders fill in from the parameter file) and the events it
posts.  Each entry has the kind and unit the thesis chart declares for it.
:func:`contract_problems` holds a class against it: what is missing, what is
of the wrong kind or unit, and the inputs nothing would ever feed.

:class:`ChartSlots` is a choice of classes for the slots (the thesis' own by
default).  The robot (:class:`~.robot.Robot`), the game session and the
scenario runner's catalogue take theirs from :func:`chosen_slots`, which a
command sets for the time it runs with :func:`using_slots` (a context
variable: scoped to the command, not a global the program keeps).
"""

from __future__ import annotations

import contextlib
import contextvars
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

from ..charts import AlgorithmActivator, Control, DriveInit1, DriveInit2, DriveInit3, Game
from ..runtime import TickChart
from .wires import GAME_WIRES, ROBOT_WIRES
from .wiring import Wire


@dataclass(frozen=True)
class Entry:
    """One datum or event of a slot's contract.

    ``kind`` is ``input``, ``output``, ``local`` (a parameter the builder sets,
    or a datum the application reads) or ``event``; ``unit`` as
    :class:`~ttt_sm.runtime.Data` writes it (empty for an event); ``why`` says
    who uses it.
    """

    name: str
    kind: str
    unit: str
    why: str

    def describe(self) -> str:
        return f"{self.kind} {self.name}" + (f" ({self.unit})" if self.unit else "")


@dataclass(frozen=True)
class Slot:
    """A replaceable chart: its name (the thesis chart's), the thesis class, and what else the app uses.

    ``sets`` / ``reads``: data the application writes or reads besides the
    wiring table, each with who does; ``parameters``: data the builder fills
    in from the parameter file; ``events``: events the application posts.
    """

    name: str
    thesis: type[TickChart]
    section: str
    sets: Mapping[str, str] = field(default_factory=dict)
    reads: Mapping[str, str] = field(default_factory=dict)
    parameters: tuple[str, ...] = ()
    events: Mapping[str, str] = field(default_factory=dict)


_INIT_PARAMETERS = ("index_angle", "park", "offset")
#: Every replaceable chart, in the order the robot builds them (thesis sections in brackets).
SLOTS: tuple[Slot, ...] = (
    Slot("DriveInit1", DriveInit1, "3.1.2", sets={"stop": "the Stop button (scenarios, the debugger)"},
         parameters=_INIT_PARAMETERS),
    Slot("DriveInit2", DriveInit2, "3.1.2", parameters=_INIT_PARAMETERS),
    Slot("DriveInit3", DriveInit3, "3.1.2", parameters=_INIT_PARAMETERS),
    Slot("Control", Control, "3.6.1",
         sets={"row": "the game and the GUIs: the cell to draw in", "column": "the cell to draw in",
               "symbol": "X or O", "speed": "the Operational GUI", "size": "the Operational GUI",
               "sine_amplitude": "the Operational GUI", "finish": "the game (Game.finish) and the GUIs"},
         reads={"Pl_fld": "ttt-sm draw (holds the field back)", "ignored_buttons": "ttt-sm play's report",
                "ctr": "the GUIs"},
         parameters=("x11", "y11", "L", "cells", "z_draw", "z_up", "z_travel", "z_sponge"),
         events={"button": "draw the symbol in the cell (the game, play, draw)", "draw_sine": "ttt-sm draw"}),
    Slot("Game", Game, "3.7", reads={"message": "the Tic-tac-toe GUI's text", "ended": "the game's end"}),
    Slot("AlgorithmActivator", AlgorithmActivator, "3.6.2",
         sets={"hold": "a new game"}, reads={"ignored_triggers": "the game's report"},
         events={"trigger": "the Play click"}),
)
SLOT_NAMES = tuple(s.name for s in SLOTS)
_BY_NAME = {s.name: s for s in SLOTS}

#: Every wiring table a slot may be wired by (the robot's and a game's).
_ALL_WIRES: tuple[Wire, ...] = ROBOT_WIRES + GAME_WIRES


def slot(name: str) -> Slot:
    """A slot by name; a :class:`SlotError` names the slots there are."""
    try:
        return _BY_NAME[name]
    except KeyError:
        raise SlotError(f"no chart slot {name!r}; slots: {', '.join(SLOT_NAMES)}") from None


class SlotError(ValueError):
    """A chart that cannot take a slot: an unknown slot, or a class that does not meet its contract."""


def _port(end: str) -> tuple[str, str]:
    block, _, port = end.partition(".")
    return block, port.partition("[")[0]


def contract(name: str) -> tuple[Entry, ...]:
    """The contract of slot `name`: wired inputs and outputs, the data the application uses, its events.

    Kinds and units are the thesis chart's declarations.
    """
    s = slot(name)
    decls = {d.name: d for d in s.thesis.declarations()}
    whys: dict[str, str] = {}
    for w in _ALL_WIRES:
        src, tgt = _port(w.source), _port(w.target)
        if tgt[0] == name:
            whys.setdefault(tgt[1], f"wired from {w.source}")
        if src[0] == name:
            whys.setdefault(src[1], f"wired to {w.target}")
    for table in (s.sets, s.reads):
        for datum, why in table.items():
            whys.setdefault(datum, why)
    for datum in s.parameters:
        whys.setdefault(datum, "set from the parameter file when the robot is built")
    entries = [Entry(n, decls[n].kind, decls[n].unit, why) for n, why in whys.items()]
    entries.sort(key=lambda e: ("input", "output", "local").index(e.kind))
    entries += [Entry(e, "event", "", why) for e, why in s.events.items()]
    return tuple(entries)


def contract_problems(name: str, cls: type[TickChart]) -> list[str]:
    """What keeps `cls` from slot `name`: missing, wrong kind or unit, extra inputs, unhandled events."""
    entries = contract(name)
    declared = {d.name: d for d in cls.declarations()}
    problems: list[str] = []
    for e in entries:
        if e.kind == "event":
            if e.name not in cls.structure().user_events:
                problems.append(f"missing event {e.name} ({e.why})")
            continue
        d = declared.get(e.name)
        if d is None:
            problems.append(f"missing {e.describe()} ({e.why})")
        elif d.kind != e.kind:
            problems.append(f"{e.name} is declared {d.kind}, the slot's is {e.describe()}")
        elif d.unit != e.unit:
            problems.append(f"{e.kind} {e.name} is in {d.unit!r}, the slot's is in {e.unit!r}")
    known = {e.name for e in entries}
    for d in declared.values():
        if d.kind == "input" and d.name not in known:
            problems.append(f"extra input {d.name} (nothing feeds it in this slot)")
    return problems


@dataclass(frozen=True)
class SlottedChart:
    """A class chosen for a slot, and where it was written (``file:line``, for messages)."""

    cls: type[TickChart]
    where: str


@dataclass(frozen=True)
class ChartSlots:
    """A class for each slot: the thesis' unless :meth:`with_chart` put another in."""

    chosen: Mapping[str, SlottedChart] = field(default_factory=lambda: MappingProxyType({}))

    def cls(self, name: str) -> type[TickChart]:
        """The class that runs in slot `name`."""
        chosen = self.chosen.get(name)
        return chosen.cls if chosen is not None else slot(name).thesis

    def with_chart(self, name: str, cls: type[TickChart], where: str) -> ChartSlots:
        """These slots with `cls` in slot `name`; a :class:`SlotError` (one line, at `where`) if it does not fit."""
        slot(name)
        if not (isinstance(cls, type) and issubclass(cls, TickChart)) or not cls.states:
            raise SlotError(f"{where}: {getattr(cls, '__name__', cls)!r} is no chart: a chart is a class"
                            " derived from ttt_sm.runtime.TickChart, with states")
        problems = contract_problems(name, cls)
        if problems:
            raise SlotError(f"{where}: class {cls.__name__} does not fit the {name} slot: " + "; ".join(problems))
        return ChartSlots(MappingProxyType({**self.chosen, name: SlottedChart(cls, where)}))

    def make(self, name: str, **kwargs: object) -> TickChart:
        """An instance of the class in slot `name`, named as the slot (the wiring table's name)."""
        return self.cls(name)(chart_name=name, **kwargs)  # type: ignore[arg-type]

    def describe(self) -> dict[str, str]:
        """Slot -> ``Class (file:line)`` for the slots a student filled."""
        return {n: f"{c.cls.__name__} ({c.where})" for n, c in self.chosen.items()}


#: The thesis' charts in every slot.
THESIS_SLOTS = ChartSlots()

_CHOSEN: contextvars.ContextVar[ChartSlots] = contextvars.ContextVar("ttt_sm_chart_slots", default=THESIS_SLOTS)


def chosen_slots() -> ChartSlots:
    """The slots chosen for the command that runs now (:func:`using_slots`); the thesis' by default."""
    return _CHOSEN.get()


@contextlib.contextmanager
def using_slots(slots: ChartSlots) -> Iterator[ChartSlots]:
    """Build every robot, game and scenario catalogue within the block with `slots`."""
    token = _CHOSEN.set(slots)
    try:
        yield slots
    finally:
        _CHOSEN.reset(token)
