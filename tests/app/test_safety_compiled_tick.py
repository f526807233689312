"""The Safety chart's quiet tick, computed in place by the Safety stage, against the chart's own tick.

While the chart is in ``monitoring`` with no event queued and no input forced,
``_monitor.step`` writes the Monitor block's outputs into the chart's buffer,
tries the state's guards and, when none holds, does what the chart's tick does
(docs/safety.md, "Cost").  These tests hold it to the chart's own Python code.
"""

from __future__ import annotations

import math
from collections import Counter

import numpy as np
import pytest

from ttt_sm.app import _monitor
from ttt_sm.app import _monitor_layout as ML
from ttt_sm.app.robot import Robot
from ttt_sm.app.safety_wiring import make_safety_chart
from ttt_sm.faults.twin import FaultyArm
from ttt_sm.params import load_params
from ttt_sm.twin.sim import ArmSim

P = load_params()
THRESHOLDS = ("max_following_error", "max_following_error_init", "max_following_error_fast", "max_current",
              "max_current_init", "max_speed", "moving_speed", "stall_ratio", "silent_s", "limit_margin",
              "q_min_1", "q_min_2", "q_min_3", "q_max_1", "q_max_2", "q_max_3", "max_servo_error", "servo_error_s")
TIMERS = ("still_1", "still_2", "still_3", "servo_off")


def _same(a: dict[str, object], b: dict[str, object]) -> bool:
    return a.keys() == b.keys() and all(
        a[k] == b[k] or (isinstance(a[k], float) and isinstance(b[k], float) and math.isnan(a[k]) and math.isnan(b[k]))
        for k in a)


def test_the_compiled_quiet_tick_decides_and_does_what_the_charts_tick_does() -> None:
    """Random readings, thresholds, timers and flags (1,200 cases): where the compiled step says nothing
    fires, the chart's own tick takes no transition and leaves every datum as the step left it; where it
    says a guard holds, the chart's own tick leaves ``monitoring``."""
    robot = Robot(P, seed=0)
    robot.run_for(0.2)
    stage, chart = robot.safety_stage, robot.safety
    rng = np.random.default_rng(11)
    base = stage._m.copy()
    counts = base[ML.M_COUNTS:ML.M_COUNTS + 3].astype(np.int64)
    defaults = {name: getattr(chart, name) for name in THRESHOLDS}
    angles = counts * base[ML.M_RPC:ML.M_RPC + 3] + base[ML.M_OFFSET:ML.M_OFFSET + 3]
    outcomes: Counter[str] = Counter()
    for _ in range(1200):
        data = {name: float(v * rng.uniform(0.2, 1.8)) for name, v in defaults.items()}
        data.update({name: float(rng.choice([0.0, rng.uniform(0.0, 0.035)])) for name in TIMERS})
        for k, q in enumerate(angles, start=1):  # joint limits near where the encoders read
            data[f"q_min_{k}"] = float(q - rng.uniform(-0.05, 0.6))
            data[f"q_max_{k}"] = float(q + rng.uniform(-0.05, 0.6))
        for name, value in data.items():
            setattr(chart, name, value)
        own = make_safety_chart(P)  # in monitoring, ticked by its own code
        m = base.copy()
        m[ML.M_R:ML.M_R + 3] += rng.normal(0.0, 0.03, 3)
        m[ML.M_P:ML.M_P + 3] += rng.normal(0.0, 0.02, 3)
        m[ML.M_DP:ML.M_DP + 3] = rng.normal(0.0, 0.004, 3)
        m[ML.M_FAST:ML.M_FAST + 3] = rng.integers(0, 2, 3)
        c = counts + rng.integers(-40, 40, 3) * rng.choice([1, 8], 3, p=[0.8, 0.2])
        i = rng.normal(0.0, 2.5, 3)
        flags = [bool(rng.random() < p) for p in (0.8, 0.06, 0.97, 0.97)]  # initialised, init_failed, link, camera
        u = rng.normal(0.0, 0.5, 4)
        # the readings, as an arm without memory to read in place gives them (no calibration: rad already)
        m[ML.M_FB_CAL:ML.M_FB_CAL + 3] = (0.0, 0.0, 1.0)
        fsrc = np.array([*i, rng.normal(0.0, 0.3)])
        csrc = np.array([*base[ML.M_OFFSET:ML.M_OFFSET + 3], rng.normal(0.0, 0.3)])
        ix = stage._ix.copy()
        ix[ML.IX_SRC:ML.IX_PREV] = [0, 1, 2, 0, 1, 2, 3, 0, 1, 2, 3]
        k = _monitor.step(m, stage._b, ix, fsrc, c, csrc, *flags, True, float(u[0]), float(u[1]), float(u[2]),
                          False, float(u[3]))
        # the twin gets what the step fed, and the data the step started from
        own.set_inputs(**chart.snapshot(("input",)))
        for name, value in data.items():
            setattr(own, name, value)
        own.tick()
        if k == -1:
            assert own.active_ids == {"monitoring"}
            assert _same(own.snapshot(), chart.snapshot()) and _same(own.previous_outputs(), chart.previous_outputs())
            outcomes["quiet"] += 1
        else:
            assert k == _monitor.FED
            assert own.active_ids != {"monitoring"}
            outcomes[own.reason.split(" on drive")[0].split(":")[0]] += 1
        for name in TIMERS:  # the next case starts from its own data
            setattr(chart, name, 0.0)
    # every guard of monitoring fired, and the quiet tick was checked often
    assert outcomes["quiet"] > 200, outcomes
    for reason in ("encoder jumped", "overcurrent", "encoder stalled while commanded to move", "following error",
                   "joint limit", "link lost", "initialisation gave up", "camera lost", "servo stuck"):
        assert outcomes[reason] > 5, (reason, outcomes)


@pytest.mark.parametrize("fault", ["none", "encoder_jump", "motor_blocked"])
def test_a_robot_runs_the_same_with_the_compiled_tick_and_without(fault: str) -> None:
    """Two robots with one seed, one ticking the Safety chart itself every chart step: the same data every
    chart step, the same trip at the same step, the same arm."""
    arms = [FaultyArm(ArmSim(P, seed=6)) for _ in range(2)]
    robots = [Robot(P, seed=6, arm=arm, truth=arm.sim.truth) for arm in arms]
    robots[1].safety_stage.compiled_tick = False
    steps = robots[0].sched.ticks_for(9.0)
    for n in range(steps):
        if fault != "none" and n == steps // 2:  # mid-initialisation
            for arm in arms:
                arm.inject(fault, 2)
        for r in robots:
            r.chart_step()
        a, b = (r.safety for r in robots)
        assert a.active_ids == b.active_ids and _same(a.snapshot(), b.snapshot()), n
    assert robots[0].tripped == (fault != "none") and robots[0].safety.trips == (fault != "none")
    assert arms[0].encoder_angles() == arms[1].encoder_angles()


def test_the_simulated_arm_read_in_place_feeds_the_chart_what_its_readings_say() -> None:
    """The Safety stage reads the simulated arm's memory in place (``ArmSim.readings_in_place``); an arm
    without it (the same simulation behind ``FaultyArm``, no fault) is read through the Arm protocol: the
    chart gets the same numbers every chart step, through initialisation and the first lines of the field."""
    plain = Robot(P, seed=8)
    wrapped_arm = FaultyArm(ArmSim(P, seed=8))
    wrapped = Robot(P, seed=8, arm=wrapped_arm, truth=wrapped_arm.sim.truth)
    assert plain.safety_stage._copied is None and wrapped.safety_stage._copied is not None
    after = plain.sched.ticks_for(3.0)  # chart steps to go once the drives are initialised
    for n in range(plain.sched.ticks_for(40.0)):
        plain.chart_step()
        wrapped.chart_step()
        assert _same(plain.safety.snapshot(), wrapped.safety.snapshot()), n
        after -= plain.initialised
        if after == 0:
            break
    assert plain.initialised and not plain.tripped and after == 0
