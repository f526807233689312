"""Every subcommand of ``ttt-sm`` with bad arguments: one error line that names the argument, never a traceback.

The whole command line, not one argument at a time (tests/test_cli_fuzz.py
fuzzes single arguments): bad numbers, missing, unreadable and unwritable
paths, folders where files belong, files where folders belong, garbage
files.  Each command line runs in a process of its own (tests/cli_sweep.py
forks one per case after importing the CLI once) with its standard input
closed to typing, and must end with a non-zero status, within the driver's
time limit (refused before anything runs), with no ``Traceback`` and no
"internal error" anywhere in its output, and with one line on standard error
that says ``error`` and names the argument or the path.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

DRIVER = Path(__file__).with_name("cli_sweep.py")

#: Bad values of a whole-number option.
BAD_INTS = ("abc", "1.5", "", "9" * 400)
#: Bad values of a number that must be positive and finite.
BAD_POSITIVE = ("abc", "nan", "inf", "-1", "0", "1e400")
#: Bad values of a number that must be finite (any sign).
BAD_FINITE = ("abc", "nan", "inf", "-inf", "1e400")

#: A folder no one can write into, even as root (sysfs refuses new entries).
READ_ONLY = "/sys/ttt-sm-cannot-write-here"


def _paths(tmp: Path) -> dict[str, str]:
    """Bad paths: missing, a folder, a file where a folder belongs, garbage, not writable, not readable."""
    garbage = tmp / "garbage.bin"
    garbage.write_bytes(bytes(range(256)) * 8 + b"\x00\xff{[(")
    folder = tmp / "a-folder"
    folder.mkdir()
    (folder / "inside.txt").write_text("x")
    return {"missing": str(tmp / "no" / "such" / "file.toml"), "folder": str(folder),
            "file_as_folder": str(garbage / "sub"), "garbage": str(garbage), "read_only": READ_ONLY,
            "proc": "/proc/version/x"}


def _cases(tmp: Path) -> list[tuple[list[str], str]]:
    """(argv, what the error line must name) for every subcommand."""
    p = _paths(tmp)
    cases: list[tuple[list[str], str]] = []

    def numbers(base: list[str], option: str, bad: tuple[str, ...]) -> None:
        cases.extend(([*base, option, value], option) for value in bad)

    def out_dirs(base: list[str], option: str | None = "--out") -> None:
        for key in ("file_as_folder", "read_only", "proc"):
            argv = [*base, option, p[key]] if option else [*base, p[key]]
            cases.append((argv, p[key]))

    def in_files(base: list[str], option: str | None, keys: tuple[str, ...] = ("missing", "folder", "garbage")) -> None:
        for key in keys:
            argv = [*base, option, p[key]] if option else [*base, p[key]]
            cases.append((argv, p[key]))

    # the parameter file every robot command reads
    for command in (["params"], ["ik", "150", "0", "100"], ["init", "--starts", "1"], ["demo"], ["tune"],
                    ["precision", "staircase", "--count", "1"]):
        for key in ("missing", "folder", "garbage"):
            cases.append((["--params", p[key], *command], p[key]))
    play = ["play", "--opponent", "simulated", "--camera", "direct"]
    numbers(play, "--seed", (*BAD_INTS, "-1"))
    out_dirs(play)
    cases.append(([*play, "--engine", "perfect"], "--engine"))
    cases.append(([*play, "--robot-symbol", "Z"], "--robot-symbol"))
    numbers(play, "--time-limit", BAD_POSITIVE)
    cases.append(([*play, "--person", "clever"], "--person"))
    numbers(["demo"], "--seed", BAD_INTS)
    out_dirs(["demo"])
    draw = ["draw", "X"]
    cases.append((["draw", "Y"], "kind"))
    numbers(draw, "--row", (*BAD_INTS, "0", "6"))
    numbers(draw, "--column", (*BAD_INTS, "-3"))
    numbers(draw, "--speed", BAD_POSITIVE)
    numbers(draw, "--size", BAD_POSITIVE)
    numbers(["draw", "lines"], "--spacing", BAD_POSITIVE)
    cases.append((["draw", "X", "--spacing", "40"], "--spacing"))
    out_dirs(draw)
    out_dirs(["tune"])
    stair = ["precision", "staircase", "--count", "1"]
    cases.append((["precision", "staircase", "--axis", "w"], "--axis"))
    cases.append((["precision", "staircase", "--steps", "huge"], "--steps"))
    cases.append((["precision", "staircase", "--tuning", "mine"], "--tuning"))
    numbers(["precision", "staircase"], "--count", (*BAD_INTS, "0", "21"))
    numbers(stair, "--hold", ("abc", "nan", "inf", "0", "-1", "11"))
    out_dirs(stair)
    cases.append((["precision"], "precision"))
    cases.append((["bench", "--only", "nothing-of-that-name"], "--only"))
    out_dirs(["bench", "--only", "ik", "--quick"])
    numbers(["ik", "150", "0", "100"], "--phi", BAD_FINITE)
    cases.append((["ik", "150", "0", "100", "--method", "newton"], "--method"))
    cases.append((["ik", "150", "0", "100", "--elbow", "sideways"], "--elbow"))
    cases.append((["ik", "150", "0", "100", "--elbow", "down"], "--elbow"))
    for i, value in enumerate(BAD_FINITE):
        argv = ["ik", "150", "0", "100"]
        argv[1 + i % 3] = value
        # "-inf" reads as an option to argparse (`ik -- -inf 0 100` is the way): z is then missing, and said so
        cases.append((argv, "z" if value == "-inf" else "xyz"[i % 3] if value == "abc" else "target"))
    numbers(["init"], "--starts", (*BAD_INTS, "0", "-5"))
    numbers(["init"], "--seed", BAD_INTS)
    numbers(["init", "--starts", "1"], "--time-limit", BAD_POSITIVE)
    cases.append((["faults", "--only", "gremlins"], "--only"))
    cases.append((["faults", "--only", ","], "--only"))
    cases.append((["faults", "--phases", "lunch"], "--phases"))
    numbers(["faults", "--phases", "init"], "--seed", BAD_INTS)
    cases.append((["charts", "export", "--format", "gif"], "--format"))
    out_dirs(["charts", "export", "--format", "dot"])
    cases.append((["charts", "explode"], "action"))
    numbers(["params"], "--seed", ("abc",))
    for action in ("run", "check"):
        in_files(["scenario", action], None)
    cases.append((["scenario", "run", str(Path(__file__).parent / "scenarios"), "--trace", p["read_only"]],
                  p["read_only"]))
    one = str(Path(__file__).parent / "scenarios" / "drive_3_leaves_its_switch_when_it_starts_on_it.yaml")
    cases.append((["scenario", "run", one, "--coverage", "--suggest", p["read_only"]], p["read_only"]))
    cases.append((["scenario", "run", one, "--suggest", str(tmp / "suggested")], "--coverage"))
    cases.append((["scenario", "generate", "NoSuchChart"], "NoSuchChart"))
    cases.append((["scenario", "mutate", "NoSuchChart", str(Path(__file__).parent / "scenarios")], "NoSuchChart"))
    out_dirs(["scenario", "generate", "DriveInit3"])
    cases.append((["scenario", "generate", "DriveInit3", "--strategy", "random"], "--strategy"))
    in_files(["scenario", "mutate", "DriveInit3"], None)
    numbers(["gui"], "--port", ("abc", "1.5", "-1", "70000"))
    numbers(["gui"], "--speed", ("abc", "nan", "inf", "0", "11"))
    numbers(["gui"], "--seed", ("abc", "-1"))
    in_files(["gui"], "--scenarios", ("missing", "garbage"))
    in_files(["gui"], "--trace", ("folder", "file_as_folder", "read_only"))
    in_files(["gui"], "--camera", ("missing", "folder", "garbage"))
    out_dirs(["gui", "--game"], "--out")
    cases.append((["debug", "--start", "1,2"], "--start"))
    cases.append((["debug", "--start", "a,b,c"], "--start"))
    numbers(["debug"], "--settle", ("abc", "nan", "-1", "inf"))
    numbers(["debug"], "--max-run", BAD_POSITIVE)
    in_files(["debug"], "--commands", ("missing", "folder"))
    serve = ["camera", "serve", "--duration", "0"]
    cases.append(([*serve, "--link", f"{p['read_only']}/cam"], p["read_only"]))
    cases.append(([*serve, "--link", f"{p['file_as_folder']}/cam"], p["file_as_folder"]))
    cases.append(([*serve, "--board", "XYZ"], "--board"))
    numbers(serve, "--rate", BAD_POSITIVE)
    numbers(serve, "--duration", ("abc", "nan", "-1"))
    numbers(serve, "--fault-every", ("abc", "1.5", "", "-1"))
    cases.append((["lab", "list", "--bogus"], "--bogus"))
    cases.append((["lab", "start", "no_such_exercise", str(tmp / "lab-new")], "no_such_exercise"))
    cases.append((["lab", "start", "drive_init3", p["folder"]], p["folder"]))
    in_files(["lab", "check"], None, ("missing", "folder", "garbage"))
    grade = ["lab", "grade", p["folder"], "--exercise", "algorithm_activator"]
    cases.append((["lab", "grade", p["folder"], "--exercise", "no_such_exercise", "--out", str(tmp / "g")],
                  "no_such_exercise"))
    cases.append((["lab", "grade", p["missing"], "--exercise", "algorithm_activator", "--out", str(tmp / "g")],
                  p["missing"]))
    out_dirs(grade)
    numbers([*grade, "--out", str(tmp / "g")], "--workers", (*BAD_INTS, "0", "-1"))
    numbers([*grade, "--out", str(tmp / "g")], "--timeout", BAD_POSITIVE)
    numbers([*grade, "--out", str(tmp / "g")], "--memory", (*BAD_INTS, "0"))
    cases.append((["--chart", "DriveInit3", "draw", "X"], "--chart"))
    cases.append((["--chart", f"DriveInit3={p['garbage']}:A", "draw", "X"], p["garbage"]))
    cases.append((["--chart", f"Nothing={p['missing']}:A", "draw", "X"], "Nothing"))
    cases.append((["--chart", f"Safety={p['missing']}:A", "demo"], "Safety"))
    for command in (play, ["demo"], ["draw", "X"], ["init", "--starts", "1"], ["debug"], ["gui"]):
        cases.append(([*command, "--arm", "bogus"], "--arm"))
        cases.append(([*command, "--arm", "serial:"], "--arm"))
        cases.append(([*command, "--arm", f"serial:{p['missing']}"], p["missing"]))
        cases.append(([*command, "--arm", f"serial:{p['folder']}"], p["folder"]))
    cases.append((["init", "--starts", "3", "--arm", f"serial:{p['missing']}"], "--starts"))
    cases.append((["debug", "--settle", "1", "--arm", f"serial:{p['missing']}"], "--settle"))
    arm = ["arm", "serve", "--duration", "0"]
    cases.append(([*arm, "--link", f"{p['file_as_folder']}/arm"], p["file_as_folder"]))
    numbers(arm, "--duration", ("abc", "nan", "-1"))
    read = ["camera", "read", "--give-up", "0.2", "--timeout", "0.5"]
    for key in ("missing", "folder", "garbage"):
        cases.append(([*read, "--port", p[key]], p[key]))
    numbers(["camera", "read", "--port", p["missing"]], "--count", ("abc", "1.5", "", "0"))
    numbers(["camera", "read", "--port", p["missing"]], "--timeout", BAD_POSITIVE)
    numbers(["camera", "read", "--port", p["missing"]], "--give-up", ("abc", "nan", "-1"))
    numbers(["camera", "read", "--port", p["missing"]], "--baud", ("abc", "1.5", ""))
    in_files(["vision", "detect"], None)
    image = str(tmp / "board.png")
    cases.append((["vision", "render", image], "ok"))  # made here, used below: not a bad case (see the test)
    cases.append((["vision", "detect", image, "--robot-marks", "1,2,nope"], "--robot-marks"))
    cases.append((["vision", "detect", image, "--overlay", f"{p['read_only']}/o.png"], p["read_only"]))
    cases.append((["vision", "detect", image, "--overlay", f"{p['file_as_folder']}/o.png"], p["file_as_folder"]))
    out_dirs(["vision", "render"], None)
    cases.append((["vision", "render", str(tmp / "x.png"), "--board", "not a board"], "--board"))
    numbers(["vision", "render", str(tmp / "x.png")], "--dim", ("abc", "nan", "0", "2"))
    numbers(["vision", "bench"], "--photos", (*BAD_INTS, "0", "-2"))
    cases.append((["ai", "move", "--board", "XXXXX", "--symbol", "X"], "--board"))
    cases.append((["ai", "move", "--board", "." * 25, "--symbol", "Q"], "--symbol"))
    cases.append((["ai", "move", "--board", "." * 25, "--engine", "nope"], "--engine"))
    kin_ws = ["kinematics", "workspace"]
    for option in ("--L2", "--L3", "--q2-max-deg", "--q3-max-deg", "--cell-m"):
        numbers(kin_ws, option, ("abc", "nan", "inf", "1e9"))
    numbers(kin_ws, "--cells", ("abc", "0", "99"))
    cases.append(([*kin_ws, "--tool", "brush"], "--tool"))
    out_dirs([*kin_ws, "--png"], None)
    cases.append(([*kin_ws, "--png", "/"], "--png"))
    cases.append(([*kin_ws, "--png", "picture.jpg"], "--png"))
    cases.append((["kinematics", "dh", "--q-deg", "0", "0", "0", "nan"], "--q-deg"))
    kin_race = ["kinematics", "race", "--target", "0.07", "0.3"]
    cases.append((["kinematics", "race", "--target", "abc", "0.3"], "--target"))
    cases.append((["kinematics", "race", "--target", "nan", "0.3"], "--target"))
    numbers(kin_race, "--max-iterations", ("abc", "0", "1e9"))
    numbers(kin_race, "--phi-deg", ("nan", "1e9"))
    kin_traj = ["kinematics", "trajectory"]
    numbers(kin_traj, "--speed", ("abc", "nan", "0", "1e9"))
    numbers(kin_traj, "--hold", ("abc", "nan", "-1"))
    cases.append(([*kin_traj, "--from", "abc", "0.2"], "--from"))
    cases.append(([*kin_traj, "--to", "nan", "0.2"], "--to"))
    cases.append(([*kin_traj, "--methods", "cubic,spline"], "--methods"))
    cases.append(([*kin_traj, "--png", "picture.jpg"], "--png"))
    kin_forces = ["kinematics", "forces"]
    cases.append(([*kin_forces, "--at", "abc", "0.2"], "--at"))
    cases.append(([*kin_forces, "--at", "9", "9"], "--at"))
    numbers(kin_forces, "--speed", ("abc", "nan", "0"))
    cases.append(([*kin_forces, "--png", "/"], "--png"))
    cases.append((["no-such-command"], "no-such-command"))
    return cases


@pytest.fixture(scope="module")
def sweep(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("sweep")
    cases = _cases(tmp)
    done = subprocess.run([sys.executable, str(DRIVER)], input=json.dumps([argv for argv, _ in cases]),
                          capture_output=True, text=True, timeout=3600, cwd=tmp,
                          env={**os.environ, "TTT_SM_TRACEBACK": ""})
    assert done.returncode == 0, done.stderr[-3000:]
    results = json.loads(done.stdout)
    return list(zip(cases, results, strict=True))


def _problem(argv: list[str], names: str, result: dict[str, object]) -> str | None:
    out, err = str(result["out"]), str(result["err"])
    shown = f"ttt-sm {' '.join(argv)}: status {result['status']}\n{err[-1500:]}"
    if result["timed_out"]:
        return f"not refused before running (killed after the time limit): {shown}"
    if "Traceback" in out + err:
        return f"a traceback: {shown}"
    if "internal error" in err:
        return f"a bug reported as one: {shown}"
    if result["status"] == 0:
        return f"status 0 for a bad argument: {shown}"
    lines = [line for line in err.splitlines() if line.strip()]
    errors = [line for line in lines if "error" in line]
    if len(errors) != 1 or not lines or errors[0] != lines[-1]:
        return f"not one error line at the end: {shown}"
    if names not in errors[0]:
        return f"the error line does not name {names!r}: {shown}"
    return None


@pytest.mark.soak  # some 600 command lines, 50 s; tests/test_cli_fuzz.py fuzzes single arguments in the default run
def test_every_subcommand_refuses_bad_arguments_in_one_line_without_a_traceback(sweep):
    problems = []
    commands = set()
    for (argv, names), result in sweep:
        if names == "ok":
            assert result["status"] == 0, result["err"]
            continue
        commands.add(" ".join(a for a in argv[:2] if not a.startswith("-") and "/" not in a))
        problem = _problem(argv, names, result)
        if problem:
            problems.append(problem)
    assert not problems, f"{len(problems)} of {len(sweep)} command lines:\n\n" + "\n\n".join(problems)


def _subcommand_paths() -> set[tuple[str, ...]]:
    import argparse

    from ttt_sm.cli import build_parser

    paths: set[tuple[str, ...]] = set()

    def walk(parser: argparse.ArgumentParser, prefix: tuple[str, ...]) -> None:
        subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
        if not subs:
            paths.add(prefix)
        for action in subs:
            for name, sp in action.choices.items():
                walk(sp, (*prefix, name))

    walk(build_parser(), ())
    return paths


def test_the_sweep_covers_every_subcommand(tmp_path):
    swept = set()
    for argv, _ in _cases(tmp_path):
        words = argv[2:] if argv[0] == "--params" else argv
        swept.update(tuple(words[:n]) for n in (1, 2))
    missing = {" ".join(path) for path in _subcommand_paths() if path not in swept}
    assert not missing, f"subcommands the sweep does not run: {sorted(missing)}"
