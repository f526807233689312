"""The runner: what each step does, and failures that name the failing step's file:line."""

from __future__ import annotations

import math
import textwrap
from types import SimpleNamespace
from typing import Any

import pytest
from statemachine import State

from ttt_sm.app.robot import Robot
from ttt_sm.params import load_params
from ttt_sm.runtime import Data, TickChart
from ttt_sm.runtime.listeners import Coverage
from ttt_sm.scenario import SIGNALS, Catalog, load_scenario_text, run_scenario

PARAMS = load_params(None)


def run(text: str, **kwargs: Any):
    scenario = load_scenario_text(textwrap.dedent(text), "s.yaml", catalog=kwargs.pop("catalog", None))
    return run_scenario(scenario, kwargs.pop("params", PARAMS), **kwargs)


def lines(result) -> list[int]:
    return [f.where.line for f in result.failures]


def test_a_passing_scenario() -> None:
    r = run("""\
        name: drive 1 starts turning forward
        steps:
          - run_until: {entered: DriveInit1.turn_fwd, timeout_s: 0.1}
          - run: {seconds: 0.2}
          - expect: "DriveInit1.pos_out > 0 and t > 0.2"
          - expect_states: {chart: DriveInit1, sequence: [run, initialise, power_on, turn_fwd]}
          - expect_states: {chart: DriveInit1, sequence: [power_on, turn_fwd], match: exact}
        """)
    assert r.passed and r.failures == ()
    assert r.steps_run == r.steps_total == 5
    assert math.isclose(r.sim_time_s, 0.202, abs_tol=1e-9)  # one chart step to turn_fwd, then 0.2 s
    assert r.to_dict()["failures"] == [] and r.to_dict()["passed"] is True


def test_failures_name_the_failing_steps_and_expectations_do_not_stop_the_run() -> None:
    r = run("""\
        name: wrong on purpose
        steps:
          - run: {chart_steps: 2}
          - expect: "DriveInit1.turn_back or q_true[1] > 10deg"
          - expect_states: {chart: DriveInit1, sequence: [turn_fwd, turn_back]}
          - run_until: {entered: DriveInit1.go_park, timeout_s: 0.2}
          - expect: "false"
        """)
    assert not r.passed
    assert lines(r) == [4, 5, 6]  # the timeout stops the scenario: line 7 never runs
    assert r.steps_run == 4 and r.steps_total == 5
    texts = [str(f) for f in r.failures]
    assert texts[0].startswith("s.yaml:4: expect: 'DriveInit1.turn_back or q_true[1] > 10deg' is false;")
    assert "t = 0.004 s; DriveInit1.turn_back = false; q_true[1] = " in texts[0]
    # the first state of the sequence not entered, and what came instead of it (here: nothing)
    assert texts[1] == ("s.yaml:5: expect_states: DriveInit1 since the start: expected turn_back (2nd of the"
                        " sequence) after turn_fwd, got nothing; DriveInit1 is in turn_fwd")
    assert texts[2].startswith("s.yaml:6: run_until: DriveInit1 did not enter go_park within 0.2 s"
                               " (from t = 0.004 s to 0.204 s); DriveInit1 is in turn_fwd;"
                               " it entered no state meanwhile")
    assert r.to_dict()["failures"] == texts


def test_a_condition_that_times_out_reports_its_values() -> None:
    r = run("""\
        name: too impatient
        steps:
          - run_until: {condition: "DriveInit1.pos_Encoder > 1.0", timeout_s: 0.1}
        """)
    assert lines(r) == [3]
    assert "run_until: 'DriveInit1.pos_Encoder > 1.0' did not hold within 0.1 s" in r.failures[0].message
    assert "values now: t = 0.100 s; DriveInit1.pos_Encoder = " in r.failures[0].message


def test_within_and_for() -> None:
    r = run("""\
        name: timing
        steps:
          - expect: {condition: "DriveInit1.turn_fwd", within_s: 0.01}
          - expect: {condition: "t > 0.5", within_s: 0.1}
          - expect: {condition: "DriveInit1.turn_fwd", for_s: 0.1}
          - expect: {condition: "DriveInit1.pos_out < 0.3", for_s: 1}
          - expect: {condition: "DriveInit1.power_on", for_s: 1}
        """)
    assert lines(r) == [4, 6, 7]
    m = [f.message for f in r.failures]
    assert m[0].startswith("expect: 't > 0.5' did not hold within 0.1 s; t = 0.102 s")
    assert m[1].startswith("expect: 'DriveInit1.pos_out < 0.3' for 1 s: false after 0.")
    assert m[2].startswith("expect: 'DriveInit1.power_on' for 1 s: false at once")


def test_entered_waits_for_a_new_entry_and_active_does_not() -> None:
    r = run("""\
        name: entered or active
        steps:
          - run_until: {entered: DriveInit1.turn_fwd, timeout_s: 0.1}
          - run_until: {active: DriveInit1.turn_fwd, timeout_s: 0.1}
          - expect: "t == 0.002"
          - run_until: {entered: DriveInit1.turn_fwd, timeout_s: 0.1}
        """)
    assert lines(r) == [6]


def test_mark_starts_a_new_window() -> None:
    r = run("""\
        name: marks
        steps:
          - run: {chart_steps: 1}
          - mark: turning
          - expect_states: {chart: DriveInit1, sequence: [turn_fwd]}
          - set: {DriveInit1.stop: true}
          - run: {chart_steps: 1}
          - set: {DriveInit1.stop: false}
          - run: {chart_steps: 2}
          - expect_states: {chart: DriveInit1, sequence: [stopped, turn_fwd], match: exact}
          - expect_states: {chart: DriveInit1, sequence: [stopped, run, initialise, turn_fwd]}
          - expect_states: {chart: DriveInit1, sequence: [stopped], match: exact}
        """)
    assert lines(r) == [5, 12]
    assert r.failures[0].message == ("expect_states: DriveInit1 since mark 'turning' (line 4): expected turn_fwd"
                                     " (1st of the sequence), got nothing; DriveInit1 is in turn_fwd")
    assert r.failures[1].message == ("expect_states: DriveInit1's 2nd leaf state since mark 'turning' (line 4):"
                                     " expected none, got turn_fwd (expected stopped, [none]; entered stopped,"
                                     " [turn_fwd]); DriveInit1 is in turn_fwd")


def test_a_failed_condition_shows_values_in_the_unit_it_compares_them_with() -> None:
    r = run("""\
        name: too far
        steps:
          - run_until: {entered: DriveInit1.turn_back, timeout_s: 5}
          - expect: "q_true[1] > 175deg or DriveInit1.pos_out > 100"
          - expect: "abs(DriveInit1.pos_Encoder - 175deg) < 20mm"
        """)
    assert [str(f) for f in r.failures] == [
        # the hard stop at 170 deg, read as the expectation reads it; pos_out beside a bare number: SI (rad)
        "s.yaml:4: expect: 'q_true[1] > 175deg or DriveInit1.pos_out > 100' is false; t = 3.016 s;"
        " q_true[1] = 170deg; DriveInit1.pos_out = 2.97021",
        # two units in one comparison: the value as the chart holds it
        "s.yaml:5: expect: 'abs(DriveInit1.pos_Encoder - 175deg) < 20mm' is false; t = 3.016 s;"
        " DriveInit1.pos_Encoder = 2.97021"]


def test_expect_states_points_at_the_first_state_that_differs() -> None:
    r = run("""\
        name: wrong sequences
        steps:
          - run_until: {entered: DriveInit1.turn_back, timeout_s: 5}
          - expect_states: {chart: DriveInit1, sequence: [power_on, turn_fwd, go_park, wait_23], match: exact}
          - expect_states: {chart: DriveInit1, sequence: [power_on, turn_fwd, turn_back, go_park], match: exact}
          - expect_states: {chart: DriveInit1, sequence: [power_on], match: exact}
          - expect_states: {chart: DriveInit1, sequence: [turn_fwd, go_park, turn_back]}
          - expect_states: {chart: DriveInit1, sequence: [power_on, turn_fwd, turn_back], match: exact}
        """)
    messages = [f.message.split("; DriveInit1 is in ")[0] for f in r.failures]
    assert lines(r) == [4, 5, 6, 7]
    assert messages == [
        # which state (the 3rd), what was expected, what came; the two lists around it
        "expect_states: DriveInit1's 3rd leaf state since the start: expected go_park, got turn_back"
        " (expected power_on, turn_fwd, [go_park], wait_23; entered power_on, turn_fwd, [turn_back])",
        "expect_states: DriveInit1's 4th leaf state since the start: expected go_park, got none"
        " (expected ..., turn_fwd, turn_back, [go_park]; entered ..., turn_fwd, turn_back, [none])",
        "expect_states: DriveInit1's 2nd leaf state since the start: expected none, got turn_fwd"
        " (expected power_on, [none]; entered power_on, [turn_fwd], turn_back)",
        # in order, others between: the first one missing, and what came after the one before it
        "expect_states: DriveInit1 since the start: expected go_park (2nd of the sequence) after turn_fwd,"
        " got turn_back"]
    assert all(f.message.endswith("; DriveInit1 is in turn_back") for f in r.failures)


def test_an_input_the_wiring_feeds_needs_force() -> None:
    r = run("""\
        name: not forced
        steps:
          - set: {DriveInit2.ini1: true}
          - expect: "DriveInit2.ini1"
          - run: {chart_steps: 3}
          - expect: "false"
        """)
    assert lines(r) == [3]
    assert "DriveInit2.ini1 was overwritten at the next chart step (now false)" in r.failures[0].message
    assert "add 'force: true'" in r.failures[0].message
    forced = run("""\
        name: forced
        steps:
          - set: {DriveInit2.ini1: true}
            force: true
          - run_until: {entered: DriveInit2.turn_one_way, timeout_s: 0.01}
          - expect: "DriveInit1.turn_fwd and not DriveInit1.ini_23"
          - release: DriveInit2.ini1
          - run: {chart_steps: 1}
          - expect: "not DriveInit2.ini1"
        """)
    assert forced.passed, forced.failures


def test_a_start_pose_beyond_the_hard_stops_is_refused() -> None:
    r = run("""\
        name: impossible
        start:
          q_deg: [0, 0, 40]
        steps:
          - run: {seconds: 1}
        """)
    assert lines(r) == [3] and r.steps_run == 0
    assert "q3 = 40 deg is beyond the joint's hard stops (-150 .. 30 deg)" in r.failures[0].message


def test_start_pose_seed_and_settling_reach_the_robot() -> None:
    seen: dict[str, Any] = {}

    def factory(scenario, params, listeners):
        robot = Robot(params, seed=scenario.seed, q_start=[math.radians(v) for v in scenario.start.q_deg],
                      settle_s=scenario.start.settle_s, listeners=listeners)
        seen["q"] = robot.truth.q
        seen["seed"] = robot.seed
        return robot
    r = run("""\
        name: held up
        seed: 7
        start: {q_deg: [10, 30, 0]}
        steps:
          - expect: "abs(q_true[2] - 30deg) < 0.01deg and abs(q_true[1] - 10deg) < 0.01deg"
        """, robot_factory=factory)
    assert r.passed, r.failures
    assert seen["seed"] == 7
    settled = run("""\
        name: settled
        start: {q_deg: [0, 30, 0], settle_s: 1.0}
        steps:
          - expect: "q_true[2] < 20deg"
        """)
    assert settled.passed, settled.failures  # gravity pulls the unpowered shoulder down


def test_coverage_counts_the_initial_states() -> None:
    cov = Coverage()
    r = run("name: nothing happens\nsteps:\n  - expect: 'true'\n", coverage=cov)
    assert r.passed
    report = {c.chart: c for c in cov.report().charts}
    assert {"DriveInit1", "DriveInit2", "DriveInit3"} <= set(report)  # every chart of the robot
    assert report["DriveInit1"].entered == ("run", "initialise", "power_on")
    assert report["DriveInit2"].entered == ("wait_ini1",) and report["DriveInit2"].taken == ()


def test_signal_table_matches_the_robot() -> None:
    robot = Robot(PARAMS, seed=0)
    values = robot.signal_values()
    for name, size in SIGNALS.items():
        assert name in values, name
        assert (len(values[name]) if isinstance(values[name], list) else None) == size, name


# -- events, data and errors, on a stand-in robot with a chart that has events ---------------------


class Lamp(TickChart):
    """A lamp switched by an event that carries the brightness."""

    tick_period_s = 0.002
    inputs = (Data("power", "bool", True, "mains"),)
    outputs = (Data("level", "1", 0.0, "brightness"),)

    off = State(initial=True)
    on = State()
    switch = off.to(on, cond="power", on="dim") | on.to(off)

    def dim(self, level: float = 1.0) -> None:
        if level < 0:
            raise ValueError("a lamp cannot be dimmer than off")
        self.level = level


class LampRobot:
    """Just what the runner needs, around one Lamp."""

    def __init__(self, scenario, params, listeners) -> None:
        self.params = SimpleNamespace(control=SimpleNamespace(chart_dt=0.002), drives=())
        self.lamp = Lamp(listeners=list(listeners))
        self.charts = {"Lamp": self.lamp}
        self.ticks = 0

    @property
    def t(self) -> float:
        return self.ticks * 0.002

    def chart(self, name: str) -> TickChart:
        return self.charts[name]

    def run_until(self, predicate, timeout_s: float) -> bool:
        for _ in range(round(timeout_s / 0.002)):
            self.lamp.tick()
            self.ticks += 1
            if predicate():
                return True
        return False

    def set_input(self, chart: str, name: str, value: Any, force: bool = False) -> None:
        setattr(self.charts[chart], name, value)

    def release(self, chart: str, name: str) -> None:
        pass

    def post(self, chart: str, event: str, **data: Any) -> None:
        self.charts[chart].post(event, **data)

    def value(self, chart: str, name: str) -> Any:
        return getattr(self.charts[chart], name)

    def active(self, chart: str) -> set[str]:
        return set(self.charts[chart].configuration_values)

    def signal_values(self) -> dict[str, Any]:
        return {"t": self.t}


LAMP = Catalog({"Lamp": Lamp}, {"t": None})


def run_lamp(text: str):
    return run(text, catalog=LAMP, params=PARAMS, robot_factory=LampRobot)


def test_post_sends_an_event_with_data_at_the_next_tick() -> None:
    r = run_lamp("""\
        name: switch the lamp on
        steps:
          - post: {chart: Lamp, event: switch, data: {level: 0.5}}
          - expect: "Lamp.off"
          - run: {chart_steps: 1}
          - expect: "Lamp.on and Lamp.level == 0.5"
          - set: {Lamp.power: false}
          - post: {chart: Lamp, event: switch}
          - post: {chart: Lamp, event: switch}
          - run: {chart_steps: 1}
          - expect: "Lamp.off"
          - expect_states: {chart: Lamp, sequence: [off, on, off], match: exact}
        """)
    assert r.passed, r.failures


def test_an_error_raised_by_a_chart_is_a_failure_at_its_step() -> None:
    r = run_lamp("""\
        name: too dim
        steps:
          - post: {chart: Lamp, event: switch, data: {level: -1}}
          - run: {seconds: 0.1}
          - expect: "true"
        """)
    assert lines(r) == [4] and r.steps_run == 2
    assert r.failures[0].message == "run: ValueError: a lamp cannot be dimmer than off"


def test_an_expression_error_at_run_time_is_a_failure() -> None:
    r = run_lamp("name: n\nsteps:\n  - expect: 't / 0 > 1'\n")
    assert lines(r) == [3] and "cannot compute '/'" in r.failures[0].message


@pytest.mark.parametrize("text, message", [
    ("name: n\nsteps:\n  - post: {chart: Lamp, event: swtch}\n", "Lamp handles no event 'swtch' (did you mean"
                                                                   " 'switch'?); events: switch"),
    ("name: n\nsteps:\n  - post: {chart: Lamp, event: switch, data: [1]}\n", "data expected a mapping"),
])
def test_post_checks_the_event(text: str, message: str) -> None:
    from ttt_sm.scenario import ScenarioError

    with pytest.raises(ScenarioError) as info:
        load_scenario_text(text, "s.yaml", catalog=LAMP)
    assert message in str(info.value)
