"""Scenarios post a chart's local events and expect the ones it broadcasts (``expect_events``),
and coverage counts every segment of a path through a junction."""

from __future__ import annotations

import textwrap

import pytest
from statemachine import State

from ttt_sm.params import load_params
from ttt_sm.runtime import Data, Junction, TickChart
from ttt_sm.runtime.listeners import Coverage
from ttt_sm.scenario import SIGNALS, Catalog, ScenarioError, load_scenario_text, run_scenario

PARAMS = load_params(None)


class Relay(TickChart):
    """A request is sorted at a junction; the big ones tell the counter with a local event."""

    tick_period_s = 1.0  # a bare chart runs at the arm's chart rate
    inputs = (Data("size", "1", 0, "size of the request"),)
    local = (Data("big", "1", 0, "big requests counted"),)

    class sorter(State.Parallel):
        class desk(State.Compound):
            idle = State(initial=True)
            small = State()
            large = State()
            j = Junction()
            request = idle.to(j)
            j.to(large, cond="size > 10", on="tell")
            j.to(small)
            done = small.to(idle) | large.to(idle)

        class counter(State.Compound):
            waiting = State(initial=True)
            counted = State()
            noted = waiting.to(counted, on="count") | counted.to(waiting, on="count")

    def tell(self) -> None:
        self.send("noted")  # a local event: the counter takes it at once, within this wake-up

    def count(self) -> None:
        self.big = self.big + 1


CATALOG = Catalog({"Relay": Relay}, {**SIGNALS})


def load(text: str):
    return load_scenario_text(textwrap.dedent(text), "s.yaml", catalog=CATALOG)


def test_a_scenario_expects_the_local_events_a_path_broadcasts_and_coverage_counts_each_segment():
    coverage = Coverage()
    scenario = load("""\
        name: a big request is sorted to large and told to the counter
        chart: Relay
        steps:
          - set: {Relay.size: 12}
          - post: {chart: Relay, event: request}
          - run: {chart_steps: 1}
          - expect: "Relay.large and Relay.counted and Relay.big == 1"
          - expect_events: {chart: Relay, sequence: [noted], match: exact}
          - mark: small ones
          - post: {chart: Relay, event: done}
          - set: {Relay.size: 3}
          - post: {chart: Relay, event: request}
          - run: {chart_steps: 1}
          - expect: "Relay.small and Relay.big == 1"
          - expect_events: {chart: Relay, sequence: [], match: exact}
          - post: {chart: Relay, event: noted}
          - post: {chart: Relay, event: done}
          - run: {chart_steps: 1}
          - expect: "Relay.waiting and Relay.idle and Relay.big == 2"
        """)
    result = run_scenario(scenario, PARAMS, coverage=coverage)
    assert result.passed, [str(f) for f in result.failures]
    (report,) = coverage.report().charts
    taken = set(report.taken)
    # both ways out of the junction, each a segment of its own (decision coverage)
    assert {"j -> large: tick [size > 10]", "j -> small: tick", "idle -> j: request"} <= taken
    assert report.missing_transitions == ()


def test_a_wrong_local_event_sequence_fails_on_its_line_and_an_unknown_event_is_refused():
    scenario = load("""\
        name: expects a broadcast that did not happen
        chart: Relay
        steps:
          - set: {Relay.size: 3}
          - post: {chart: Relay, event: request}
          - run: {chart_steps: 1}
          - expect_events: {chart: Relay, sequence: [noted]}
        """)
    result = run_scenario(scenario, PARAMS)
    assert not result.passed
    (failure,) = result.failures
    assert failure.where.line == 7 and "expected local event noted" in str(failure)
    with pytest.raises(ScenarioError, match="s.yaml:7: expect_events: Relay has no event 'nothed'"):
        load("""\
            name: a typo
            chart: Relay
            steps:
              - run: {chart_steps: 1}
              - expect_events:
                  chart: Relay
                  sequence: [nothed]
            """)
