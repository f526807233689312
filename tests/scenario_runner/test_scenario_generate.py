"""Generated scenarios (docs/scenarios.md, "Generated scenarios"): they pass on the real runner and take
every reachable transition; what cannot be taken is said with the reason; the scenarios kill mutants."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from statemachine import State

from ttt_sm.charts import ALL_CHARTS, DriveInit3
from ttt_sm.cli import main
from ttt_sm.params import load_params
from ttt_sm.runtime import Data, Junction, TickChart
from ttt_sm.scenario import SIGNALS, Catalog, load_scenario, run_scenarios
from ttt_sm.scenario.generate import generate, write
from ttt_sm.scenario.mutate import mutation_test, summary

PARAMS = load_params(None)
DT = PARAMS.control.chart_dt


def _run(paths: list[Path], catalog: Catalog | None = None):
    return run_scenarios([load_scenario(p, catalog) for p in paths], PARAMS, coverage=True)


@pytest.mark.parametrize("cls", ALL_CHARTS, ids=lambda c: c.__name__)
def test_the_generated_scenarios_pass_and_take_every_transition(cls, tmp_path) -> None:
    generated = generate(cls, DT)
    paths = write(generated, tmp_path, "test")
    report = _run(paths)
    assert report.passed, [str(f) for r in report.results for f in r.failures]
    (coverage,) = [c for c in report.coverage.charts if c.chart == cls.__name__]
    assert not generated.unreachable, generated.unreachable  # every transition of the project's charts
    assert set(coverage.taken) == set(coverage.transitions)
    summary_ = generated.to_dict()
    assert summary_["covered"] == summary_["transitions"] == len(coverage.transitions)
    assert summary_["tour_lower_bound"] == len(coverage.transitions)
    assert summary_["scenarios"] == len(paths) and summary_["steps"] >= summary_["scenarios"]


@pytest.mark.parametrize("name", ["DriveInit1", "DriveInit3", "AlgorithmActivator", "Game"])
def test_tours_are_fewer_longer_scenarios_that_take_every_transition(name, tmp_path) -> None:
    cls = next(c for c in ALL_CHARTS if c.__name__ == name)
    shortest, tour = generate(cls, DT, "shortest"), generate(cls, DT, "tour")
    report = _run(write(tour, tmp_path, "test"))
    assert report.passed
    assert set(report.coverage.charts[0].taken) == set(tour.transitions)
    assert len(tour.scenarios) < len(shortest.scenarios)
    assert max(len(s.path) for s in tour.scenarios) >= max(len(s.path) for s in shortest.scenarios)


def test_a_generated_file_says_what_it_takes_and_checks_the_path(tmp_path) -> None:
    generated = generate(DriveInit3, DT)
    text = next(p for p in write(generated, tmp_path, "test") if "approach_to_back_off" in p.name).read_text()
    assert "# The shortest path found to:\n#   approach -> back_off: tick [index]\n" in text
    assert "index = true makes 'index' true" in text  # the input's value, from the guard
    assert "  # takes approach -> back_off: tick [index] (after 1 chart step)\n" in text
    assert text.rstrip().endswith(
        "expect_states: {chart: DriveInit3, sequence: [wait_ini1, approach, back_off], match: exact}")
    # the runner holds the file to its path: a step that took the other way fails it
    wrong = tmp_path / "wrong" / "wrong.yaml"
    wrong.parent.mkdir()
    wrong.write_text(text.replace("set: {DriveInit3.index: true}", "set: {DriveInit3.index: false}"))
    assert not _run([wrong]).passed


class Sorter(TickChart):
    """A request sorted at a junction by its size: each segment is a decision outcome of its own."""

    inputs = (Data("size", "1", 0, "size of the request"),)
    local = (Data("big", "1", 0, "big requests"),)

    idle = State(initial=True)
    small = State()
    large = State()
    j = Junction()
    request = idle.to(j)
    j.to(large, cond="size > 10", on="count")
    j.to(small)
    done = small.to(idle) | large.to(idle)

    def count(self) -> None:
        self.big = self.big + 1


class Dead(TickChart):
    """Transitions no input can take, each for its own reason."""

    inputs = (Data("x", "1", 0, "an input"),)
    local = (Data("count", "1", 0, "nothing changes it"),)

    idle = State(initial=True)
    busy = State()
    never = State()
    idle.to(busy, cond="x > 3")
    idle.to(never, cond="x > 3 and not (x > 3)")
    busy.to(idle, cond="count >= 5")
    never.to(idle)


def _catalog(cls: type[TickChart]) -> Catalog:
    return Catalog({cls.__name__: cls}, SIGNALS, ())


def test_junction_segments_are_each_taken_with_the_input_at_its_boundary(tmp_path) -> None:
    generated = generate(Sorter, DT)
    assert not generated.unreachable
    paths = write(generated, tmp_path, "test")
    report = _run(paths, _catalog(Sorter))
    coverage = report.coverage.charts[0]
    assert report.passed and set(coverage.taken) == set(coverage.transitions)
    text = "".join(p.read_text() for p in paths)
    assert "Sorter.size: 11" in text  # just past 'size > 10'


def test_what_cannot_be_taken_is_reported_with_the_reason(tmp_path) -> None:
    generated = generate(Dead, DT)
    reasons = generated.unreachable
    assert set(reasons) == {"idle -> never: tick [x > 3 and not (x > 3)]", "busy -> idle: tick [count >= 5]",
                            "never -> idle: tick"}
    assert "never true" in reasons["idle -> never: tick [x > 3 and not (x > 3)]"]
    assert "reads only the chart's own data (count)" in reasons["busy -> idle: tick [count >= 5]"]
    assert "never is never active" in reasons["never -> idle: tick"]
    # the reachable one is taken, and the files pass
    report = _run(write(generated, tmp_path, "test"), _catalog(Dead))
    assert report.passed
    assert report.coverage.charts[0].taken == ("idle -> busy: tick [x > 3]",)
    assert generated.to_dict()["tour_lower_bound"] == 1


def test_the_generated_scenarios_kill_the_mutants_of_drive_3(tmp_path) -> None:
    scenarios = [load_scenario(p) for p in write(generate(DriveInit3, DT), tmp_path, "test")]
    results = mutation_test(DriveInit3, scenarios, PARAMS)
    counts = summary(results)
    assert counts["mutants"] >= 15 and counts["stillborn"] == 0
    assert counts["kill_ratio"] >= 0.9, [r.to_dict() for r in results if r.status == "survived"]
    assert counts["killed"] >= 0.8 * counts["mutants"]
    kinds = {r.mutant.kind for r in results if r.status == "killed"}
    assert kinds == {"flip", "swap", "drop"}
    assert all(r.detail for r in results if r.status == "equivalent")
    # one scenario alone kills fewer: the ratio measures the scenarios
    fewer = summary(mutation_test(DriveInit3, scenarios[:1], PARAMS, check_equivalence=False))
    assert fewer["killed"] < counts["killed"]


@pytest.mark.soak
@pytest.mark.parametrize("cls", [c for c in ALL_CHARTS if c is not DriveInit3], ids=lambda c: c.__name__)
def test_the_generated_scenarios_kill_the_mutants_of_every_chart(cls, tmp_path) -> None:
    """The target on every chart of the robot; of Control's 132 mutants (4 minutes) every fourth."""
    scenarios = [load_scenario(p) for p in write(generate(cls, DT), tmp_path, "test")]
    results = mutation_test(cls, scenarios, PARAMS, stride=4 if cls.__name__ == "Control" else 1)
    counts = summary(results)
    assert counts["mutants"] >= 5 and counts["stillborn"] == 0
    assert counts["kill_ratio"] >= 0.9, [r.to_dict() for r in results if r.status == "survived"]
    assert all(r.detail for r in results if r.status == "equivalent")


@pytest.mark.soak
def test_generation_is_the_same_whatever_python_hashes_strings_with(tmp_path) -> None:
    """Control's tour once chose among equally short paths in a set's order: with these three hash seeds it
    wrote three different sets of files."""
    import os
    import subprocess
    import sys

    texts = []
    for seed in ("0", "3", "11"):
        out = tmp_path / seed
        done = subprocess.run([sys.executable, "-m", "ttt_sm.cli", "scenario", "generate", "Control", "--strategy",
                               "tour", "--out", str(out)], env={**os.environ, "PYTHONHASHSEED": seed},
                              capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, done.stderr
        texts.append({f.name: f.read_text() for f in sorted(out.iterdir())})
    assert texts[0] == texts[1] == texts[2] and len(texts[0]) >= 3


# -- the command line -----------------------------------------------------------------------

def _one_error_line(capsys) -> str:
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, captured.err
    assert "Traceback" not in captured.err + captured.out
    return lines[0]


@pytest.mark.parametrize("argv", [["scenario", "generate", "DriveInt3"],
                                  ["scenario", "mutate", "DriveInt3", "tests/scenarios"]])
def test_an_unknown_chart_is_one_line_naming_it_and_the_choices(argv, capsys) -> None:
    assert main(argv) == 2
    line = _one_error_line(capsys)
    assert "unknown chart 'DriveInt3'" in line and "DriveInit3" in line and "Safety" in line


def test_an_unwritable_out_folder_is_one_line(tmp_path, capsys) -> None:
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    assert main(["scenario", "generate", "DriveInit3", "--out", str(blocker / "sub")]) == 2
    assert str(blocker / "sub") in _one_error_line(capsys)


def test_generate_json_then_run_with_coverage(tmp_path, capsys) -> None:
    out = tmp_path / "gen"
    assert main(["scenario", "generate", "AlgorithmActivator", "--out", str(out), "--strategy", "tour",
                 "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)["charts"]["AlgorithmActivator"]
    assert doc["covered"] == doc["transitions"] == 7 and doc["unreachable"] == []
    assert doc["scenarios"] == len(doc["files"]) == len(list(out.glob("*.yaml")))
    assert main(["scenario", "run", str(out), "--coverage"]) == 0
    assert "AlgorithmActivator: states 3/3, transitions 7/7" in capsys.readouterr().out


def test_suggest_writes_a_scenario_for_each_transition_never_taken(tmp_path, capsys) -> None:
    gen = tmp_path / "gen"
    assert main(["scenario", "generate", "DriveInit2", "--out", str(gen)]) == 0
    one = sorted(gen.glob("*.yaml"))[0]
    capsys.readouterr()
    suggested = tmp_path / "suggested"
    assert main(["scenario", "run", str(one), "--coverage", "--suggest", str(suggested)]) == 0
    out = capsys.readouterr().out
    missing = re.findall(r"never taken:\s+(.*)", out)
    assert missing and len(re.findall(r"^suggested for DriveInit2 ", out, re.M)) == len(missing)
    # the given scenario and the suggested ones together take every transition
    assert main(["scenario", "run", str(one), str(suggested), "--coverage"]) == 0
    assert "DriveInit2: states 7/7, transitions 7/7" in capsys.readouterr().out


def test_suggest_without_coverage_is_one_line(tmp_path, capsys) -> None:
    path = tmp_path / "g"
    assert main(["scenario", "generate", "DriveInit1", "--out", str(path)]) == 0
    capsys.readouterr()
    assert main(["scenario", "run", str(path), "--suggest", str(tmp_path / "s")]) == 2
    assert "--coverage" in _one_error_line(capsys)


def test_mutate_reports_the_kill_ratio(tmp_path, capsys) -> None:
    gen = tmp_path / "gen"
    assert main(["scenario", "generate", "DriveInit3", "--out", str(gen)]) == 0
    capsys.readouterr()
    assert main(["scenario", "mutate", "DriveInit3", str(gen), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["kill_ratio"] >= 0.9 and doc["killed"] + doc["survived"] + doc["equivalent"] == doc["mutants"]
    # a robot scenario is not run against mutants: said, not silently passed
    assert main(["scenario", "mutate", "DriveInit3", "tests/scenarios/drive_1_turns_back_at_a_hard_stop.yaml"]) == 2
    assert "runs DriveInit3 bare" in _one_error_line(capsys)


def _x_drops():
    from ttt_sm.charts.control import Control
    from ttt_sm.scenario.mutate import mutants

    return [m for m in mutants(Control) if m.override and m.description.startswith("XDrawing.")]


def test_the_actions_control_mixes_in_are_drop_mutants() -> None:
    """Control's actions live in a module per sub-chart (charts/control_drawing.py, ...), mixed into the chart
    class: each is still a ``drop`` mutant, the chart with the method overridden to do nothing."""
    from ttt_sm.charts.control import Control
    from ttt_sm.scenario.mutate import build, mutants

    found = mutants(Control)
    mixed = {m.description.split(":")[0] for m in found if m.override}
    actions = {f"{base.__name__}.{name}" for base in Control.__mro__[1:] if base.__module__.startswith(
        "ttt_sm.charts.control_") for name in vars(base) if name.startswith(("on_enter_", "on_exit_", "during_"))
        and getattr(getattr(base, name), "__name__", "") == name}
    assert mixed == actions and len(mixed) >= 30
    x_drops = _x_drops()
    assert len(x_drops) >= 3 and all(m.file.endswith("control_drawing.py") for m in x_drops)
    dropped = build(Control, x_drops[0])(tick_period_s=DT, chart_name="Control")
    assert getattr(dropped, x_drops[0].override).__doc__ == "The dropped action: does nothing."
    assert getattr(Control(tick_period_s=DT), x_drops[0].override).__doc__ != "The dropped action: does nothing."


@pytest.mark.soak
def test_the_generated_scenarios_kill_the_drops_of_the_actions_control_mixes_in(tmp_path) -> None:
    from ttt_sm.charts.control import Control
    from ttt_sm.scenario.mutate import build, first_failure, runs_chart

    x_drops = _x_drops()
    scenarios = [s for s in (load_scenario(p) for p in write(generate(Control, DT), tmp_path, "test"))
                 if runs_chart(s, "Control")]
    assert scenarios and first_failure(scenarios, "Control", Control, PARAMS) is None  # the chart passes them
    for m in x_drops:
        assert first_failure(scenarios, "Control", build(Control, m), PARAMS) is not None, m.description
