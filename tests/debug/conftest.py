"""Shared fixtures of the debugger tests: a debugger at the rest pose (``params`` is the
suite's, tests/conftest.py) and a robot with one extra event-driven chart (the drive-init charts take no events)."""

from __future__ import annotations

import pytest
from statemachine import State

from ttt_sm.app.robot import Robot
from ttt_sm.debug import Debugger, RobotRecipe
from ttt_sm.params import ArmParams
from ttt_sm.runtime import Data, TickChart, after


@pytest.fixture
def dbg(params: ArmParams) -> Debugger:
    return Debugger.build(params, seed=0)


class Lamp(TickChart):
    """A lamp that lights on ``press`` and goes out by itself after 3 ticks; ``reset`` anywhere."""

    tick_period_s = 0.002
    outputs = (Data("level", "1", 0.0, "brightness"),)

    off = State(initial=True)
    lit = State()
    press = off.to(lit)
    lit.to(off, cond=after(3))
    reset = lit.to(off)

    def on_enter_lit(self) -> None:
        self.level = 1.0

    def on_enter_off(self) -> None:
        self.level = 0.0


class LampStage:
    """Joint stage that ticks the lamp with the drive charts."""

    def __init__(self, lamp: Lamp) -> None:
        self.lamp = lamp

    def tick(self, signals: object) -> None:
        self.lamp.tick()


class LampRecipe:
    """The rest-pose robot plus a Lamp chart: a recipe a replay can rebuild."""

    def __init__(self, params: ArmParams) -> None:
        self.base = RobotRecipe(params, seed=0)

    def build(self) -> Robot:
        robot = self.base.build()
        lamp = Lamp()
        robot.charts["Lamp"] = lamp
        robot.sched.joint_stages.append(LampStage(lamp))
        return robot


@pytest.fixture
def lamp_dbg(params: ArmParams) -> Debugger:
    recipe = LampRecipe(params)
    return Debugger(recipe.build(), recipe)

