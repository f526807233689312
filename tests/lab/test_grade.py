"""``ttt-sm lab grade``: a class whose code loops, sleeps, hoards memory or does not parse still gets a line
per student, the reports hold them all, an interrupt keeps what was graded, and a Dask cluster grades alike.

The class (tests/lab/grade_class.py) is the algorithm_activator exercise (the quickest to check) written
seven ways; the limits are short so that the students who never finish cost seconds, not minutes.
"""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from grade_class import EXERCISE, REFERENCE, kinds, make_class

from ttt_sm.cli import main
from ttt_sm.lab.grade import RESULTS, read_results
from ttt_sm.lab.grade_report import build_reports

#: Short limits: the wall clock a submission may take, s, and the address space it may map, MB.  The reference
#: grades in 0.9 s on an idle machine: 10 s leaves room for a machine loaded four times over.
TIMEOUT = "10"
MEMORY = "1200"
#: What each student's line must say: their status, and whether they passed.
EXPECTED = {
    "ada_reference": ("graded", True),
    "ben_skeleton": ("graded", False),
    "cy_syntax_error": ("load error", False),
    "dee_endless_loop": ("time limit", False),
    "eve_memory_hog": ("memory limit", False),
    "fay_never_finishes": ("time limit", False),
    "gus_no_file": ("load error", False),
    "hal_wrong_contract": ("load error", False),
}


def _class(folder: Path) -> Path:
    subs = make_class(folder / "submissions")
    (subs / "gus_no_file").mkdir()  # a student who handed in nothing
    return subs


def _grade(capsys, subs: Path, out: Path, *more: str) -> tuple[int, str]:
    status = main(["lab", "grade", str(subs), "--exercise", EXERCISE, "--out", str(out), "--timeout", TIMEOUT,
                   "--memory", MEMORY, *more])
    return status, capsys.readouterr().err


@pytest.fixture(scope="module")
def graded(tmp_path_factory) -> tuple[Path, Path, int]:
    """The class graded once on the local pool: (submissions, report folder, exit status)."""
    root = tmp_path_factory.mktemp("grade")
    subs = _class(root)
    out = root / "report"
    status = main(["lab", "grade", str(subs), "--exercise", EXERCISE, "--out", str(out), "--timeout", TIMEOUT,
                   "--memory", MEMORY, "--workers", "2"])
    return subs, out, status


def _by_student(out: Path) -> dict[str, dict]:
    return read_results(out / RESULTS)[1]


def test_each_submission_gets_its_result_line(graded):
    _, out, status = graded
    assert status == 0
    results = _by_student(out)
    assert {s: (r["status"], r["passed"]) for s, r in results.items()} == EXPECTED
    assert results["ada_reference"]["score"] == results["ada_reference"]["total"] >= 2
    ben = results["ben_skeleton"]
    assert 0 < ben["score"] < ben["total"] and ben["error"] == ""
    assert results["cy_syntax_error"]["error"] == ("cy_syntax_error/algorithm_activator.py:14:"
                                                   " syntax error: invalid syntax")
    assert results["gus_no_file"]["error"] == "gus_no_file/algorithm_activator.py: no such file"
    assert results["hal_wrong_contract"]["error"].startswith(
        "hal_wrong_contract/algorithm_activator.py:14: class MyActivator does not fit the AlgorithmActivator slot")
    for name in ("dee_endless_loop", "fay_never_finishes"):
        assert results[name]["error"].startswith(f"still running after {TIMEOUT} s: stopped"), results[name]
    assert "ran out of memory" in results["eve_memory_hog"]["error"]
    assert f"limit {MEMORY} MB" in results["eve_memory_hog"]["error"]


def test_no_child_outlives_the_grading(graded):
    import psutil

    # this test process's own children only: they inherit its environment, and under pytest-xdist the
    # other worker may be grading a class of the same names at this very moment
    worker = os.environ.get("PYTEST_XDIST_WORKER")
    left = [p.info["cmdline"] for p in psutil.process_iter(["cmdline", "environ"])
            if (p.info["environ"] or {}).get("PYTEST_XDIST_WORKER") == worker
            and any("dee_endless_loop/" in a or "fay_never_finishes/" in a for a in p.info["cmdline"] or [])]
    assert left == []


def test_the_csv_json_and_html_hold_every_student(graded):
    _, out, _ = graded
    with (out / "grades.csv").open(encoding="utf-8") as f:
        rows = {row["student"]: row for row in csv.DictReader(f)}
    assert set(rows) == set(EXPECTED)
    assert rows["ada_reference"]["passed"] == "yes" and rows["ben_skeleton"]["passed"] == "no"
    check = "a click enables the algorithm for one step"
    assert rows["ada_reference"][check] == "pass" and rows["ben_skeleton"][check] == "fail"
    assert rows["cy_syntax_error"][check] == "" and "syntax error" in rows["cy_syntax_error"]["error"]
    assert rows["dee_endless_loop"]["status"] == "time limit"

    report = json.loads((out / "report.json").read_text(encoding="utf-8"))
    assert report["students"] == len(EXPECTED) and report["passed"] == 1
    assert report["statuses"] == {"graded": 2, "load error": 3, "time limit": 2, "memory limit": 1}
    [shared, *_] = report["shared_failures"]
    assert shared["check"] == check and set(shared["students"]) == {"ben_skeleton", "eve_memory_hog"}
    assert shared["typical_reason"]
    heat = {row["transition"]: row for row in report["transitions"]}
    assert "ada_reference" in heat["armed -> enabled: trigger"]["taken_by"]

    page = (out / "report.html").read_text(encoding="utf-8")
    for student in EXPECTED:
        assert student in page
    assert "Transitions each chart took" in page and "The failures most of the class shares" in page


def test_the_page_escapes_what_students_wrote(tmp_path):
    (tmp_path / RESULTS).write_text(
        json.dumps({"event": "grade", "exercise": EXERCISE}) + "\n"
        + json.dumps({"student": "<script>x</script>", "exercise": EXERCISE, "status": "load error",
                      "passed": False, "score": 0, "total": 0, "checks": [], "error": "<b>oops</b>"}) + "\n"
        + '{"student": "cut off mid-wri', encoding="utf-8")
    report = build_reports(tmp_path)
    page = (tmp_path / "report.html").read_text(encoding="utf-8")
    assert "<script>x" not in page and "&lt;script&gt;x" in page and "&lt;b&gt;oops" in page
    assert report["students"] == 1  # the line a kill cut short is left out


def test_progress_is_a_line_per_submission_k_of_n(tmp_path, capsys):
    subs = make_class(tmp_path / "subs", {"ada": REFERENCE, "cy": kinds()["cy_syntax_error"]})
    status, err = _grade(capsys, subs, tmp_path / "out", "--workers", "1")
    assert status == 0
    lines = err.splitlines()
    assert lines[0].startswith("1/2 ") and lines[1].startswith("2/2 ")
    assert "ada: 2/2 every check passed" in err and "cy: load error: cy/algorithm_activator.py:14" in err
    assert "reports in" in lines[-1]


def test_an_interrupt_keeps_the_results_and_a_rerun_grades_only_the_rest(tmp_path, capsys):
    subs = make_class(tmp_path / "subs", {"a1": REFERENCE, "a2": REFERENCE, "b1": kinds()["ben_skeleton"],
                                          "d1": kinds()["dee_endless_loop"]})
    out = tmp_path / "out"
    argv = [sys.executable, "-m", "ttt_sm.cli", "lab", "grade", str(subs), "--exercise", EXERCISE, "--out", str(out),
            "--timeout", "300", "--memory", MEMORY, "--workers", "1"]
    grader = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 240
    while time.monotonic() < deadline and grader.poll() is None:
        if (out / RESULTS).is_file() and len(_by_student(out)) >= 2:
            break
        time.sleep(0.2)
    grader.send_signal(signal.SIGINT)
    _, err = grader.communicate(timeout=60)
    assert grader.returncode == 130, err
    assert "Traceback" not in err and "stopped:" in err and "interrupted" in err
    kept = _by_student(out)
    assert {"a1", "a2"} <= set(kept) and "d1" not in kept  # the endless loop was running, not finished
    assert (out / "grades.csv").is_file() and "a1" in (out / "report.html").read_text(encoding="utf-8")

    # the rerun keeps the results there, grades the rest
    status, err = _grade(capsys, subs, out, "--workers", "2")
    assert status == 0 and "already holds" in err
    lines = [json.loads(line) for line in (out / RESULTS).read_text(encoding="utf-8").splitlines()]
    graded = [line["student"] for line in lines if "student" in line]
    assert sorted(graded) == ["a1", "a2", "b1", "d1"]  # each once
    assert _by_student(out)["d1"]["status"] == "time limit"


@pytest.mark.soak  # a LocalCluster of two workers grading the class again: 40-70 s
def test_a_dask_cluster_gives_the_same_grades(graded, tmp_path, capsys):
    from dask.distributed import LocalCluster

    subs, out, _ = graded
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster:
        status, err = _grade(capsys, subs, tmp_path / "on-dask", "--dask", cluster.scheduler_address)
    assert status == 0, err
    local, on_dask = _by_student(out), _by_student(tmp_path / "on-dask")

    def grades(results: dict[str, dict]) -> dict[str, tuple]:
        return {s: (r["status"], r["passed"], r["score"], r["total"],
                    [(c["name"], c["passed"]) for c in r["checks"]]) for s, r in results.items()}
    assert grades(on_dask) == grades(local)


# -- bad input: one line, exit status 2 ---------------------------------------------------------------

def _one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


def test_an_unknown_exercise_is_one_line(tmp_path, capsys):
    status = main(["lab", "grade", str(tmp_path), "--exercise", "drive_init9", "--out", str(tmp_path / "o")])
    line = _one_line(capsys.readouterr().err)
    assert status == 2 and "no exercise 'drive_init9'" in line


def test_a_missing_or_empty_submissions_folder_is_one_line(tmp_path, capsys):
    status = main(["lab", "grade", str(tmp_path / "nope"), "--exercise", EXERCISE, "--out", str(tmp_path / "o")])
    assert status == 2 and "nope: no such folder" in _one_line(capsys.readouterr().err)
    (tmp_path / "empty").mkdir()
    status = main(["lab", "grade", str(tmp_path / "empty"), "--exercise", EXERCISE, "--out", str(tmp_path / "o")])
    assert status == 2 and "no sub-folders" in _one_line(capsys.readouterr().err)


def test_an_unwritable_out_is_one_line(tmp_path, capsys):
    subs = make_class(tmp_path / "subs", {"ada": REFERENCE})
    status = main(["lab", "grade", str(subs), "--exercise", EXERCISE, "--out", "/sys/ttt-sm-cannot-write-here"])
    assert status == 2 and "cannot write there" in _one_line(capsys.readouterr().err)


def test_a_report_folder_of_another_exercise_is_one_line(tmp_path, capsys):
    subs = make_class(tmp_path / "subs", {"ada": REFERENCE})
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / RESULTS).write_text(json.dumps({"event": "grade", "exercise": "drive_init1"}) + "\n")
    status = main(["lab", "grade", str(subs), "--exercise", EXERCISE, "--out", str(tmp_path / "out")])
    assert status == 2 and "holds results of exercise 'drive_init1'" in _one_line(capsys.readouterr().err)


def test_dask_without_dask_installed_is_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "dask.distributed", None)  # import dask.distributed now fails
    subs = make_class(tmp_path / "subs", {"ada": REFERENCE})
    status = main(["lab", "grade", str(subs), "--exercise", EXERCISE, "--out", str(tmp_path / "o"),
                   "--dask", "tcp://127.0.0.1:1"])
    line = _one_line(capsys.readouterr().err)
    assert status == 2 and "--dask needs Dask: pip install 'ttt_sm[cluster]'" in line


def test_an_unreachable_scheduler_is_one_line(tmp_path, capsys):
    subs = make_class(tmp_path / "subs", {"ada": REFERENCE})
    status = main(["lab", "grade", str(subs), "--exercise", EXERCISE, "--out", str(tmp_path / "o"),
                   "--dask", "tcp://127.0.0.1:9"])
    line = _one_line(capsys.readouterr().err)
    assert status == 2 and "cannot reach a Dask scheduler" in line


@pytest.mark.parametrize("option,value", [("--workers", "0"), ("--timeout", "nan"), ("--memory", "-5")])
def test_bad_limits_are_refused_naming_the_option(tmp_path, capsys, option, value):
    with pytest.raises(SystemExit) as stop:
        main(["lab", "grade", str(tmp_path), "--exercise", EXERCISE, "--out", str(tmp_path / "o"), option, value])
    err = capsys.readouterr().err  # argparse's usage, then the one error line
    assert stop.value.code == 2 and "Traceback" not in err
    assert f"ttt-sm lab grade: error: argument {option}:" in err.strip().splitlines()[-1]

