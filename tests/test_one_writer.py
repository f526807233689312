"""One run, one record: a second ``ttt-sm`` on a record another one writes now is refused in one line.

Two ``ttt-sm gui`` from one checkout both wrote ``out/gui/trace.jsonl``, and
their lines interleaved into invalid JSON.  Every record is now locked by the
process writing it (:class:`ttt_sm.files.LineSink`, ``flock``); a second
writer is refused before it builds anything, and the first one's record
stays whole.  Two real processes in each test: a process writing the record,
and the real ``ttt-sm`` command that must be refused; the reproduced case,
two ``ttt-sm gui``, under ``soak`` (two cockpits' start).
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from gui_process import child_env, running_gui
from ttt_sm.runtime.recordfile import read_lines

#: A process that writes a record and holds it until its standard input closes.
_HOLDER = """
import sys
from ttt_sm.runtime.recordfile import RecordFile
with RecordFile(sys.argv[1]) as record:
    record.add({"event": "head"})
    print("writing", flush=True)
    sys.stdin.read()
"""


@pytest.mark.parametrize("argv, record", [
    (["gui", "--port", "0", "--trace", "{dir}/trace.jsonl"], "trace.jsonl"),
    (["play", "--out", "{dir}"], "game.jsonl"),
    pytest.param(["debug", "--trace", "{dir}/trace.jsonl", "--commands", "/dev/null"], "trace.jsonl",
                 marks=pytest.mark.soak),
    pytest.param(["demo", "--out", "{dir}"], "demo.jsonl", marks=pytest.mark.soak),
    pytest.param(["scenario", "run", str(Path(__file__).resolve().parent / "scenarios"), "--out",
                  "{dir}/report.jsonl"], "report.jsonl", marks=pytest.mark.soak),
])
def test_a_record_being_written_refuses_a_second_writer_in_one_line(tmp_path: Path, argv: list[str],
                                                                   record: str) -> None:
    path = tmp_path / record
    holder = subprocess.Popen([sys.executable, "-c", _HOLDER, str(path)], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout is not None and holder.stdout.readline() == "writing\n"
        second = subprocess.run([sys.executable, "-m", "ttt_sm.cli", *(a.format(dir=tmp_path) for a in argv)],
                                capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL)
        lines = second.stderr.strip().splitlines()
        assert second.returncode == 2 and len(lines) == 1, second.stderr
        assert lines[0].startswith(f"ttt-sm {argv[0]}: error: ") and lines[0].endswith(
            f"{path} is being written by another ttt-sm process now: give this run another file (or folder),"
            " or stop the other one first"), lines
    finally:
        holder.communicate("", timeout=60)
    assert read_lines(path) == [{"event": "head"}, {"event": "finished"}]  # untouched by the second


@pytest.mark.soak
def test_a_second_gui_on_the_same_trace_is_refused_in_one_line(tmp_path: Path) -> None:
    trace = tmp_path / "out" / "gui" / "trace.jsonl"
    with running_gui("--speed", "max", "--trace", str(trace)) as first:  # the address: robot built, trace open
        assert first.proc.poll() is None and trace.is_file(), "the first cockpit did not start"
        second = subprocess.run([sys.executable, "-m", "ttt_sm.cli", "gui", "--port", "0", "--trace", str(trace)],
                                capture_output=True, text=True, timeout=120, env=child_env())
        assert second.returncode == 2, second.stderr
        assert second.stderr.splitlines() == [
            f"ttt-sm gui: error: --trace {trace} is being written by another ttt-sm process now: give this run"
            " another file (or folder), or stop the other one first"], second.stderr
        assert second.stdout == ""
        status, err = first.stop()
    assert status == 0, err[-2000:]
    lines = read_lines(trace)  # every line parses: nobody else wrote into it
    assert lines[0]["event"] == "trace" and lines[-1]["event"] == "interrupted"
    assert sum(1 for e in lines if e.get("event") == "trace") == 1
