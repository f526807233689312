"""The wiring table (ttt_sm.app.wires): checked when the robot is built, compiled into plain copies."""

from __future__ import annotations

import math

import pytest

from ttt_sm.app.game import GameSession
from ttt_sm.app.robot import Robot
from ttt_sm.app.wires import BLOCKS, GAME_WIRES, INIT_WIRES, ROBOT_WIRES
from ttt_sm.app.wiring import Wire, WiringError, chart_block, check
from ttt_sm.charts import ALL_CHARTS
from ttt_sm.params import load_params
from ttt_sm.runtime.data import BoolSlot

P = load_params()


def replaced(old: Wire, new: Wire | None) -> list[Wire]:
    """ROBOT_WIRES with one row replaced (or dropped)."""
    assert old in ROBOT_WIRES
    return [w for w in ROBOT_WIRES if w != old] + ([new] if new else [])


def test_the_tables_fit_every_chart_and_block():
    rows = check([*ROBOT_WIRES, *GAME_WIRES], [*(chart_block(c) for c in ALL_CHARTS), *BLOCKS])
    assert len(rows) == len(ROBOT_WIRES) + len(GAME_WIRES)
    assert set(INIT_WIRES) < set(ROBOT_WIRES)
    # Control tells the game what it does only through outputs it declares (erasing: a full board erases
    # while the game ends, thesis section 3.6.1)
    control_to_game = {(r.source.port, r.target.port) for r in rows
                       if r.source.block == "Control" and r.target.block == "Game"}
    assert control_to_game == {("ready", "ready"), ("busy", "busy"), ("at_start", "finished"),
                               ("erasing", "sponge")}


def test_a_misspelt_wire_fails_when_the_robot_is_built_naming_it():
    wires = replaced(Wire("Control.fr_sw", "Drives.fr_sw"), Wire("Control.fr_sv", "Drives.fr_sw"))
    with pytest.raises(WiringError, match=r"^wire Control\.fr_sv -> Drives\.fr_sw: Control has no output 'fr_sv';"
                                          r" outputs: X_out, Y_out"):
        Robot(P, wires=wires)
    wires = replaced(Wire("FK.X", "Control.X_now"), Wire("FK.X", "Control.Xnow"))
    with pytest.raises(WiringError, match=r"^wire FK\.X -> Control\.Xnow: Control has no input 'Xnow'"):
        Robot(P, wires=wires)
    wires = replaced(Wire("FK.X", "Control.X_now"), Wire("Fk.X", "Control.X_now"))
    with pytest.raises(WiringError, match=r"^wire Fk\.X -> Control\.X_now: no block named 'Fk'; blocks: "):
        Robot(P, wires=wires)


def test_a_unit_mismatch_fails_when_the_robot_is_built_naming_it():
    wires = replaced(Wire("FK.X", "Control.X_now"), Wire("Encoder.angle[0]", "Control.X_now"))
    with pytest.raises(WiringError, match=r"^wire Encoder\.angle\[0\] -> Control\.X_now: units differ:"
                                          r" Encoder\.angle\[0\] is in 'rad', Control\.X_now in 'm'$"):
        Robot(P, wires=wires)


@pytest.mark.parametrize("old, new, message", [
    # a missing row: inverse kinematics would get no z
    (Wire("Control.Z_out", "IK.Z"), None, r"^nothing is wired to IK\.Z$"),
    (Wire("DriveInit2.pos_out", "Drives.q_set[1]"), None, r"^nothing is wired to Drives\.q_set\[1\]$"),
    # an input as a source, an output as a target
    (Wire("Control.erasing", "EraseFlag.erasing"), Wire("Control.erase", "EraseFlag.erasing"),
     r"Control\.erase is an input; a wire's source must be an output"),
    (Wire("FK.X", "Control.X_now"), Wire("FK.X", "Control.X_out"),
     r"Control\.X_out is an output; a wire's target must be an input"),
    # elements of a vector
    (Wire("Encoder.angle[0]", "DriveInit1.pos_Encoder"), Wire("Encoder.angle[3]", "DriveInit1.pos_Encoder"),
     r"Encoder\.angle has 3 elements; name one, Encoder\.angle\[0\] \.\. \[2\]"),
    (Wire("Encoder.angle[0]", "DriveInit1.pos_Encoder"), Wire("Encoder.angle", "DriveInit1.pos_Encoder"),
     r"Encoder\.angle has 3 elements"),
    (Wire("FK.X", "Control.X_now"), Wire("FK.X[0]", "Control.X_now"), r"FK\.X is a scalar; drop \[0\]"),
    # a target fed twice
    (Wire("FK.Y", "Control.Y_now"), Wire("FK.X", "Control.X_now"),
     r"Control\.X_now is already driven by wire FK\.X -> Control\.X_now"),
    # a chart the robot does not have, a block input no stage reads
    (Wire("FK.Y", "Control.Y_now"), Wire("Control.busy", "Game.busy"), r"no block named 'Game'"),
    (Wire("FK.Y", "Control.Y_now"), Wire("Control.erasing", "Session.erasing"),
     r"^wire Control\.erasing -> Session\.erasing: nothing reads Session\.erasing"),
    (Wire("FK.Y", "Control.Y_now"), Wire("FK.Y", "Control.Y now"), r"'Control\.Y now' is not Block\.port"),
])
def test_a_wire_that_does_not_fit_fails_when_the_robot_is_built(old, new, message):
    with pytest.raises(WiringError, match=message):
        Robot(P, wires=replaced(old, new))


@pytest.fixture(scope="module")
def game_robot() -> Robot:
    """A game's robot: every table wired (the camera emulator is not started)."""
    session = GameSession(P, seed=0, camera="direct", record_trace=False)
    yield session.robot
    session.close()


#: Blocks whose outputs their stage computes every chart step and passes to the feeds as arguments.
ARGUMENT_BLOCKS = ("FK", "IK", "Monitor")


def _plant(robot: Robot) -> tuple[dict[str, float], list[object]]:
    """A distinct value at every source of the robot's table.

    Returns the values by source, and the arguments a feed of every chart takes
    (the outputs of ARGUMENT_BLOCKS, in declaration order).
    """
    wiring = robot.wiring
    values: dict[str, float] = {}
    blocks = {b.name: b for b in BLOCKS}
    arguments = {f"{name}.{p.name}": [math.nan] * p.size if p.size > 1 else math.nan
                 for name in ARGUMENT_BLOCKS for p in blocks[name].outputs}
    later: list[tuple[str, object, str]] = []
    for k, row in enumerate(wiring.rows):
        source = row.source
        key = str(source)
        if key in values:
            continue
        values[key] = value = 1000.0 + k
        port = f"{source.block}.{source.port}"
        if source.block in robot.charts:
            robot.charts[source.block].data_mapping()[source.port] = value
        elif port in arguments:
            if source.index is None:
                arguments[port] = value
            else:
                arguments[port][source.index] = value  # type: ignore[index]
        else:
            obj = wiring.objects[source.block]
            attr = row.source_port.attribute
            derived = getattr(type(obj), attr, None)
            if isinstance(derived, property) and derived.fset is None:
                later.append((key, obj, attr))  # computed from other outputs (Session.detected): read at the end
                continue
            if source.index is None:
                current = getattr(obj, attr)
                if isinstance(current, int) and not isinstance(current, bool):
                    values[key] = value = int(value)  # a count or a bit set stays an integer
                setattr(obj, attr, value)
            else:
                vector = list(getattr(obj, attr))
                vector[source.index] = value
                setattr(obj, attr, vector)
    for key, obj, attr in later:
        values[key] = getattr(obj, attr)
    return values, list(arguments.values())


def _held(chart, datum: str, value: float) -> object:
    """What `datum` of `chart` reads after `value` is written to it: a buffered chart's flag reads as a bool."""
    if datum in chart.data_slots() and isinstance(getattr(type(chart), datum), BoolSlot):
        return bool(value)
    return value


def _source_value(robot: Robot, values: dict[str, float], row) -> object:
    source = row.source
    value = values[str(source)]
    return _held(robot.charts[source.block], source.port, value) if source.block in robot.charts else value


def test_every_row_that_feeds_a_chart_copies_its_source_into_the_input(game_robot):
    robot = game_robot
    values, arguments = _plant(robot)
    robot.wiring.feed(list(robot.charts), args=ARGUMENT_BLOCKS)(*arguments)
    rows = [r for r in robot.wiring.rows if r.target.block in robot.charts]
    assert len(rows) == 56  # 31 into the thesis' charts and the game's, 25 into the Safety chart
    for row in rows:
        chart = robot.charts[row.target.block]
        expected = _held(chart, row.target.port, _source_value(robot, values, row))
        assert getattr(chart, row.target.port) == expected, row.wire


def test_every_row_into_another_block_is_collected_from_its_source(game_robot):
    robot = game_robot
    values, _ = _plant(robot)
    rows = [r for r in robot.wiring.rows if r.target.block not in robot.charts]
    ports = sorted({f"{r.target.block}.{r.target.port}" for r in rows})
    collected = dict(zip(ports, robot.wiring.collect(*ports)(), strict=True))
    for row in rows:
        value = collected[f"{row.target.block}.{row.target.port}"]
        if row.target.index is not None:
            value = value[row.target.index]
        assert value == _source_value(robot, values, row), row.wire


def test_a_game_is_wired_from_the_robots_table_and_the_games():
    session = GameSession(P, seed=0, camera="direct", record_trace=False)
    try:
        robot = session.robot
        assert robot.wires == (*ROBOT_WIRES, *GAME_WIRES)
        assert list(robot.charts) == ["DriveInit1", "DriveInit2", "DriveInit3", "Control", "Safety",
                                      "AlgorithmActivator", "Game"]
        assert robot.wiring.unused() == []
    finally:
        session.close()
