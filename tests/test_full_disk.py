"""Records and pictures on a full disk: whole lines or none, whole pictures or none, one line naming the file.

The disk is real: a tmpfs of a few kB mounted in a mount namespace of the
command's own (``unshare -rm``, :mod:`tools.full_disk`), so the writes fail
with ``ENOSPC`` where a full disk fails them, short writes included.  Where
no mount namespace can be had, the same runs use a file-size limit
(``RLIMIT_FSIZE`` in the child): a write past it fails with ``EFBIG`` after
the same short write, which is the write path a record's writer has to
survive (it cannot show a second file refused for want of space; the tmpfs
does).  Each test names which it used in its failure messages.

The long runs (``play``, ``demo``, ``draw``, ``bench``, ``charts export``, a
scenario run, several sizes each) are the probe ``python -m tools.full_disk``
and its soak test here; docs/reliability.md, "Records on a full disk", has
the numbers.
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from tools.full_disk import WRITERS, Writer, command, full_disk_popen, namespace_works, run_gui, run_writer

from ttt_sm.files import LineSink, RecordBusyError, RecordWriteError, write_atomic
from ttt_sm.runtime.recordfile import RecordFile, read_lines

SRC = Path(__file__).resolve().parents[1] / "src"
HOW = "tmpfs" if namespace_works() else "fsize"

#: Writes lines of growing length into r.jsonl until the disk refuses one, then a picture over an old one,
#: then a new picture; prints what was raised.
_FILL = textwrap.dedent("""
    import json, numpy as np
    from pathlib import Path
    from ttt_sm.files import write_png, RecordWriteError
    from ttt_sm.runtime.recordfile import RecordFile
    old = np.full((40, 40, 3), 200, np.uint8)
    write_png("old.png", old)
    told = {}
    record = RecordFile("r.jsonl")
    try:
        for n in range(100000):
            record.add({"n": n, "pad": "x" * (n % 700)})
    except RecordWriteError as exc:
        told["record"] = [exc.filename, exc.errno, exc.strerror, record.lines]
    noise = np.random.default_rng(1).integers(0, 255, (400, 400, 3), dtype=np.uint8)
    for name in ("old.png", "new.png"):
        try:
            write_png(name, noise)
        except RecordWriteError as exc:
            told[name] = [exc.filename, exc.errno, exc.strerror]
    record.add({"after": "the failure"})  # nothing: the record ended at its failure
    print(json.dumps(told))
""")


def test_a_record_and_pictures_on_a_full_disk_keep_whole_lines_and_whole_pictures(tmp_path: Path) -> None:
    disk, copy = tmp_path / "disk", tmp_path / "copy"
    disk.mkdir()
    (copy / "given").mkdir(parents=True)
    _, env = command(SRC, [])
    proc = full_disk_popen([sys.executable, "-c", _FILL], env, disk, copy, 32, HOW, stdout=subprocess.PIPE,
                           stderr=subprocess.PIPE)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, (HOW, err[-2000:])
    told = json.loads(out)
    where = copy if HOW == "tmpfs" else disk
    filename, code, reason, kept = told["record"]
    assert filename == "r.jsonl" and code in (28, 27) and "no half line" in reason, (HOW, told)
    lines = read_lines(where / "r.jsonl")  # every line parses (raises naming the one that does not)
    body = [line for line in lines if "n" in line]
    assert [line["n"] for line in body] == list(range(len(body))) and len(body) > 10, HOW
    assert kept == len(body) + (lines[-1].get("event") == "error")
    if lines[-1].get("event") == "error":  # the ending fitted in the space the cut freed
        assert "could not be written on" in lines[-1]["message"]
    assert not any("after" in line for line in lines)
    # the old picture is there whole, the new one not at all; no temporary left
    import cv2
    assert told["old.png"][0] == "old.png" and told["new.png"][0] == "new.png", told
    old = cv2.imread(str(where / "old.png"))
    assert old is not None and old.shape == (40, 40, 3) and (old == 200).all()
    assert not (where / "new.png").exists()
    assert [p.name for p in where.iterdir() if p.name.endswith(".tmp")] == []


def test_a_line_sink_appends_after_its_last_whole_line_and_refuses_a_second_writer(tmp_path: Path) -> None:
    path = tmp_path / "r.jsonl"
    path.write_bytes(b'{"a": 1}\n{"b": 2}\n{"c": ')  # a line cut short by a kill
    sink = LineSink(path, append=True)
    with pytest.raises(RecordBusyError, match=r"r\.jsonl is being written by another ttt-sm process now"):
        LineSink(path)  # another open file: refused as another process would be, the file untouched
    with pytest.raises(RecordBusyError):
        RecordFile(path)
    assert path.read_bytes().endswith(b'{"b": 2}\n')
    sink.write('{"d": 4}\n')
    with pytest.raises(ValueError, match="whole line"):
        sink.write('{"e": 5}')
    sink.close()
    assert [json.loads(x) for x in path.read_text().splitlines()] == [{"a": 1}, {"b": 2}, {"d": 4}]
    LineSink(path).close()  # closed: free for the next writer, which starts it anew
    assert path.read_bytes() == b""


def test_a_picture_that_cannot_be_renamed_into_place_is_not_left_half(tmp_path: Path) -> None:
    (tmp_path / "dir.png").mkdir()  # a folder where the picture belongs: the rename fails
    with pytest.raises(RecordWriteError) as caught:
        write_atomic(tmp_path / "dir.png", b"\x89PNG")
    assert caught.value.filename == str(tmp_path / "dir.png")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dir.png"]


def _writer(name: str) -> Writer:
    return next(w for w in WRITERS if w.name == name)


def test_the_debuggers_trace_and_trace_save_on_a_full_disk(tmp_path: Path) -> None:
    """The trace fills the disk: the session goes on (told once), ``trace save`` is an error line, and the run
    ends with one line naming the trace file and what to do, status 2."""
    writer = Writer("debug", ["debug", "--trace", "trace.jsonl", "--commands", "commands.txt"], (4,), 120,
                    "tick 5\nrun 8\ntrace save saved.jsonl\nquit\n")
    outcome = run_writer(SRC, writer, 4, HOW, tmp_path)
    assert outcome.half_lines == 0 and outcome.records >= 1, (HOW, outcome)
    assert outcome.status == 2 and not outcome.traceback, (HOW, outcome)
    assert outcome.last_line.startswith("ttt-sm debug: error: trace.jsonl: "), (HOW, outcome.last_line)
    assert outcome.last_line.endswith(("free some space or choose another path", "raise the limit or write less"))
    assert outcome.names_the_file and outcome.problems == [], outcome


@pytest.mark.soak  # 20-35 s: the cockpit's start, the disk filling at full speed, a page, its stop
@pytest.mark.skipif(HOW != "tmpfs", reason="the cockpit's other files need a disk that is full, not a size limit")
def test_the_cockpit_survives_a_full_disk_under_gui_trace(tmp_path: Path) -> None:
    """``gui --trace`` on a 24 kB disk: the trace stops with whole lines, the page is told, the ink picture is
    served, SIGTERM ends it with one line naming the trace (no "Application shutdown failed")."""
    outcome = run_gui(SRC, 24, HOW, tmp_path)
    assert outcome.problems == [], outcome
    assert outcome.half_lines == 0 and outcome.records == 1 and outcome.lines > 3, outcome
    assert outcome.status == 2 and not outcome.traceback, outcome
    assert outcome.last_line.startswith("ttt-sm gui: error: trace.jsonl: No space left on device"), outcome


@pytest.mark.soak
@pytest.mark.parametrize("writer", [w.name for w in WRITERS])
def test_every_writer_on_a_full_disk(tmp_path: Path, writer: str) -> None:
    """Each size fills the disk at another point of the run: never a half line, an empty picture or a left
    temporary; the run ends with one line naming the file (or finishes, if it all fitted)."""
    w = _writer(writer)
    for size in w.sizes_kb:
        work = tmp_path / str(size)
        work.mkdir()
        outcome = run_writer(SRC, w, size, HOW, work)
        assert outcome.problems == [] and not outcome.traceback, outcome
        # an error names the file: the command's last line (status 2), or the debugger's error line for a
        # `trace save` the disk refused while its trace fitted (status 1: a scripted session with errors)
        assert outcome.status == 0 or (outcome.status in (1, 2) and outcome.names_the_file), outcome
