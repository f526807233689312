"""Every CLI argument that takes a number or a path, under fuzz: a value the command cannot use is
refused in one line (exit status 2) before any work, never a traceback."""

from __future__ import annotations

import contextlib
import io
import math
import sys
import tempfile

import pytest
from hypothesis import assume
from hypothesis import strategies as st

from fuzzing import fuzz
from ttt_sm.cli import main

_NUMBERS = st.one_of(
    st.sampled_from(["nan", "inf", "-inf", "-1", "0", "1e308", "-1e308", "1e400", "1" + "0" * 30, "-" + "9" * 30,
                     "", "x", "0x10", "1_0", "١", "1e-320", "5", "3", "0.5", "9223372036854775808"]),
    st.integers(-(10**20), 10**20).map(str), st.floats(allow_nan=True).map(repr))


def _number(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def _whole(text: str) -> int | None:
    try:
        return int(text)
    except ValueError:
        return None


def _in(lo: float, hi: float, whole: bool = False):
    def ok(text: str) -> bool:
        v = _whole(text) if whole else _number(text)
        return v is not None and math.isfinite(v) and lo <= v <= hi
    return ok


#: (argv before the value, argv after it, what a usable value is): the commands whose work is long run only
#: with a value the predicate calls unusable, so each case stops at the check; None: a quick command, run
#: with any value (it answers, 0, or refuses, 2).
ARGS = [
    (["draw", "X", "--seed"], [], _in(0, 2**63 - 1, whole=True)),
    (["draw", "X", "--row"], [], _in(1, 5, whole=True)),
    (["draw", "X", "--column"], [], _in(1, 5, whole=True)),
    (["draw", "X", "--speed"], [], _in(1, 100)),
    (["draw", "X", "--size"], [], _in(4, 30)),
    (["init", "--starts"], [], _in(1, 10000, whole=True)),
    (["init", "--seed"], [], _in(0, 2**63 - 1, whole=True)),
    (["demo", "--seed"], [], _in(0, 2**63 - 1, whole=True)),
    (["bench", "--seed"], [], _in(0, 2**63 - 1, whole=True)),
    (["vision", "bench", "--photos"], [], _in(1, 10000, whole=True)),
    (["vision", "bench", "--seed"], [], _in(0, 2**63 - 1, whole=True)),
    (["vision", "render", "/nonexistent-dir/x.png", "--dim"], [], lambda t: False),
    (["debug", "--settle"], ["--commands", "/dev/null"], _in(0, 600)),
    (["debug", "--max-run"], ["--commands", "/dev/null"], lambda t: _in(5e-324, 1.8e308)(t)),
    (["debug", "--seed"], ["--commands", "/dev/null"], _in(0, 2**63 - 1, whole=True)),
    (["camera", "read", "--count"], ["--port", "/proc/nope", "--give-up", "0"], None),
    (["camera", "read", "--timeout"], ["--port", "/proc/nope", "--give-up", "0"], None),
    (["ik"], ["0", "0"], None),
    (["ik", "0", "250", "0", "--phi"], [], None),
]


@contextlib.contextmanager
def _stdin(stream: io.StringIO):
    """Standard input as a pipe that has ended (``debug`` reads commands from it when given no file)."""
    saved = sys.stdin
    sys.stdin = stream
    try:
        yield
    finally:
        sys.stdin = saved


def _run(argv: list[str]) -> tuple[int, str]:
    err, out = io.StringIO(), io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out), _stdin(io.StringIO("")):
        try:
            rc = main(argv)
        except SystemExit as exc:  # argparse refusing a value: usage and one error line
            rc = int(exc.code or 0)
    return rc, err.getvalue()


def one_error_line(err: str) -> None:
    """The error is one line: ``ttt-sm CMD: error: ...`` (argparse puts its usage lines before it)."""
    assert "Traceback" not in err, err[-1500:]
    lines = err.strip().splitlines()
    errors = [line for line in lines if ": error: " in line]
    assert len(errors) == 1 and errors[0] == lines[-1] and errors[0].startswith("ttt-sm"), err[-1500:]
    assert all(line.startswith(("usage: ", " ")) for line in lines[:-1]), err[-1500:]


def refused(case: tuple[int, str]) -> None:
    index, value = case
    before, after, usable = ARGS[index]
    assume(usable is None or not usable(value))
    rc, err = _run([*before, value, *after])
    assert rc == 2 or (usable is None and rc == 0), (before, value, rc, err[-500:])
    if rc == 2:
        one_error_line(err)


test_an_unusable_number_is_refused_in_one_line, test_an_unusable_number_is_refused_in_one_line_soak = fuzz(
    st.tuples(st.integers(0, len(ARGS) - 1), _NUMBERS), quick=200, soak=3000)(refused)

#: Stands for a folder: an empty one the case owns.  A folder is a usable argument to some commands
#: (``scenario check`` reads the scenario files in it), so a shared one such as /tmp would make the case
#: depend on what other programs left there.
_FOLDER = "<an empty folder>"
_PATHS = ["/nonexistent/x", "/dev/null", "/dev/zero", "/proc/nope/x", "/proc/version", _FOLDER, "", " ", "-",
          "relative/missing", "/etc/hostname", "a" * 5000]
#: Folders no command can write, even as root: /proc and /sys refuse new files, /dev/null and /proc/version
#: are files, not folders.
_UNWRITABLE = ["/proc/nope/x", "/dev/null/x", "/proc/version", "/proc/version/x", "/sys/nope/x", "/etc/hostname/x"]
#: (argv before the path, argv after it, whether the command writes there): commands that read a path get
#: any text; those that write get only places they cannot write (a usable one would run the whole command).
PATH_ARGS = [
    (["--params"], ["params"], False),
    (["vision", "detect"], [], False),
    (["scenario", "check"], [], False),
    (["debug", "--max-run", "0.001", "--commands"], [], False),
    (["vision", "render"], [], True),
    (["vision", "detect", "/nonexistent.png", "--overlay"], [], True),
    (["tune", "--out"], [], True),
    (["charts", "export", "--out"], [], True),
    (["draw", "X", "--out"], [], True),
    (["demo", "--out"], [], True),
    (["bench", "--out"], [], True),
]


def path_refused(case: tuple[int, str, int]) -> None:
    index, path, pick = case
    before, after, writes = PATH_ARGS[index]
    if writes:
        path = _UNWRITABLE[pick % len(_UNWRITABLE)]
    # Run in an empty working folder of the case's own, so a relative path names nothing left by others.
    with tempfile.TemporaryDirectory() as folder, contextlib.chdir(folder):
        rc, err = _run([*before, folder if path == _FOLDER else path, *after])
    assert rc in ((2,) if writes else (0, 1, 2)), (before, path, rc, err[-500:])
    if rc == 2:
        one_error_line(err)
    assert "Traceback" not in err, err[-1500:]


test_an_unusable_path_is_refused_in_one_line, test_an_unusable_path_is_refused_in_one_line_soak = fuzz(
    st.tuples(st.integers(0, len(PATH_ARGS) - 1), st.one_of(st.sampled_from(_PATHS), st.text(max_size=20)),
              st.integers(0, 100)), quick=150, soak=2000)(path_refused)


def arm_refused(case: tuple[int, str, bool]) -> None:
    """``--arm`` with anything but ``sim``: a bad value, or a port that does not open or answer, in one line."""
    index, text, as_port = case
    value = f"serial:{text}" if as_port else text
    assume(value != "sim")
    before = [["draw", "X"], ["init", "--starts", "1"], ["demo"], ["debug", "--commands", "/dev/null"]][index]
    rc, err = _run([*before, "--arm", value])
    assert rc == 2, (before, value, rc, err[-500:])
    one_error_line(err)


test_an_unusable_arm_is_refused_in_one_line, test_an_unusable_arm_is_refused_in_one_line_soak = fuzz(
    st.tuples(st.integers(0, 3), st.one_of(st.sampled_from(_PATHS), st.text(max_size=20)), st.booleans()),
    quick=60, soak=600)(arm_refused)


@pytest.mark.parametrize("argv, message", [
    (["draw", "X", "--seed", "-1"], "argument --seed: expected a whole number 0 .. 2**63 - 1, got -1"),
    (["vision", "bench", "--photos", "1", "--seed", "-5"], "argument --seed: expected a whole number 0 .. 2**63 - 1"),
    (["init", "--starts", "76560"], "--starts must lie in 1..10000, got 76560"),
    (["tune", "--out", "/proc/nope/x"], "--out /proc/nope/x: cannot write there (No such file or directory)"),
    (["charts", "export", "--out", "/proc/version"], "--out /proc/version: cannot write there"),
    (["debug", "--max-run", "0.001", "--commands", "/dev/zero"],
     "--commands /dev/zero:1: a line longer than 10000 characters: not a commands file"),
    (["--params", "a\rb", "params"], "'a\\rb': cannot read parameter file"),
    (["--params", "a\x00b", "params"], "'a\\x00b': cannot read parameter file (embedded null byte)"),
    (["scenario", "check", "a\x00b"], "'a\\x00b': cannot read the file: embedded null byte"),
    (["scenario", "check", "a" * 5000], "cannot read the file: File name too long"),
    (["vision", "detect", "a" * 5000], "cannot read the file (File name too long)"),
    (["debug", "--commands", "a\rb"], "--commands: cannot read 'a\\rb': No such file or directory"),
    (["debug", "--commands", "a\x00b"], "--commands: cannot read 'a\\x00b': embedded null byte"),
])
def test_what_the_cli_fuzzer_found_is_one_line_before_any_work(argv, message):
    rc, err = _run(argv)
    assert rc == 2 and message in err, err[-800:]
    one_error_line(err)
