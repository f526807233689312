"""The debugger's command line under fuzz: any line gets a result or one ``error:`` line from the
debugger's own errors, never an internal exception, and no command runs past its bound."""

from __future__ import annotations

import cmd
import contextlib
import io
import tempfile
from pathlib import Path

from hypothesis import strategies as st

from fuzzing import fuzz
from ttt_sm.debug import Debugger
from ttt_sm.debug.shell import USER_ERRORS, DebugShell
from ttt_sm.params import load_params

#: Every command runs at most this long: a fuzz case stays quick, and the bound itself is fuzzed.
MAX_RUN_S = 0.02
_OUT = Path(tempfile.mkdtemp(prefix="ttt-sm-shell-fuzz-"))
_shell: DebugShell | None = None


def shell() -> DebugShell:
    """One session for all cases (state piles up, as in a long session); output to a string."""
    global _shell
    if _shell is None:
        _shell = DebugShell(Debugger.build(load_params(), seed=0, max_run_s=MAX_RUN_S), stdout=io.StringIO())
        _shell.scripted = True
    return _shell


_NUMBERS = st.one_of(st.sampled_from(["0", "1", "-1", "2", "0.001", "0.015", "1e12", "1e308", "-0", "nan", "inf",
                                      "-inf", "1e-300", "10000000000000000000000", "0x10", "1_000", "٣", "1deg",
                                      "20mm", "5ms", "true", "false", "on", ""]),
                     st.integers(-(10**25), 10**25).map(str), st.floats(allow_nan=True).map(str))
_CHARTS = st.sampled_from(["DriveInit1", "DriveInit2", "Control", "Nope", "", "*"])
_NAMES = st.sampled_from(["stop", "pos_in", "index", "turn_back", "power_on", "finish", "button", "tick", "run",
                          "ini_23", "x", "", "*", "a.b", "pos_Encoder"])
_REFS = st.builds(lambda c, n: f"{c}.{n}", _CHARTS, _NAMES)
_PATHS = st.sampled_from([str(_OUT / "t.jsonl"), str(_OUT / "d.svg"), str(_OUT / "d.png"), str(_OUT / "d.xyz"),
                          str(_OUT / "d"), str(_OUT / "no" / "such" / "dir.svg"), "/dev/null", "/proc/version",
                          str(_OUT), "/proc/nope/x.svg", "'a b'.svg"])
_CONDITIONS = st.lists(st.one_of(_REFS, _NUMBERS, st.sampled_from(["and", "or", "not", "<", ">", "==", "+", "*",
                                                                   "(", ")", "abs(", "t", "q_true[1]", '"x"',
                                                                   "'", "-", "/", "0"])),
                       min_size=1, max_size=8).map(" ".join)
_SOUP = st.lists(st.one_of(_CHARTS, _NAMES, _REFS, _NUMBERS, _PATHS, st.text(max_size=6),
                           st.sampled_from(['"', "'", "\\", "#", "=", "->", ";"])), max_size=5).map(" ".join)


def _line(*parts: st.SearchStrategy[str]) -> st.SearchStrategy[str]:
    return st.tuples(*parts).map(" ".join)


def _words(*words: str) -> st.SearchStrategy[str]:
    return st.sampled_from(words)


LINE = st.one_of(
    _line(_words("run", "next", "step", "tick"), _NUMBERS),
    _line(_words("break"), _words("enter", "exit", "event", "nope"), _REFS),
    _line(_words("break transition"), _CHARTS, st.builds(lambda a, b: f"{a}->{b}", _NAMES, _NAMES)),
    _line(_words("break when"), _CONDITIONS),
    _line(_words("delete", "enable", "disable"), _NUMBERS),
    _line(_words("show"), _words("charts", "data", "signals", "trace", "breakpoints", "inputs", "snapshot", "x"),
          st.one_of(_CHARTS, _NUMBERS)),
    _line(_words("trace", "trace save", "trace save a"), st.one_of(_PATHS, _NUMBERS)),
    _line(_words("diagram"), _CHARTS, st.one_of(_PATHS, st.just(""))),
    _line(_words("set", "force"), _REFS, _NUMBERS),
    _line(_words("release"), st.one_of(_REFS, st.just(""))),
    _line(_words("post"), _CHARTS, _NAMES,
          st.lists(st.one_of(st.builds(lambda k, v: f"{k}={v}", _NAMES, _NUMBERS), _words('"', "'", "a=b c", "=")),
                   max_size=3).map(" ".join)),
    _line(_words("replay", "replay step"), _NUMBERS),
    _line(_words("help"), st.one_of(_NAMES, _words("run", "EOF", "help", ""))),
    _SOUP)
LINES = st.lists(LINE, min_size=1, max_size=3)


def run_lines(lines: list[str]) -> None:
    with contextlib.chdir(_OUT):  # `trace save 12` and `diagram Control` write where the session runs
        run_commands(lines)


#: The furthest simulated time the shared session has reached: `replay` may go back, and forward again
#: as far as this, never further.
_furthest_t = 0.0


def run_commands(lines: list[str]) -> None:
    global _furthest_t
    sh = shell()
    for line in lines:
        t0 = sh.dbg.robot.t
        line = line.split("#", 1)[0].strip()
        if not line or line.split()[0] in ("quit", "exit", "EOF"):
            continue
        try:
            cmd.Cmd.onecmd(sh, line)  # what DebugShell.onecmd runs, without its catch-all
        except USER_ERRORS as exc:
            message = str(exc)
            assert "\n" not in message and 0 < len(message) < 1500, message[:300]
        # no command runs past its bound: `run` and its kin at most MAX_RUN_S on from where they began, a replay
        # no further than where the session has been
        bound = max(t0 + MAX_RUN_S + 2 * sh.dbg.robot.params.control.chart_dt, _furthest_t)
        assert sh.dbg.robot.t <= bound, (line, t0, _furthest_t)
        _furthest_t = max(_furthest_t, sh.dbg.robot.t)


test_any_command_line_gives_a_result_or_one_error_line, \
    test_any_command_line_gives_a_result_or_one_error_line_soak = fuzz(LINES, quick=150, soak=3000)(run_lines)


def test_what_the_fuzzer_found_gets_one_error_line_naming_the_argument(tmp_path):
    out = io.StringIO()
    sh = DebugShell(Debugger.build(load_params(), seed=0, max_run_s=MAX_RUN_S), stdout=out)
    sh.run_script([f"trace save {tmp_path}", "trace save /proc/nope/t.jsonl", "diagram DriveInit1 /proc/nope/d.svg",
                   'post DriveInit1 stop "', "set DriveInit1.pos_in nan", "set DriveInit1.pos_in 1e400"])
    errors = [line for line in out.getvalue().splitlines() if line.startswith("error: ")]
    assert errors == [
        f"error: trace save: cannot write '{tmp_path}': Is a directory",
        "error: trace save: cannot write '/proc/nope/t.jsonl': No such file or directory",
        "error: diagram: cannot write '/proc/nope/d.svg': No such file or directory",
        "error: post: No closing quotation in 'DriveInit1 stop \"'",
        "error: DriveInit1.pos_in (rad): 'nan' is not a finite number",
        "error: DriveInit1.pos_in (rad): '1e400' is not a finite number",
    ]
