"""Scenario files: the format, and errors that name file, line and what was wrong."""

from __future__ import annotations

import textwrap
from pathlib import Path

import pytest

from ttt_sm.scenario import ScenarioError, ScenarioErrors, load_scenario, load_scenario_text, scenario_files
from ttt_sm.scenario.loader import TOP_KEYS
from ttt_sm.scenario.model import (
    ExpectStatesStep,
    ExpectStep,
    MarkStep,
    ReleaseStep,
    RunStep,
    RunUntilStep,
    SetStep,
)
from ttt_sm.scenario.source import MarkedDict, MarkedList, load_yaml

GOOD = """\
name: a scenario using every step
description: one of each
seed: 3
start: {q_deg: [0, 30, 28.5], settle_s: 0.5}
steps:
  - set: {DriveInit1.stop: true, DriveInit1.pos_in: 1}
  - set: {DriveInit2.index: false}
    force: true
  - release: DriveInit2.index
  - release: [DriveInit1.index, DriveInit3.index]
  - run: {seconds: 0.5}
  - run: {chart_steps: 3}
  - run_until: {entered: DriveInit1.turn_back, timeout_s: 10}
  - run_until: {active: DriveInit1.run, timeout_s: 1}
  - run_until: {condition: "DriveInit1.pos_Encoder > 1.0", timeout_s: 5}
  - expect: "DriveInit1.ini_23 == true"
  - expect: {condition: "q_true[2] > 10deg", within_s: 2}
  - expect: {condition: "not DriveInit1.failed", for_s: 1}
  - mark: after the turn
  - mark:
  - expect_states: {chart: DriveInit1, sequence: [turn_fwd, turn_back]}
  - expect_states: {chart: DriveInit1, sequence: [turn_back], match: exact}
"""


S = "name: n\nsteps:\n"  # the head of a file whose steps a case is about


def load(text: str):
    return load_scenario_text(textwrap.dedent(text), "s.yaml")


def error_of(text: str) -> ScenarioError:
    with pytest.raises(ScenarioError) as info:
        load(text)
    return info.value


def test_every_step_kind_loads_with_its_line() -> None:
    s = load(GOOD)
    assert (s.name, s.description, s.seed) == ("a scenario using every step", "one of each", 3)
    assert s.start.q_deg == (0.0, 30.0, 28.5, 0.0) and s.start.settle_s == 0.5
    kinds = [type(step) for step in s.steps]
    assert kinds == [SetStep, SetStep, ReleaseStep, ReleaseStep, RunStep, RunStep, RunUntilStep, RunUntilStep,
                     RunUntilStep, ExpectStep, ExpectStep, ExpectStep, MarkStep, MarkStep, ExpectStatesStep,
                     ExpectStatesStep]
    assert [step.where.line for step in s.steps] == [6, 7, *range(9, 23)]
    assert str(s.steps[0].where) == "s.yaml:6"
    first = s.steps[0]
    assert isinstance(first, SetStep) and not first.force
    assert [(str(r), v) for r, v in first.values] == [("DriveInit1.stop", True), ("DriveInit1.pos_in", 1.0)]
    second = s.steps[1]
    assert isinstance(second, SetStep) and second.force
    until = s.steps[6]
    assert isinstance(until, RunUntilStep) and str(until.entered) == "DriveInit1.turn_back"
    assert until.timeout_s == 10
    exp = s.steps[10]
    assert isinstance(exp, ExpectStep) and exp.within_s == 2 and exp.for_s is None
    states = s.steps[15]
    assert isinstance(states, ExpectStatesStep) and states.match == "exact"
    assert s.steps[12] == MarkStep(s.steps[12].where, "after the turn")


def test_defaults() -> None:
    s = load(S + "  - run: {seconds: 1}\n")
    assert s.seed == 0 and s.start.q_deg is None and s.start.settle_s == 0 and s.description == ""


def test_marked_loader_keeps_lines_and_is_safe() -> None:
    data = load_yaml("a: 1\nb:\n  - x\n  - {c: 2}\n", "f.yaml")
    assert isinstance(data, MarkedDict) and data.key_lines == {"a": 1, "b": 2}
    assert isinstance(data["b"], MarkedList) and data["b"].item_lines == [3, 4]
    assert data["b"][1].line == 4 and data == {"a": 1, "b": ["x", {"c": 2}]}
    # YAML 1.2 booleans: state names like on and off stay text.
    assert load_yaml("[on, off, yes, no, true, False]", "f.yaml") == ["on", "off", "yes", "no", True, False]
    with pytest.raises(ScenarioError, match="f.yaml:1: not valid YAML"):
        load_yaml("!!python/object/apply:os.system ['true']\n", "f.yaml")


@pytest.mark.parametrize("text, line, message", [
    # YAML itself
    (S + "  - run: {seconds: 1\n", 3, "flow mapping started on line 3"),
    (S + "  - run: {seconds: 1}\n    expect: x\n  - set: [a\n", 5, "not valid YAML"),
    ("name: n\nname: m\nsteps: []\n", 2, "key 'name' given twice (first on line 1)"),
    # top level
    ("- run: {seconds: 1}\n", 1, "a scenario file is a mapping"),
    ("name: n\n", 1, "missing steps:"),
    ("steps:\n  - run: {seconds: 1}\n", 1, "missing name:"),
    ("name: n\nstep:\n  - run: {seconds: 1}\n", 2, "unknown key 'step' (did you mean 'steps'?)"),
    ("name: n\nsteps: []\n", 2, "steps: expected a list of steps"),
    ("name: n\nseed: -1\nsteps:\n  - run: {seconds: 1}\n", 2, "seed: expected a whole number >= 0"),
    ("name: 3\nsteps:\n  - run: {seconds: 1}\n", 1, "name: expected text, got number 3"),
    ("name: n\nstart: {q_deg: [1, 2]}\nsteps:\n  - run: {seconds: 1}\n", 2, "list of 3 or 4"),
    ("name: n\nstart: {pose: [1, 2, 3]}\nsteps:\n  - run: {seconds: 1}\n", 2, "start: unknown key 'pose'"),
    # step shape
    (S + "  - runn: {seconds: 1}\n", 3, "unknown step kind 'runn' (did you mean 'run'?)"),
    (S + "  - wait 1 s\n", 3, "a step is a mapping"),
    (S + "  - run: {seconds: 1}\n    expect: x\n", 4, "one step, two actions ('run' and 'expect')"),
    (S + "  - run: {seconds: 1}\n    force: true\n", 4, "run: unknown key 'force'"),
    # set / release
    (S + "  - set: {DriveInit4.stop: true}\n", 3, "unknown chart 'DriveInit4' (did you mean"),
    (S + "  - set: {DriveInit1.stopp: true}\n", 3, "DriveInit1 has no input 'stopp' (did you mean 'stop'?)"),
    (S + "  - set: {DriveInit1.ini_23: true}\n", 3, "DriveInit1.ini_23 is an output, not an input"),
    (S + "  - set: {DriveInit1.stop: 1}\n", 3, "DriveInit1.stop is a flag: expected true or false"),
    (S + "  - set: {DriveInit1.pos_in: yes please}\n", 3, "DriveInit1.pos_in is a number (rad)"),
    (S + "  - set:\n      DriveInit1.stop: true\n      DriveInit1.pos_in: x\n", 5, "is a number"),
    (S + "  - set: {stop: true}\n", 3, "set: expected Chart.input like DriveInit1.stop"),
    (S + "  - set: {DriveInit1.stop: true}\n    force: 1\n", 4, "force: expected true or false"),
    (S + "  - set: {DriveInit1.stop: yes}\n", 3, "expected true or false, got text 'yes'"),
    (S + "  - release:\n    - DriveInit1.index\n    - DriveInit1.offset\n", 5,
     "DriveInit1.offset is an output"),
    # post
    (S + "  - post: {chart: DriveInit1, event: go}\n", 3,
     "DriveInit1 handles no event 'go'; events: (none: all its transitions are tick transitions)"),
    (S + "  - post: {chart: DriveInit1}\n", 3, "post: missing event:"),
    # run / run_until
    (S + "  - run: 1\n", 3, "run: expected {seconds: S} or {chart_steps: N}"),
    (S + "  - run: {seconds: -1}\n", 3, "run: seconds must be > 0"),
    (S + "  - run: {chart_steps: 1.5}\n", 3, "chart_steps expected a whole number"),
    (S + "  - run: {minutes: 1}\n", 3, "run: unknown key 'minutes'"),
    (S + "  - run_until: {entered: DriveInit1.turn_back}\n", 3, "run_until: missing timeout_s:"),
    (S + "  - run_until: {timeout_s: 1}\n", 3, "give exactly one of entered, active, condition"),
    (S + "  - run_until: {entered: DriveInit1.turn_bak, timeout_s: 1}\n", 3,
     "DriveInit1 has no state 'turn_bak' (did you mean 'turn_back'?)"),
    (S + "  - run_until: {entered: DriveInit1.h, timeout_s: 1}\n", 3, "history pseudo-state"),
    (S + "  - run_until: {entered: DriveInit1.turn_back, timeout_s: soon}\n", 3,
     "timeout_s expected a number, got text 'soon'"),
    (S + "  - run_until:\n      condition: DriveInit1.x > 1\n      timeout_s: 1\n", 4,
     "DriveInit1 has no datum or state 'x'"),
    # conditions
    (S + "  - expect: DriveInit1.pos_Encoder >> 1\n", 3, "at column 25"),
    (S + "  - expect: q_tru[1] > 0\n", 3, "unknown name 'q_tru' (did you mean 'q_true'?)"),
    (S + "  - expect: q_true[0] > 0\n", 3, "numbered from 1"),
    (S + "  - expect: q_true[5] > 0\n", 3, "q_true[5] out of range"),
    (S + "  - expect: q_true > 0\n", 3, "signal q_true has 4 values: pick one"),
    (S + "  - expect: t[1] > 0\n", 3, "signal t is a single value"),
    (S + "  - expect: DriveInit1.stop[1]\n", 3, "DriveInit1.stop is not a list"),
    (S + "  - expect: 3\n", 3, "expect: expected a condition"),
    (S + "  - expect: {within_s: 1}\n", 3, "expect: missing condition:"),
    (S + "  - expect:\n      condition: t > 1\n      within_s: 1\n      for_s: 1\n", 6,
     "within_s (holds at some moment) and for_s (holds all the time) exclude each other"),
    # expect_states
    (S + "  - expect_states: {chart: DriveInit1}\n", 3, "expect_states: missing sequence:"),
    (S + "  - expect_states:\n      chart: DriveInit1\n      sequence:\n        - turn_fwd\n"
     "        - turn_forward\n", 7, "DriveInit1 has no state 'turn_forward'"),
    (S + "  - expect_states: {chart: DriveInit1, sequence: [run], match: exact}\n", 3,
     "DriveInit1.run is a compound state; an exact sequence lists the leaf states"),
    (S + "  - expect_states: {chart: DriveInit1, sequence: [run], match: strict}\n", 3,
     "match expected one of subsequence, exact"),
    (S + "  - mark: [1]\n", 3, "mark: expected a label"),
])
def test_mistakes_name_file_line_and_what(text: str, line: int, message: str) -> None:
    err = error_of(text)
    assert err.file == "s.yaml"
    assert message in err.message, err.message
    assert err.line == line, str(err)
    assert str(err).startswith(f"s.yaml:{line}: ")


def test_a_file_error_names_the_path(tmp_path: Path) -> None:
    path = tmp_path / "drive_1_does_something.yaml"
    path.write_text(S + "  - run: {seconds: 1}\n  - expect: DriveInit1.nothing\n")
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert str(info.value).startswith(f"{path}:4: expect: DriveInit1 has no datum or state 'nothing'")
    with pytest.raises(ScenarioError, match="cannot read the file"):
        load_scenario(tmp_path / "missing.yaml")


def test_folders_expand_to_their_yaml_files(tmp_path: Path) -> None:
    for name in ("b.yaml", "a.yml", "notes.txt"):
        (tmp_path / name).write_text("x")
    assert [p.name for p in scenario_files([tmp_path])] == ["a.yml", "b.yaml"]
    assert scenario_files([tmp_path / "b.yaml"]) == [tmp_path / "b.yaml"]


def test_every_mistake_of_a_file_is_reported_in_line_order_as_a_compiler_does() -> None:
    err = error_of("""\
        name: typos
        seed: -1
        steps:
          - run_until: {entered: DriveInit1.turn_bak, timeout_s: 5}
          - expect: "q_tru[1] > 165deg and DriveInit1.nothing"
          - expect_state: {chart: DriveInit1, sequence: [turn_fwd]}
          - run: {seconds: 1}
          - expect_states: {chart: DriveInit1, sequence: [turn_fwd, turn_forward, go_parkk]}
        """)
    assert isinstance(err, ScenarioErrors)
    found = [(e.line, e.message.split(" (did you mean")[0].split(";")[0]) for e in err.errors]
    assert found == [
        (2, "seed: expected a whole number >= 0, got number -1"),
        (4, "run_until: DriveInit1 has no state 'turn_bak'"),
        (5, "expect: unknown name 'q_tru'"),  # two names of one condition: two mistakes
        (5, "expect: DriveInit1 has no datum or state 'nothing'"),
        (6, "unknown step kind 'expect_state'"),
        (8, "expect_states: DriveInit1 has no state 'turn_forward'"),
        (8, "expect_states: DriveInit1 has no state 'go_parkk'"),
    ]
    assert str(err).splitlines() == [str(e) for e in err.errors]  # one FILE:LINE: message each
    assert all(line.startswith("s.yaml:") for line in str(err).splitlines())
    assert (err.line, err.message) == (err.errors[0].line, err.errors[0].message)  # the first, for one-line use


def test_what_the_rest_cannot_be_read_without_stops_the_reading() -> None:
    # a misspelt steps: is one mistake, not also a missing steps:
    err = error_of("name: n\nstep:\n  - run: {seconds: 1}\n")
    assert [str(e) for e in err.errors] == ["s.yaml:2: scenario: unknown key 'step' (did you mean 'steps'?);"
                                            " keys: " + ", ".join(TOP_KEYS)]
    # unknown bare charts: the steps cannot be checked against them; the mistakes before are kept
    err = error_of("name: n\nseed: x\nchart: Gam\nsteps:\n  - expect: Gam.ready\n")
    assert [(e.line, e.message.split(" (")[0]) for e in err.errors] == [
        (2, "seed: expected a whole number >= 0, got text 'x'"), (3, "chart: unknown chart 'Gam'")]
    # a mistake within a step stops that step only: the next step is checked
    err = error_of(S + "  - post: {chart: Control, evnt: button, dat: {}}\n  - run: {seconds: -1}\n")
    assert [(e.line, e.message.split(";")[0]) for e in err.errors] == [
        (3, "post: unknown key 'evnt' (did you mean 'event'?)"), (3, "post: unknown key 'dat' (did you mean 'data'?)"),
        (4, "run: seconds must be > 0, got -1")]
