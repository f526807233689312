"""Every record written as it happens survives a signal: traces, scenario reports, the bench's results.

Each command runs in a subprocess and gets SIGINT or SIGTERM (chosen at
random) after a random number of its record's lines and a random delay; then
every line of every record must parse, the first be the record's head, the
last say how the run ended (``finished``: the run ended before the signal;
``interrupted`` with that signal; never nothing), the exit status and the
last line on standard error agree with it, and a ``--json`` document on
standard output is still one valid JSON document that says whether it is
complete (docs/reliability.md, "Records that survive").  ``ttt-sm play``'s
game record has its own test (tests/app/test_game_records.py).

One seed each in the default run; twelve under ``make soak``.
"""

from __future__ import annotations

import json
import random
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

from ttt_sm import cli
from ttt_sm.cli import commands
from ttt_sm.cli.common import Interrupted
from ttt_sm.runtime.listeners import Trace
from ttt_sm.runtime.recordfile import ENDINGS, RecordFile, read_lines

TTT = Path(sys.executable).with_name("ttt-sm")
SCENARIOS = Path(__file__).resolve().parent / "scenarios"
pytestmark = pytest.mark.skipif(not TTT.exists(), reason="the ttt-sm console script is not installed beside python")


def _lines(path: Path) -> int:
    try:
        with path.open("rb") as f:
            return sum(1 for _ in f)
    except FileNotFoundError:
        return 0


def signal_of(seed: int) -> signal.Signals:
    """SIGINT for odd seeds, SIGTERM for even ones: each test sees both."""
    return signal.SIGINT if seed % 2 else signal.SIGTERM


def interrupt(cmd: list[str], record: Path, cwd: Path, rng: random.Random, after_lines: int,
              max_delay_s: float = 0.5, sig: signal.Signals = signal.SIGINT) -> tuple[signal.Signals, int, str, str]:
    """Run ``ttt-sm CMD``, signal it with ``sig`` once ``record`` has ``after_lines`` lines (and a random
    delay); the signal, the exit status, standard output and standard error."""
    proc = subprocess.Popen([str(TTT), *cmd], stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, cwd=cwd)
    give_up = time.monotonic() + 300
    try:
        while proc.poll() is None and time.monotonic() < give_up and _lines(record) < after_lines:
            time.sleep(0.01)
        time.sleep(rng.uniform(0.0, max_delay_s))
        if proc.poll() is None:
            proc.send_signal(sig)
        out, err = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    return sig, proc.returncode, out, err


def check_record(path: Path, head: str | None, sig: signal.Signals) -> dict[str, Any]:
    """Every line parses, the first is ``head``'s (None: a transition or the ending), the last an ending
    (this signal's if interrupted)."""
    lines = read_lines(path)  # raises, naming the line, if one does not parse
    assert lines and lines[0].get("event", "transition") in ((head,) if head else ("transition", *ENDINGS)), \
        (path, lines[:1])
    last = lines[-1]
    assert last.get("event") in ENDINGS, f"{path}: its last line says nothing of how the run ended: {last}"
    if last["event"] == "interrupted":
        assert last["signal"] == sig.name, last
    else:
        assert last["event"] == "finished", last  # nothing here fails on its own
    assert sum(1 for e in lines if e.get("event") in ENDINGS) == 1, "one ending, at the end"
    return last


def check_exit(status: int, err: str, ended: str, sig: signal.Signals, finished_status: tuple[int, ...] = (0,)) -> None:
    assert "Traceback" not in err, err[-2000:]
    if ended == "finished":  # the run ended before the signal (or the signal came as the process exited: -sig)
        assert status in (*finished_status, -sig), (status, err[-500:])
    else:
        assert status == 128 + sig, (status, err[-500:])
        assert "interrupted" in err.strip().splitlines()[-1], err[-500:]


SOAK = [pytest.param(seed, marks=pytest.mark.soak) for seed in (2, 3, *range(10, 20))]


@pytest.mark.parametrize("seed", [1, *SOAK])
def test_the_debuggers_trace_file_survives_a_signal(tmp_path: Path, seed: int) -> None:
    rng = random.Random(seed)
    commands = tmp_path / "commands.txt"
    commands.write_text("tick 5\nrun 2\nreplay 100\nrun 3\ntick 200\nrun 20\nrun 20\nquit\n")
    trace = tmp_path / "out" / "trace.jsonl"
    sig, status, out, err = interrupt(["debug", "--seed", str(seed), "--trace", str(trace), "--commands",
                                       str(commands)], trace, tmp_path, rng, rng.randint(1, 15), sig=signal_of(seed))
    last = check_record(trace, "trace", sig)
    lines = read_lines(trace)
    assert lines[0]["seed"] == seed and lines[0]["charts"][:3] == ["DriveInit1", "DriveInit2", "DriveInit3"]
    # Ctrl-C during a `run` pauses it and the script goes on (the debugger's Ctrl-C); between commands it ends
    check_exit(status, err, last["event"], sig)
    if last["event"] == "interrupted":
        assert {"tick", "steps", "t", "transitions", "command"} <= last.keys()
    else:
        assert last["errors"] == 0, out
    transitions = Trace.read_jsonl(trace)  # a trace file reads back as transitions, marks passed over
    assert len(transitions) == sum(1 for e in lines if "event" not in e)
    assert [e["tick"] for e in lines if e.get("event") == "replay"] in ([], [100])


@pytest.mark.parametrize("seed", [1, *SOAK])
def test_the_cockpits_trace_file_is_written_as_it_happens_and_ended_by_the_signal(tmp_path: Path,
                                                                                    seed: int) -> None:
    rng = random.Random(seed)
    trace = tmp_path / "gui" / "trace.jsonl"
    sig, status, out, err = interrupt(["gui", "--port", "0", "--speed", "max", "--seed", str(seed), "--trace",
                                       str(trace)], trace, tmp_path, rng, rng.randint(2, 40), sig=signal_of(seed))
    last = check_record(trace, "trace", sig)
    assert last["event"] == "interrupted"  # the cockpit runs until it is stopped
    assert "Traceback" not in err, err[-2000:]
    # stopped while serving: status 0, "stopped"; before the server started: as any command
    assert status in (0, 128 + sig), (status, err[-500:])
    assert last["transitions"] == sum(1 for e in read_lines(trace) if "event" not in e)


@pytest.mark.parametrize("seed", [1, *SOAK])
def test_a_scenario_runs_report_and_traces_survive_a_signal_and_json_stays_one_document(tmp_path: Path,
                                                                                      seed: int) -> None:
    rng = random.Random(seed)
    files = [SCENARIOS / name for name in ("drive_1_finds_its_index_on_the_first_turn.yaml",
                                           "drive_1_turns_back_at_a_hard_stop.yaml",
                                           "drive_3_leaves_its_switch_when_it_starts_on_it.yaml")]
    report = tmp_path / "report.jsonl"
    traces = tmp_path / "traces"
    sig, status, out, err = interrupt(["scenario", "run", *map(str, files), "--coverage", "--json", "--out",
                                       str(report), "--trace", str(traces)], report, tmp_path, rng,
                                      rng.randint(1, 3), max_delay_s=3.0, sig=signal_of(seed))
    last = check_record(report, "run", sig)
    check_exit(status, err, last["event"], sig)
    results = [e for e in read_lines(report) if e.get("event") == "scenario"]
    assert all(r["passed"] for r in results)
    for path in traces.glob("*.jsonl"):  # every scenario begun has its trace, ended
        assert check_record(path, None, sig)["scenario"] in [r["name"] for r in results] + [last.get("scenario")]
    assert len(list(traces.glob("*.jsonl"))) in (len(results), len(results) + 1)
    document = json.loads(out)  # one document, complete or not
    assert [s["name"] for s in document["scenarios"]] == [r["name"] for r in results]
    if last["event"] == "finished":
        assert document["complete"] is True and "coverage" in document
    else:
        assert document["complete"] is False and document["ended"]["signal"] == sig.name
        # where it stood: in a scenario, or between two (None: a loaded soak run met one there), or before
        # the first began (the command's own ending: nothing done yet)
        assert last.get("scenarios_done", 0) == len(results), last
        assert "scenario" in last or not results, last


@pytest.mark.parametrize("seed", [1, *SOAK])
def test_the_benchs_results_are_written_section_by_section_and_survive_a_signal(tmp_path: Path, seed: int) -> None:
    rng = random.Random(seed)
    out_dir = tmp_path / "bench"
    record = out_dir / "bench.jsonl"
    sig, status, out, err = interrupt(["bench", "--quick", "--only", "ik,loop,pacing,charts", "--json", "--out",
                                       str(out_dir)], record, tmp_path, rng, rng.randint(1, 4), max_delay_s=2.0,
                                      sig=signal_of(seed))
    last = check_record(record, "bench", sig)
    check_exit(status, err, last["event"], sig)
    sections = [e["section"] for e in read_lines(record) if e.get("event") == "section"]
    assert sections == ["ik", "loop", "pacing", "charts"][:len(sections)]
    document = json.loads(out)
    assert document["complete"] is (last["event"] == "finished")
    if last["event"] == "interrupted":
        assert document["ended"]["sections_done"] == sections == last["sections_done"]
        assert last["section"] in ("ik", "loop", "pacing", "charts", None)


@pytest.mark.parametrize("seed", [1, *SOAK])
def test_the_demos_record_survives_a_signal_with_the_board_as_it_was(tmp_path: Path, seed: int) -> None:
    rng = random.Random(seed)
    out = tmp_path / "demo"
    record = out / "demo.jsonl"
    sig, status, _, err = interrupt(["demo", "--seed", str(seed), "--out", str(out)], record, tmp_path, rng,
                                    rng.randint(2, 60), max_delay_s=2.0, sig=signal_of(seed))
    last = check_record(record, "demo", sig)
    check_exit(status, err, last["event"], sig)
    lines = read_lines(record)
    steps = [e["event"] for e in lines if e.get("event") not in (None, "demo", *ENDINGS)]
    assert steps == ["initialised", "drawn", "drawn", "drawn", "board_saved", "erased"][:len(steps)]
    if last["event"] == "interrupted":  # where it stood, and the board of that moment
        assert {"t", "tick", "control"} <= last.keys()
        assert Path(last["pictures"]["board"]).is_file()
    else:
        assert last["erased"] is True and (out / "board_erased.png").is_file()


def test_a_record_file_flushes_every_line_and_ends_once(tmp_path: Path) -> None:
    path = tmp_path / "deep" / "r.jsonl"
    with RecordFile(path) as record:
        record.add({"event": "head", "x": float("nan")})  # strict JSON: NaN is null
        assert path.read_text() == '{"event": "head", "x": null}\n'  # on disk before the next line
    assert read_lines(path)[-1] == {"event": "finished"}
    with pytest.raises(KeyboardInterrupt), RecordFile(path) as record:
        record.add({"event": "head"})
        raise KeyboardInterrupt
    assert read_lines(path)[-1] == {"event": "interrupted", "signal": "SIGINT"}
    with pytest.raises(ZeroDivisionError), RecordFile(path) as record:
        record.end("error", message="first")
        raise ZeroDivisionError("later")
    assert read_lines(path) == [{"event": "error", "message": "first"}]
    path.write_text('{"event": "head"}\n{"event": "fini')
    with pytest.raises(ValueError, match=r"r.jsonl:2: not a JSON line"):
        read_lines(path)


def test_unwritable_record_paths_are_refused_before_the_run(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("")
    for cmd in (["debug", "--trace", str(blocker / "t.jsonl"), "--commands", "/dev/null"],
                ["scenario", "run", str(SCENARIOS / "drive_1_finds_its_index_on_the_first_turn.yaml"), "--out",
                 str(blocker / "r.jsonl")],
                ["scenario", "run", str(SCENARIOS / "drive_1_finds_its_index_on_the_first_turn.yaml"), "--trace",
                 str(blocker / "d")],
                ["bench", "--only", "charts", "--out", str(blocker / "b")],
                ["debug", "--trace", str(tmp_path), "--commands", "/dev/null"]):
        proc = subprocess.run([str(TTT), *cmd], capture_output=True, text=True, timeout=120, cwd=tmp_path)
        assert proc.returncode == 2, (cmd, proc.stderr)
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and "error" in lines[0] and ("--trace" in lines[0] or "--out" in lines[0]), lines


def _import_broken_by(signal_name: str) -> None:
    """What CPython raises when a signal lands while a C extension initialises: the import fails,
    the interruption only its context (seen once: SIGINT during matplotlib's first import)."""
    interrupt = KeyboardInterrupt() if signal_name == "SIGINT" else Interrupted(signal_name)
    try:
        raise interrupt
    except KeyboardInterrupt:
        raise ImportError("initialization failed")  # noqa: B904  (as CPython leaves it: the context only)


@pytest.mark.parametrize("signal_name", ["SIGINT", "SIGTERM"])
def test_a_signal_inside_an_import_ends_the_record_and_the_command_as_interrupted(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], signal_name: str) -> None:
    path = tmp_path / "r.jsonl"
    with pytest.raises(ImportError), RecordFile(path) as record:
        record.add({"event": "head"})
        _import_broken_by(signal_name)
    assert read_lines(path)[-1] == {"event": "interrupted", "signal": signal_name}

    def broken(args: Any) -> int:
        _import_broken_by(signal_name)
        return 0

    monkeypatch.setattr(commands, "cmd_params", broken)
    status = cli.main(["params"])
    err = capsys.readouterr().err
    assert status == 128 + (signal.SIGINT if signal_name == "SIGINT" else signal.SIGTERM)
    assert err.strip() == "ttt-sm params: interrupted" + ("" if signal_name == "SIGINT" else f" ({signal_name})")
