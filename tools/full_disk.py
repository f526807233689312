"""Every writer of ``ttt-sm`` on a full disk: ``python -m tools.full_disk [--src DIR] [--only NAMES]``.

Each command that writes a record (JSON Lines) or a picture runs in a
folder on a real file system that is nearly full: a tmpfs of a few kB,
mounted in a mount namespace of the command's own (``unshare -rm``: no root
needed where unprivileged user namespaces are allowed).  The run is given
several sizes, so the disk fills at different points of it (the record's
head, the middle, a picture, the last line).  Then every file left is read
back: a *half line* is a line of a ``.jsonl`` that is not JSON, an *empty
picture* a ``.png`` that is empty or does not decode, a *left temporary* a
``.*.tmp`` left beside them; the command's last line on standard error must
name the file the disk refused and say what to do, and nothing may print a
traceback.

Where a mount namespace cannot be had, the same runs are made under a
file-size limit (``RLIMIT_FSIZE``, set in the child): a write past the limit
fails with ``EFBIG`` exactly where the disk would have failed it with
``ENOSPC`` (the same short write, then an error), which is what a record's
writer has to survive.  What it does not show is a second file refused for
want of space: the tmpfs does.

``--src``: the source tree to run (default: this checkout's ``src``), so
the same probe measures a tree before a fix.  Prints one JSON document: per
writer and size, the exit status, the files, the half lines, the empty
pictures, the left temporaries and the last line on standard error; and the
totals (docs/reliability.md, "Records on a full disk").
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import urllib.request
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = [str(ROOT / "tests" / "scenarios" / name) for name in (
    "drive_1_finds_its_index_on_the_first_turn.yaml", "drive_1_turns_back_at_a_hard_stop.yaml",
    "drive_3_leaves_its_switch_when_it_starts_on_it.yaml")]
DEBUG_COMMANDS = "tick 5\nrun 20\ntrace save saved.jsonl\nrun 20\nrun 20\ntrace save saved.jsonl\nquit\n"


@dataclass
class Writer:
    """A command that writes, the sizes of disk it is given (kB), and the seconds it may take."""

    name: str
    argv: list[str]
    sizes_kb: tuple[int, ...]
    timeout_s: float = 300.0
    commands: str = DEBUG_COMMANDS  # the debugger's commands.txt


WRITERS = (
    Writer("debug --trace, trace save", ["debug", "--trace", "trace.jsonl", "--commands", "commands.txt"],
           (8, 20, 40, 60)),
    Writer("scenario run --out --trace", ["scenario", "run", *SCENARIOS, "--out", "report.jsonl", "--trace",
                                          "traces"], (8, 12, 16, 20)),
    Writer("demo --out", ["demo", "--out", "demo"], (32, 120, 200)),
    Writer("play --out", ["play", "--out", "play"], (32, 140, 250)),
    Writer("draw --out", ["draw", "X", "--out", "draw"], (16, 80, 140)),
    Writer("bench --out", ["bench", "--quick", "--only", "ik,charts", "--out", "bench"], (8,)),
    Writer("charts export --out", ["charts", "export", "--out", "charts"], (24, 120)),
)


@dataclass
class Outcome:
    """What one run left: its status, the files and what is wrong with them."""

    writer: str
    size_kb: int
    how: str
    status: int | None
    records: int = 0
    lines: int = 0
    half_lines: int = 0
    pictures: int = 0
    empty_pictures: int = 0
    left_temporaries: int = 0
    last_line: str = ""
    traceback: bool = False
    names_the_file: bool = False
    problems: list[str] = field(default_factory=list)


def namespace_works() -> bool:
    """Whether ``unshare -rm`` can mount a tmpfs here."""
    if shutil.which("unshare") is None:
        return False
    with tempfile.TemporaryDirectory() as d:
        proc = subprocess.run(["unshare", "-rm", "sh", "-c", 'mount -t tmpfs -o size=8k tmpfs "$0"', d],
                              capture_output=True, timeout=30)
        return proc.returncode == 0


def command(src: Path, argv: Sequence[str]) -> tuple[list[str], dict[str, str]]:
    env = {**os.environ, "PYTHONPATH": f"{src}{os.pathsep}{ROOT}", "PYTHONUNBUFFERED": "1"}
    env.pop("TTT_SM_TRACEBACK", None)
    return [sys.executable, "-m", "ttt_sm.cli", *argv], env


def full_disk_popen(argv: list[str], env: dict[str, str], disk: Path, copy: Path, size_kb: int, how: str,
                    **kw: Any) -> subprocess.Popen[str]:
    """Start ``argv`` in ``disk``, a file system of ``size_kb`` kB (``how``: "tmpfs" or "fsize"); when it
    exits, what it wrote is copied to ``copy`` (the tmpfs goes with its namespace)."""
    if how == "tmpfs":
        script = ('D="$1"; C="$2"; shift 2; mount -t tmpfs -o size="$SIZE"k tmpfs "$D" || exit 97; '
                  'cp -a "$C/given/." "$D/" 2>/dev/null; cd "$D"; "$@" & pid=$!; '
                  "trap 'kill -TERM $pid' TERM; wait $pid; rc=$?; "
                  'while kill -0 $pid 2>/dev/null; do wait $pid; rc=$?; done; '  # a trap cut the first wait short
                  'cp -a "$D/." "$C/"; exit $rc')
        return subprocess.Popen(["unshare", "-rm", "sh", "-c", script, "sh", str(disk), str(copy), *argv],
                                env={**env, "SIZE": str(size_kb)}, text=True, **kw)

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (size_kb * 1024, resource.RLIM_INFINITY))
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    shutil.copytree(copy / "given", disk, dirs_exist_ok=True)
    return subprocess.Popen(argv, env=env, cwd=disk, text=True, preexec_fn=limit, **kw)


def inspect(folder: Path, outcome: Outcome) -> None:
    """Count records, lines, half lines, pictures, empty pictures and left temporaries under ``folder``."""
    for path in sorted(folder.rglob("*")):
        if not path.is_file() or path.parts[len(folder.parts)] == "given":
            continue
        rel = path.relative_to(folder)
        if path.name.startswith(".") and path.name.endswith(".tmp"):
            outcome.left_temporaries += 1
            outcome.problems.append(f"{rel}: a temporary left")
        elif path.suffix == ".jsonl":
            outcome.records += 1
            data = path.read_bytes()
            for n, line in enumerate(data.split(b"\n"), 1):
                if not line and n == data.count(b"\n") + 1:
                    continue  # after the last new line: nothing
                outcome.lines += 1
                try:
                    json.loads(line)
                except ValueError:
                    outcome.half_lines += 1
                    outcome.problems.append(f"{rel}:{n}: not a JSON line ({line[-40:]!r})")
        elif path.suffix in (".svg", ".md", ".dot", ".json", ".csv", ".html", ".yaml") and _cut_short(path):
            outcome.empty_pictures += 1
            outcome.problems.append(f"{rel}: {path.stat().st_size} bytes, cut short")
        elif path.suffix == ".png":
            outcome.pictures += 1
            if not _decodes(path):
                outcome.empty_pictures += 1
                outcome.problems.append(f"{rel}: {path.stat().st_size} bytes, not a picture")


def _cut_short(path: Path) -> bool:
    """An empty file, or an SVG without its end."""
    data = path.read_bytes()
    return not data or (path.suffix == ".svg" and not data.rstrip().endswith(b"</svg>"))


def _decodes(path: Path) -> bool:
    import cv2

    return path.stat().st_size > 0 and cv2.imread(str(path), cv2.IMREAD_UNCHANGED) is not None


def run_writer(src: Path, writer: Writer, size_kb: int, how: str, work: Path) -> Outcome:
    disk, copy = work / "disk", work / "copy"
    disk.mkdir()
    (copy / "given").mkdir(parents=True)
    (copy / "given" / "commands.txt").write_text(writer.commands)
    argv, env = command(src, writer.argv)
    proc = full_disk_popen(argv, env, disk, copy, size_kb, how, stdin=subprocess.DEVNULL,
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        out, err = proc.communicate(timeout=writer.timeout_s)
    except subprocess.TimeoutExpired:
        proc.kill()
        out, err = proc.communicate()
    outcome = Outcome(writer.name, size_kb, how, proc.returncode)
    inspect(copy if how == "tmpfs" else disk, outcome)
    # the debugger says a command's error on standard output ("error: ..."), the session going on
    told = [ln for ln in out.splitlines() if ln.startswith("error: ")]
    judge_stderr(err if err.strip() or not told else told[-1], outcome)
    return outcome


def judge_stderr(err: str, outcome: Outcome) -> None:
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    outcome.last_line = lines[-1][:300] if lines else ""
    outcome.traceback = "Traceback" in err
    # a refused write names a file (a path with a folder or an extension) before the reason
    outcome.names_the_file = bool(re.search(r"error: .*?\S+(\.jsonl|\.png|\.svg|\.md|\.json|\.csv|\.yaml)'?: "
                                            r"(No space left|File too large)", outcome.last_line))


def run_gui(src: Path, size_kb: int, how: str, work: Path, wait_s: float = 120.0) -> Outcome:
    """``ttt-sm gui --trace`` until its trace stops on the full disk, a page connected (a WebSocket); then the
    ink picture is asked for, and SIGTERM stops it.  The page must be told, the session must answer, and it
    must end with one line naming the trace.  ``problems`` says what went wrong."""
    disk, copy = work / "disk", work / "copy"
    disk.mkdir()
    (copy / "given").mkdir(parents=True)
    argv, env = command(src, ["gui", "--port", "0", "--speed", "max", "--trace", "trace.jsonl"])
    proc = full_disk_popen(argv, env, disk, copy, size_kb, how, stdin=subprocess.DEVNULL,
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    outcome = Outcome("gui --trace", size_kb, how, None)
    try:
        url = _printed_url(proc, wait_s)
        if url is None:
            outcome.problems.append("the cockpit printed no address")
        else:
            outcome.problems += _as_a_page(url, wait_s)
    finally:
        proc.send_signal(signal.SIGTERM)  # the shell in the namespace passes it on (or, without one, the cockpit)
        try:
            _, err = proc.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            proc.kill()
            _, err = proc.communicate()
    outcome.status = proc.returncode
    inspect(copy if how == "tmpfs" else disk, outcome)
    judge_stderr(err, outcome)
    if "shutdown failed" in err.lower():
        outcome.problems.append("Application shutdown failed")
    return outcome


def _printed_url(proc: subprocess.Popen[str], wait_s: float) -> str | None:
    assert proc.stdout is not None
    give_up = time.monotonic() + wait_s
    while time.monotonic() < give_up:
        line = proc.stdout.readline()
        if not line:
            return None
        found = re.search(r"(http://\S+/charts\S*)", line)
        if found:
            return found.group(1)
    return None


def _as_a_page(url: str, wait_s: float) -> list[str]:
    """Join as a page, wait to be told the trace stopped, then fetch the ink picture; what went wrong."""
    import asyncio
    from urllib.parse import parse_qs, urlsplit

    import websockets

    parts = urlsplit(url)
    token = parse_qs(parts.query).get("token", [None])[0]
    query = f"?token={token}" if token else ""
    origin = f"{parts.scheme}://{parts.netloc}"
    problems: list[str] = []
    told: list[str] = []

    async def page() -> None:
        give_up = time.monotonic() + wait_s
        while True:  # the server listens once the robot is built
            try:
                ws = await websockets.connect(f"ws://{parts.netloc}/ws{query}", origin=origin,  # type: ignore[arg-type]
                                              max_size=1 << 22)
                break
            except OSError:
                if time.monotonic() > give_up:
                    raise
                await asyncio.sleep(0.2)
        async with ws:
            await ws.send(json.dumps({"type": "hello", "page": "charts"}))
            while time.monotonic() < give_up and not told:
                try:
                    text = await asyncio.wait_for(ws.recv(), timeout=max(0.1, give_up - time.monotonic()))
                except TimeoutError:
                    break
                message = json.loads(text)
                if message.get("type") == "error" and "trac" in str(message.get("error")):
                    told.append(str(message["error"]))

    try:
        asyncio.run(page())
    except Exception as exc:  # noqa: BLE001  (what a page would see)
        problems.append(f"the page: {type(exc).__name__}: {exc}")
    if not told:
        problems.append("the page was never told that tracing stopped")
    try:
        with urllib.request.urlopen(f"{origin}/api/arm/ink.png{query}", timeout=15) as reply:
            if reply.status != 200 or not reply.read().startswith(b"\x89PNG"):
                problems.append(f"ink.png: HTTP {reply.status}")
    except Exception as exc:  # noqa: BLE001
        problems.append(f"ink.png: {type(exc).__name__}: {exc}")
    return problems


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--src", type=Path, default=ROOT / "src", help="the source tree to run")
    parser.add_argument("--only", default=None, help="writers whose name contains one of these (comma-separated)")
    parser.add_argument("--fsize", action="store_true", help="use the file-size limit even if tmpfs works")
    args = parser.parse_args(argv)
    how = "tmpfs" if not args.fsize and namespace_works() else "fsize"
    chosen = [w for w in WRITERS if args.only is None or any(o in w.name for o in args.only.split(","))]
    outcomes: list[Outcome] = []
    for writer in chosen:
        for size in writer.sizes_kb:
            with tempfile.TemporaryDirectory() as work:
                outcomes.append(run_writer(args.src, writer, size, how, Path(work)))
                print(json.dumps(asdict(outcomes[-1])), file=sys.stderr, flush=True)
    if args.only is None or "gui" in args.only:
        for size in (24, 48):
            with tempfile.TemporaryDirectory() as work:
                outcomes.append(run_gui(args.src, size, how, Path(work)))
                print(json.dumps(asdict(outcomes[-1])), file=sys.stderr, flush=True)
    totals = {k: sum(getattr(o, k) for o in outcomes) for k in
              ("records", "lines", "half_lines", "pictures", "empty_pictures", "left_temporaries")}
    totals |= {"runs": len(outcomes), "writers": len({o.writer for o in outcomes}),
               "tracebacks": sum(o.traceback for o in outcomes),
               "last_line_names_the_file": sum(o.names_the_file for o in outcomes), "how": how}
    print(json.dumps({"totals": totals, "runs": [asdict(o) for o in outcomes]}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
