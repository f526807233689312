"""Bare-chart mode: ``chart: Game`` runs that chart alone, no robot; its names checked for the mode."""

from __future__ import annotations

import dataclasses
import textwrap
from typing import Any

import pytest
from statemachine import State

from ttt_sm.app.robot import Robot
from ttt_sm.charts import AlgorithmActivator, Game
from ttt_sm.params import load_params
from ttt_sm.runtime import Data, TickChart, after_s
from ttt_sm.runtime.listeners import Coverage
from ttt_sm.scenario import SIGNALS, Catalog, ScenarioError, load_scenario_text, run_scenario, run_scenarios
from ttt_sm.scenario.robots import ChartsOnly

PARAMS = load_params(None)


class Latch(TickChart):
    """Takes a request and clears it itself: an input a bare scenario sets, and the chart writes."""

    tick_period_s = 1.0  # overridden: a bare chart runs at the arm's chart rate
    inputs = (Data("request", "bool", False, "asked for"),)
    outputs = (Data("taken", "1", 0, "requests taken"),)
    taken: int  # for type checkers: counts up from its own value

    idle = State(initial=True)
    busy = State()
    idle.to(busy, cond="request", on="take")
    busy.to(idle, cond=after_s(0.01))
    poke = idle.to(busy, on="take")

    def take(self) -> None:
        self.request = False
        self.taken = self.taken + 1


CATALOG = Catalog({"Latch": Latch, "Game": Game, "AlgorithmActivator": AlgorithmActivator,
                   "Robotic": Latch}, {**SIGNALS}, robot_charts=("Robotic",))


def load(text: str, catalog: Catalog | None = CATALOG):
    return load_scenario_text(textwrap.dedent(text), "s.yaml", catalog=catalog)


def run(text: str, **kwargs: Any):
    return run_scenario(load(text, kwargs.pop("catalog", CATALOG)), kwargs.pop("params", PARAMS), **kwargs)


def test_a_passing_bare_scenario_ticks_the_chart_alone_at_the_chart_rate() -> None:
    r = run("""\
        name: the latch takes a request
        chart: Latch
        steps:
          - expect: "Latch.idle and t == 0"
          - set: {Latch.request: true}
          - run: {chart_steps: 1}
          - expect: "Latch.busy and Latch.taken == 1 and not Latch.request and t == 0.002"
          - run_until: {entered: Latch.idle, timeout_s: 0.01}
          - expect: "t == 0.012"
          - post: {chart: Latch, event: poke}
          - run: {seconds: 0.004}
          - expect: "Latch.busy and Latch.taken == 2"
          - expect_states: {chart: Latch, sequence: [idle, busy, idle, busy], match: exact}
        """)
    # The chart cleared the input the scenario set: nothing to report (no wiring overwrote it).
    assert r.passed, [str(f) for f in r.failures]
    assert r.steps_run == r.steps_total == 10
    assert r.sim_time_s == pytest.approx(0.016)
    assert r.wall_time_s < 1.0


def test_a_failing_bare_scenario_names_its_lines() -> None:
    r = run("""\
        name: wrong on purpose
        chart: Game
        steps:
          - run: {chart_steps: 1}
          - expect: 'Game.message == "Wait for the model to be compiled."'
          - expect_states: {chart: Game, sequence: [compiling, your_turn]}
          - set: {Game.ready: true}
          - run_until: {entered: Game.game_over, timeout_s: 0.1}
          - expect: "false"
        """)
    assert [f.where.line for f in r.failures] == [5, 6, 8]
    assert r.steps_run == 5
    m = [f.message for f in r.failures]
    assert m[0] == ("expect: 'Game.message == \"Wait for the model to be compiled.\"' is false; t = 0.002 s;"
                    " Game.message = 'The compilation is done wait for the manipulator to be initialized.'")
    assert m[1] == ("expect_states: Game since the start: expected your_turn (2nd of the sequence) after"
                    " compiling, got initialising; Game is in initialising")
    assert m[2] == ("run_until: Game did not enter game_over within 0.1 s (from t = 0.002 s to 0.102 s);"
                    " Game is in your_turn; it entered playing, your_turn meanwhile")


def test_the_charts_run_at_the_arms_chart_rate() -> None:
    slow = dataclasses.replace(PARAMS, control=dataclasses.replace(PARAMS.control,
                                                                    chart_divider=2 * PARAMS.control.chart_divider))
    assert slow.control.chart_dt == pytest.approx(0.004)
    text = """\
        name: the result shows for 2 s of chart time
        chart: Game
        steps:
          - set: {Game.ready: true, Game.result: 2}
          - run_until: {entered: Game.game_over, timeout_s: 1}
          - expect: "t == 3 * {dt}"
          - run_until: {entered: Game.erasing, timeout_s: 3}
          - expect: "abs(t - (2 + 3 * {dt})) < 1e-9"
        """
    for params in (PARAMS, slow):
        dt = params.control.chart_dt
        r = run(text.replace("{dt}", f"{dt:g}"), params=params)
        assert r.passed, [str(f) for f in r.failures]
    robot = ChartsOnly(load("name: n\nchart: Game\nsteps:\n  - run: {seconds: 1}\n").bare, slow, [])
    assert robot.chart("Game").tick_period_s == pytest.approx(0.004)


def test_several_charts_tick_together_and_one_chart_can_run_under_names_of_ones_own() -> None:
    cov = Coverage()
    r = run("""\
        name: two latches and an activator
        charts:
          first: Latch
          second: Latch
          AlgorithmActivator: AlgorithmActivator
        steps:
          - set: {first.request: true}
          - post: {chart: AlgorithmActivator, event: trigger}
          - run: {chart_steps: 1}
          - expect: "first.busy and second.idle and AlgorithmActivator.enable"
          - expect_states: {chart: second, sequence: [idle], match: exact}
        """, coverage=cov)
    assert r.passed, [str(f) for f in r.failures]
    report = {c.chart: c for c in cov.report().charts}
    assert set(report) == {"Latch", "AlgorithmActivator"}  # coverage adds instances up per class
    assert report["Latch"].taken == ("idle -> busy: tick [request]",)
    listed = run("name: n\ncharts: [Latch, Game]\nsteps:\n  - run: {chart_steps: 1}\n"
                 "  - expect: Game.initialising and Latch.idle\n")
    assert listed.passed, [str(f) for f in listed.failures]


def test_the_default_catalog_runs_the_game_charts_bare_and_knows_the_robots_charts() -> None:
    catalog = Catalog.default()
    assert catalog.robot_charts == tuple(Robot(PARAMS).charts)
    assert {"AlgorithmActivator", "Game"} <= set(catalog.charts) - set(catalog.robot_charts or ())
    report = run_scenarios([load("name: n\nchart: AlgorithmActivator\nsteps:\n"
                                 "  - post: {chart: AlgorithmActivator, event: trigger}\n"
                                 "  - run: {chart_steps: 1}\n  - expect: AlgorithmActivator.enable\n",
                                 catalog=None)], PARAMS, coverage=True)
    assert report.passed and report.coverage is not None
    assert [c.chart for c in report.coverage.charts] == ["AlgorithmActivator"]  # no robot was built


S = "name: n\nchart: Latch\nsteps:\n"  # the head of a bare scenario whose steps a case is about


@pytest.mark.parametrize("text, line, message", [
    # the mode itself
    ("name: n\nchart: Lach\nsteps:\n  - run: {seconds: 1}\n", 2,
     "chart: unknown chart 'Lach' (did you mean 'Latch'?); charts: Latch, Game, AlgorithmActivator, Robotic"),
    ("name: n\nchart: [Latch]\nsteps:\n  - run: {seconds: 1}\n", 2, "chart: expected a chart name like"),
    ("name: n\ncharts: []\nsteps:\n  - run: {seconds: 1}\n", 2, "got an empty list"),
    ("name: n\ncharts: Latch\nsteps:\n  - run: {seconds: 1}\n", 2, "charts: expected a chart name like"),
    ("name: n\ncharts:\n  - Latch\n  - Gaem\nsteps:\n  - run: {seconds: 1}\n", 4,
     "charts: unknown chart 'Gaem' (did you mean 'Game'?)"),
    ("name: n\ncharts: [Latch, Latch]\nsteps:\n  - run: {seconds: 1}\n", 2, "charts: Latch is listed twice"),
    ("name: n\ncharts:\n  a: Latch\n  b: Lath\nsteps:\n  - run: {seconds: 1}\n", 4, "unknown chart 'Lath'"),
    ("name: n\ncharts:\n  a: Latch\n  two words: Latch\nsteps:\n  - run: {seconds: 1}\n", 4,
     "charts: 'two words' cannot name a chart in a condition"),
    ("name: n\ncharts:\n  not: Latch\nsteps:\n  - run: {seconds: 1}\n", 3, "cannot name a chart"),
    ("name: n\ncharts:\n  Game: Latch\nsteps:\n  - run: {seconds: 1}\n", 3,
     "charts: Game is the name of a chart: name the Latch otherwise"),
    ("name: n\nchart: Latch\ncharts: [Game]\nsteps:\n  - run: {seconds: 1}\n", 3,
     "chart: and charts: exclude each other"),
    ("name: n\nchart: Latch\nstart: {q_deg: [0, 0, 0]}\nsteps:\n  - run: {seconds: 1}\n", 3,
     "start: this bare-chart scenario (line 2) runs only Latch, without the arm: there is no pose"),
    # the data, states and events of charts it does not run
    (S + "  - set: {Game.ready: true}\n", 4, "set: Game is not run: this bare-chart scenario (line 2) runs"
                                             " only Latch"),
    (S + "  - post: {chart: Game, event: stop}\n", 4, "post: Game is not run"),
    (S + "  - expect: Latch.idle and Game.off\n", 4, "expect: Game is not run"),
    (S + "  - run_until: {entered: Game.off, timeout_s: 1}\n", 4, "run_until: Game is not run"),
    (S + "  - expect_states: {chart: Game, sequence: [off]}\n", 4, "expect_states: Game is not run"),
    ("name: n\ncharts: {a: Latch}\nsteps:\n  - set: {Latch.request: true}\n", 4,
     "Latch is not run: this bare-chart scenario (line 2) runs only a (Latch)"),
    (S + "  - set: {Latch.requst: true}\n", 4, "Latch has no input 'requst' (did you mean 'request'?)"),
    # signals of the arm, forcing and releasing
    (S + "  - expect: q_true[1] > 0\n", 4, "expect: q_true is a signal of the simulated arm; this bare-chart"
                                           " scenario (line 2) runs only Latch, without the arm: a condition"
                                           " reads the charts' data and states, and t (chart time)"),
    (S + "  - run_until: {condition: fr_sw, timeout_s: 1}\n", 4,
     "run_until: fr_sw is a signal of the simulated arm"),
    (S + "  - expect: tt > 0\n", 4, "unknown name 'tt' (did you mean 't'?)"),
    (S + "  - expect: t[1] > 0\n", 4, "signal t is a single value"),
    (S + "  - set: {Latch.request: true}\n    force: true\n", 5,
     "force: this bare-chart scenario (line 2) runs only Latch: nothing feeds the charts' inputs"),
    (S + "  - release: Latch.request\n", 4, "release: this bare-chart scenario (line 2) runs only Latch:"
                                            " nothing feeds the charts' inputs"),
])
def test_mistakes_in_bare_mode_name_file_line_and_what(text: str, line: int, message: str) -> None:
    with pytest.raises(ScenarioError) as info:
        load(text)
    err = info.value
    assert message in err.message, err.message
    assert err.line == line, str(err)


def test_a_robot_scenario_cannot_name_a_chart_the_robot_does_not_hold() -> None:
    with pytest.raises(ScenarioError) as info:
        load("name: n\nsteps:\n  - run: {seconds: 1}\n  - expect: Game.off\n", catalog=None)
    assert str(info.value) == ("s.yaml:4: expect: Game is not part of the simulated robot (its charts:"
                               " DriveInit1, DriveInit2, DriveInit3, Control, Safety); run it alone: put 'chart: Game'"
                               " at the top of the file")
    s = load("name: n\nsteps:\n  - set: {Robotic.request: true}\n  - expect: q_true[1] > 0\n")
    assert s.bare is None


def test_a_run_stopped_between_two_scenarios_ends_its_report_saying_so(tmp_path) -> None:
    # a loaded soak run met it: the signal came after one scenario ended and before the next began, and
    # the report's ending said neither where the run stood nor how many scenarios it had done
    from ttt_sm.runtime.recordfile import RecordFile
    from ttt_sm.runtime.recordfile import read_lines as read_record

    text = """\
        name: latch N
        chart: Latch
        steps:
          - run: {seconds: 0.01}
    """
    scenarios = [load(text.replace("N", str(n))) for n in (1, 2)]

    def stop_after_the_first(_result: Any) -> None:
        raise KeyboardInterrupt

    report = RecordFile(tmp_path / "report.jsonl")
    with pytest.raises(KeyboardInterrupt):
        run_scenarios(scenarios, PARAMS, report_file=report, progress=stop_after_the_first)
    lines = read_record(tmp_path / "report.jsonl")
    assert [e["event"] for e in lines] == ["scenario", "interrupted"]
    assert lines[-1]["scenario"] is None and lines[-1]["scenarios_done"] == 1
