"""The lab: every exercise's reference (the thesis chart) passes its checks and its skeleton fails them;
a student's file that cannot run is one line with file:line; ``--chart`` runs a file's class in a slot."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from ttt_sm.app.chart_file import ChartFileError, load_chart
from ttt_sm.app.slots import SLOTS, ChartSlots, SlotError, contract, contract_problems, slot
from ttt_sm.cli import main
from ttt_sm.lab.checks import check_folder, run_checks
from ttt_sm.lab.exercise import exercises

NAMES = [e.name for e in exercises()]
CHARTS_SRC = Path(__file__).resolve().parents[2] / "src" / "ttt_sm" / "charts"


def test_there_are_five_exercises_each_with_its_pages():
    assert len(NAMES) >= 5
    for ex in exercises():
        assert (ex.folder / "task.md").is_file(), ex.name
        assert ex.chart_file.is_file(), ex.name


@pytest.mark.parametrize("name", NAMES)
def test_the_thesis_chart_passes_its_exercise(name, params):
    ex = next(e for e in exercises() if e.name == name)
    report = run_checks(ex, slot(ex.slot).thesis, "thesis", params)
    assert report.passed, report.to_text()
    assert report.score[0] == report.score[1] >= 2


@pytest.mark.parametrize("name", NAMES)
def test_the_skeleton_loads_and_fails_its_exercise(name, params):
    ex = next(e for e in exercises() if e.name == name)
    report = check_folder(ex.folder, params)
    assert not report.passed
    failed = [c for c in report.checks if not c.passed]
    assert all(c.reason for c in failed)  # each failure says why


def test_the_drive_init3_skeleton_fails_for_the_reasons_a_student_can_act_on(params):
    ex = next(e for e in exercises() if e.name == "drive_init3")
    report = check_folder(ex.folder, params)
    by_name = {c.name: c for c in report.checks}
    init = by_name["the drives initialise within 20 s"]
    assert not init.passed and "your DriveInit3 is in approach" in init.reason
    slow = by_name["drive 3 touches its switch slowly"]
    assert not slow.passed and "drive_3_touches_its_switch_slowly.yaml:13: expect: 'DriveInit3.pos_out > 0.08'" \
        in slow.reason
    assert by_name["the Safety chart never tripped"].passed


# -- files that cannot run: one line, file:line -------------------------------------------------------

def _run(capsys, *argv: str) -> tuple[int, str, str]:
    status = main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


def _student(tmp_path: Path, text: str, name: str = "mine.py") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _one_error_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


def test_a_syntax_error_is_one_line_with_file_and_line(tmp_path, capsys):
    path = _student(tmp_path, "from ttt_sm.runtime import TickChart\n\nclass A(TickChart:\n    pass\n")
    status, _, err = _run(capsys, "--chart", f"DriveInit3={path}:A", "draw", "X")
    line = _one_error_line(err)
    assert status == 2 and re.search(r"mine\.py:3: syntax error", line), line


def test_an_import_error_is_one_line_with_file_and_line(tmp_path, capsys):
    path = _student(tmp_path, "import math\nimport no_such_module_here\n")
    status, _, err = _run(capsys, "--chart", f"DriveInit3={path}:A", "scenario", "run", "x.yaml")
    line = _one_error_line(err)
    assert status == 2 and "mine.py:2: ModuleNotFoundError: No module named 'no_such_module_here'" in line


def test_an_invalid_chart_definition_is_one_line_with_file_and_line(tmp_path, capsys):
    path = _student(tmp_path, "from statemachine import State\nfrom ttt_sm.runtime import TickChart\n\n\n"
                              "class A(TickChart):\n    a = State(initial=True)\n    b = State()\n")
    status, _, err = _run(capsys, "--chart", f"DriveInit3={path}:A", "draw", "X")
    line = _one_error_line(err)
    assert status == 2 and "mine.py:5: InvalidDefinition:" in line and "unreachable" in line, line


def _copy_of_thesis_init3(tmp_path: Path, edit=lambda s: s) -> Path:
    """The thesis' drive_init.py as a student's file: absolute imports, a new module, new classes."""
    text = (CHARTS_SRC / "drive_init.py").read_text(encoding="utf-8")
    text = text.replace("from ..runtime import", "from ttt_sm.runtime import")
    return _student(tmp_path, edit(text), "thesis_copy.py")


def test_a_missing_input_and_a_wrong_unit_are_one_error_naming_both_with_the_class_line(tmp_path, capsys):
    def edit(s: str) -> str:
        s = s.replace('Data("ini2", "bool", False, "drive 2 is initialised"),\n    )\n    outputs = (\n'
                      '        _POS_OUT,\n        _OFFSET,\n        Data("ini3"',
                      ')\n    outputs = (\n        _POS_OUT,\n        _OFFSET,\n        Data("ini3"')
        return s.replace('Data("index_pos", "rad", 0.0, "encoder angle latched at the switch',
                         'Data("index_pos", "deg", 0.0, "encoder angle latched at the switch')
    path = _copy_of_thesis_init3(tmp_path, edit)
    line_of_class = next(n for n, text in enumerate(path.read_text().splitlines(), 1)
                         if text.startswith("class DriveInit3"))
    status, _, err = _run(capsys, "--chart", f"DriveInit3={path}:DriveInit3", "draw", "X")
    line = _one_error_line(err)
    assert status == 2
    assert f"thesis_copy.py:{line_of_class}: class DriveInit3 does not fit the DriveInit3 slot:" in line
    assert "missing input ini2 (bool)" in line and "input index_pos is in 'deg', the slot's is in 'rad'" in line


def test_an_extra_input_and_a_wrong_kind_are_named():
    from ttt_sm.charts import DriveInit1
    problems = contract_problems("DriveInit3", DriveInit1)
    assert "ini3 is declared input, the slot's is output ini3 (bool)" in problems
    assert "extra input pos_Encoder (nothing feeds it in this slot)" in problems
    with pytest.raises(SlotError, match="no chart slot 'Safety'"):
        ChartSlots().with_chart("Safety", DriveInit1, "x.py:1")


def test_every_thesis_chart_meets_its_own_slot():
    for s in SLOTS:
        assert contract_problems(s.name, s.thesis) == []
        assert contract(s.name)


def test_a_missing_class_names_the_charts_in_the_file(tmp_path):
    path = _copy_of_thesis_init3(tmp_path)
    with pytest.raises(ChartFileError, match=r"thesis_copy\.py:1: no class 'Nope'.*DriveInit1, DriveInit2"):
        load_chart(path, "Nope")


# -- --chart on scenario run and draw: the thesis chart from a file does what the built-in does -----

def test_scenario_run_with_the_reference_from_a_file_gives_the_built_in_outcome(tmp_path, capsys):
    path = _copy_of_thesis_init3(tmp_path)
    scenario = next(e for e in exercises() if e.name == "drive_init3").folder / "checks"
    status, out, _ = _run(capsys, "scenario", "run", str(scenario), "--json")
    built_in = json.loads(out)
    status2, out2, _ = _run(capsys, "--chart", f"DriveInit3={path}:DriveInit3", "scenario", "run", str(scenario),
                            "--json")
    from_file = json.loads(out2)
    assert status == status2 == 0
    keep = ("name", "passed", "failures", "sim_time_s", "steps_run")
    assert [{k: r[k] for k in keep} for r in built_in["scenarios"]] == \
        [{k: r[k] for k in keep} for r in from_file["scenarios"]]


def test_draw_with_the_reference_from_a_file_draws_the_same_x(tmp_path, capsys):
    path = _copy_of_thesis_init3(tmp_path)
    status, out, _ = _run(capsys, "draw", "X", "--json")
    status2, out2, _ = _run(capsys, "--chart", f"DriveInit3={path}:DriveInit3", "draw", "X", "--json")
    a, b = json.loads(out), json.loads(out2)
    assert status == status2 == 0
    for key in ("rms_error_mm", "max_error_mm", "ink_points", "duration_s", "sim_time_s"):
        assert a[key] == b[key], key


def test_a_skeleton_in_a_slot_changes_what_the_robot_does(tmp_path, capsys):
    ex = next(e for e in exercises() if e.name == "drive_init3")
    status, out, err = _run(capsys, "--chart", f"DriveInit3={ex.chart_file}:MyDriveInit3", "draw", "X")
    last = err.strip().splitlines()[-1]
    assert status == 2 and last == "ttt-sm draw: error: the drives did not initialise within 40 s"


# -- the commands -------------------------------------------------------------------------------------

def test_lab_start_copies_and_refuses_a_non_empty_folder(tmp_path, capsys):
    target = tmp_path / "work"
    status, out, _ = _run(capsys, "lab", "start", "drive_init3", str(target))
    assert status == 0 and (target / "task.md").is_file() and (target / "drive_init3.py").is_file()
    assert sorted(p.name for p in (target / "checks").iterdir()) == sorted(
        p.name for p in (next(e for e in exercises() if e.name == "drive_init3").folder / "checks").iterdir())
    status, _, err = _run(capsys, "lab", "start", "drive_init3", str(target))
    assert status == 2 and _one_error_line(err).endswith("is not empty: start an exercise in a new or empty folder")


def test_lab_check_json_scores_the_skeleton_and_exits_1(tmp_path, capsys):
    target = tmp_path / "work"
    _run(capsys, "lab", "start", "algorithm_activator", str(target))
    status, out, _ = _run(capsys, "lab", "check", str(target), "--json")
    report = json.loads(out)
    assert status == 1 and report["passed"] is False
    assert report["score"]["passed"] < report["score"]["total"]


def test_lab_check_passes_a_solved_exercise(tmp_path, capsys):
    target = tmp_path / "work"
    _run(capsys, "lab", "start", "algorithm_activator", str(target))
    text = (CHARTS_SRC / "game.py").read_text(encoding="utf-8")
    text = text.replace("from ..runtime import", "from ttt_sm.runtime import")
    (target / "algorithm_activator.py").write_text(text + "\n\nclass MyActivator(AlgorithmActivator):\n    pass\n")
    status, out, _ = _run(capsys, "lab", "check", str(target))
    assert status == 0 and out.rstrip().endswith("every check passed"), out


def test_lab_list_names_every_exercise(capsys):
    status, out, _ = _run(capsys, "lab", "list")
    assert status == 0 and all(name in out for name in NAMES)


def test_chart_is_refused_by_a_command_that_does_not_build_a_robot(tmp_path, capsys):
    status, _, err = _run(capsys, "--chart", "DriveInit3=x.py:A", "params")
    assert status == 2 and "--chart is not taken by params" in _one_error_line(err)


def test_chart_and_a_lab_folder_together_are_refused_in_one_line(tmp_path, capsys):
    status, _, err = _run(capsys, "--chart", "DriveInit3=x.py:A", "gui", "--lab", str(tmp_path))
    assert status == 2 and "--chart and gui --lab" in _one_error_line(err)
