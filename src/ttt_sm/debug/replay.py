"""Replay: how a robot is built again the same, and how two states are compared exactly.

A run is reproducible from its recipe (parameters, seed, power-on pose) and
the inputs the user set or posted, each at the control step it was applied.
:func:`fingerprint` is everything a replay must reproduce; :func:`differences`
names what does not match, float for float.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Protocol

from ..app.game import GameSession
from ..app.person import RemotePerson
from ..app.robot import Robot
from ..app.slots import ChartSlots, chosen_slots, using_slots
from ..arm import Arm
from ..params import ArmParams
from ..twin.sim import ArmSim
from ..twin.truth import GroundTruth
from .errors import DebugError

#: Quantities of the simulated arm a fingerprint compares (arrays, exact floats): its
#: controllers' ...
TWIN_FIELDS = ("q_encoder", "offset_estimate", "duty")
#: ... and its ground truth (``ArmSim.truth``; a replay is of a simulation).
TRUTH_FIELDS = ("q", "q_motor", "current_a", "speed_motor", "speed_load")


class Recipe(Protocol):
    """How to build the robot again, the same: what :meth:`Debugger.replay` needs."""

    def build(self) -> Robot:
        """A fresh robot, powered on, not yet stepped."""


@dataclass(frozen=True)
class RobotRecipe:
    """Parameters, seed and power-on pose: a :class:`Robot` built again bit for bit.

    ``q_start`` and ``settle_s`` are the Robot's own arguments: the pose before
    the unpowered arm settles under gravity for ``settle_s`` seconds; ``slots``
    the class in each replaceable chart's place (the command's, by default).
    """

    params: ArmParams
    seed: int = 0
    q_start: tuple[float, ...] | None = None
    settle_s: float = 0.0
    slots: ChartSlots = field(default_factory=chosen_slots)

    def build(self) -> Robot:
        return Robot(self.params, seed=self.seed, q_start=self.q_start, settle_s=self.settle_s, slots=self.slots)

    @classmethod
    def of(cls, robot: Robot) -> RobotRecipe:
        """The recipe of a robot not yet stepped: its seed and the pose it was powered on in."""
        if robot.steps:
            raise DebugError(f"the robot has run {robot.steps} control steps: its recipe cannot be"
                             " read back; pass recipe=RobotRecipe(params, seed, q_start, settle_s)")
        return cls(robot.params, robot.seed, tuple(float(v) for v in _sim(robot).truth.q), slots=robot.slots)


@dataclass(frozen=True)
class GameRecipe:
    """A robot with the game around it, built again bit for bit: a :class:`GameSession`
    (Game and AlgorithmActivator charts, the simulated person, the camera) whose
    flow is played from inside the chart steps (:meth:`GameSession.drive`).

    The camera is read in-process (``direct``): the debugger steps the robot
    one control step at a time, and the serial link's emulated camera, a
    thread behind a pseudo-terminal, would only add wall time to each reading.
    The simulated person is seeded with the seed, as in ``ttt-sm play``;
    ``person="page"``: a person at a GUI plays instead (:class:`RemotePerson`,
    the ``/game`` page of ``ttt-sm gui``), whose clicks the debugger records as
    inputs (:meth:`~.debugger.Debugger.game_input`) and a replay repeats.
    ``record_root``: the game's record (``game.jsonl``, with the board
    pictures, as ``ttt-sm play`` writes them) goes to ``record_root/game-<number>``
    as it is played (None: kept in memory only).
    """

    params: ArmParams
    seed: int = 0
    q_start: tuple[float, ...] | None = None
    settle_s: float = 0.0
    robot_symbol: str = "O"
    engine: str = "strong"
    person: str = "simulated"
    record_root: Path | None = None
    number: int = 1
    slots: ChartSlots = field(default_factory=chosen_slots)

    @property
    def out_dir(self) -> Path | None:
        """Where this game's record and board pictures are written (None: nowhere)."""
        return None if self.record_root is None else self.record_root / f"game-{self.number}"

    def build(self) -> Robot:
        if self.person not in ("simulated", "page"):
            raise ValueError(f"the person is 'simulated' or 'page', got {self.person!r}")
        person = RemotePerson() if self.person == "page" else None
        out_dir = self.out_dir
        with using_slots(self.slots):  # the game's charts and the robot's from the same slots
            session = GameSession(self.params, seed=self.seed, robot_symbol=self.robot_symbol, engine=self.engine,
                                  person=person, camera="direct", record_trace=out_dir is not None,
                                  q_start=self.q_start, settle_s=self.settle_s, out_dir=out_dir)
        session.drive()
        return session.robot


@dataclass
class ArmRecipe:
    """A robot on an arm that is not the twin (``--arm serial:PORT``), alone or in a game.

    It is built once: an arm behind a serial link cannot be powered on again
    in the same state, so a replay is refused with a line that says so.
    ``record_root``: with ``game``, the game's record goes to
    ``record_root/game-1`` as it is played, as :class:`GameRecipe`'s does.
    """

    params: ArmParams
    arm: Arm
    truth: GroundTruth | None
    seed: int = 0
    game: bool = False
    person: str = "simulated"
    built: bool = False
    record_root: Path | None = None

    def build(self) -> Robot:
        if self.built:
            raise DebugError("replay needs the twin: an arm behind a serial link cannot be powered on again in the"
                             " state it started from")
        self.built = True
        if not self.game:
            return Robot(self.params, seed=self.seed, arm=self.arm, truth=self.truth)
        if self.person not in ("simulated", "page"):
            raise ValueError(f"the person is 'simulated' or 'page', got {self.person!r}")
        out_dir = None if self.record_root is None else self.record_root / "game-1"
        session = GameSession(self.params, seed=self.seed, person=RemotePerson() if self.person == "page" else None,
                              camera="direct", record_trace=out_dir is not None, arm=self.arm, truth=self.truth,
                              out_dir=out_dir)
        session.drive()
        return session.robot


@dataclass(frozen=True)
class ReplayResult:
    """What :meth:`Debugger.replay` did and whether it reached the state seen before.

    ``identical`` is ``None`` when the session had not been at that step before
    (nothing to compare), else whether configuration, chart data and twin state
    are equal, float for float; ``differences`` names what differs.
    """

    tick: int
    steps: int
    t: float
    applied: int
    dropped: int
    identical: bool | None
    differences: tuple[str, ...] = ()
    #: Later inputs kept: applied again when a run reaches their control steps.
    ahead: int = 0

    def describe(self) -> str:
        text = f"replayed to step {self.steps} (t = {self.t:.3f} s, chart tick {self.tick})," \
               f" {self.applied} recorded input{'s' if self.applied != 1 else ''} re-applied"
        if self.dropped:
            text += f", {self.dropped} later one{'s' if self.dropped != 1 else ''} dropped"
        if self.ahead:
            text += (f", {self.ahead} later one{'s' if self.ahead != 1 else ''} kept (applied again when"
                     " you run to {})".format("their steps" if self.ahead != 1 else "its step"))
        if self.identical is True:
            text += "; identical to the first visit"
        elif self.identical is False:
            text += "; DIFFERS from the first visit: " + ", ".join(self.differences[:5])
        return text


def fingerprint(robot: Robot, forced: Mapping[tuple[str, str], Any] = MappingProxyType({})) -> dict[str, Any]:
    """The whole state a replay must reproduce: configurations, chart data (and their
    previous outputs, clocks, queued events), forced inputs and the twin's state, exact;
    in a game, the session's boards, moves and flags and where its flow stands."""
    sim = _sim(robot)
    charts = {}
    for name, c in robot.charts.items():
        charts[name] = {"active": sorted(c.configuration_values), "tick": c.tick_count,
                        "data": c.snapshot(), "previous": c.previous_outputs(),
                        "pending": c.pending_events}
    twin = {name: getattr(sim, name).tolist() for name in TWIN_FIELDS}
    twin.update({f"truth.{name}": getattr(sim.truth, name).tolist() for name in TRUTH_FIELDS})
    twin["sensors"] = sim.sensors()._asdict()
    out = {"steps": robot.steps, "chart_ticks": robot.chart_ticks, "t": sim.t, "charts": charts,
           "forced": sorted(forced.items()), "twin": twin}
    game = game_of(robot)
    if game is not None:
        driver = game.driver
        out["game"] = {**game.state(), "flow": None if driver is None else
                       {"waited": driver.waited, "done": driver.done,
                        "error": None if driver.error is None else str(driver.error)}}
    return out


def game_of(robot: Robot) -> GameSession | None:
    """The game session a robot plays, if a :class:`GameSession` added its charts."""
    game = robot.game
    return game if isinstance(game, GameSession) else None


def _sim(robot: Robot) -> ArmSim:
    """The robot's simulated arm: replaying needs a simulation."""
    if robot.sim is None:
        raise DebugError("replay needs a robot on the simulated arm (its whole state is compared)")
    return robot.sim


def differences(a: Any, b: Any, path: str = "") -> Iterator[str]:
    """Paths where two fingerprints differ (exact comparison)."""
    if isinstance(a, dict) and isinstance(b, dict):
        for key in dict.fromkeys([*a, *b]):
            yield from differences(a.get(key), b.get(key), f"{path}.{key}" if path else str(key))
    elif isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)) and len(a) == len(b):
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            yield from differences(x, y, f"{path}[{i}]")
    elif not (a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b))):
        yield path
