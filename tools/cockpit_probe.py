"""Load probes of the cockpit's server (docs/reliability.md, "The cockpit's session"): measurements, not tests.

Starts ``ttt-sm gui`` in a process of its own (at x1, running), joins it as a
viewer page and measures what the viewer sees while another page floods the
session::

    python -m tools.cockpit_probe [--flood 20000] [--posts 200000] [--json]

- flood: one page sends ``--flood`` ``hello`` messages as fast as its socket
  takes them (reading what comes back); the viewer's longest gap between two
  frames (a freeze), the simulated against wall time meanwhile (the pace), how
  the flooder's messages were answered;
- posts: one page sends ``--posts`` ``post`` messages, then the server's
  resident memory is read (``/proc/PID/status``) against its idle value;
- after each: the session must still answer a command (``speed``, handled in
  its simulation thread) and the process live (deaths counted).
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import json
import re
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from pathlib import Path
from typing import Any

import websockets


def rss_mb(pid: int) -> float:
    """Resident memory of process ``pid``, MB."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024
    raise RuntimeError("no VmRSS")


def start_gui(folder: Path) -> tuple[subprocess.Popen[str], str, str]:
    proc = subprocess.Popen([sys.executable, "-m", "ttt_sm.cli", "gui", "--port", "0", "--speed", "1",
                             "--trace", str(folder / "trace.jsonl")],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=folder)
    assert proc.stdout is not None
    for _ in range(20):
        found = re.search(r"http://([^/\s]+)/charts\?token=([\w-]+)", proc.stdout.readline())
        if found:
            return proc, found.group(1), found.group(2)
    proc.kill()
    raise RuntimeError("ttt-sm gui printed no address")


async def connect(host: str, token: str) -> Any:
    deadline = time.monotonic() + 120
    while True:
        try:
            return await websockets.connect(f"ws://{host}/ws", additional_headers={"Cookie": f"ttt_sm_token_"
                                            f"{host.rsplit(':', 1)[1]}={token}"}, max_size=2**24)
        except OSError:
            if time.monotonic() > deadline:
                raise
            await asyncio.sleep(0.2)


class Viewer:
    """A page that only watches, in a thread and event loop of its own (so the flooding page of this process
    never delays its reading): the arrival time and simulated time of each frame."""

    def __init__(self, host: str, token: str) -> None:
        self.frames: list[tuple[float, float]] = []
        #: The session's pacing figures of each frame (web/frames.py ``pace``): slips and time lost.
        self.paces: list[tuple[float, dict[str, Any]]] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=lambda: asyncio.run(self._read(host, token)), daemon=True)
        self._thread.start()

    async def _read(self, host: str, token: str) -> None:
        ws = await connect(host, token)
        await ws.send(json.dumps({"type": "hello"}))
        while not self._stop.is_set():
            try:
                text = await asyncio.wait_for(ws.recv(), 0.5)
            except TimeoutError:
                continue
            except websockets.ConnectionClosed:
                return
            m = json.loads(text)
            if m.get("type") == "frame":
                now = time.perf_counter()
                self.frames.append((now, float(m["t"])))
                if "pace" in m:
                    self.paces.append((now, m["pace"]))
        await ws.close()

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(10)

    def between(self, t0: float, t1: float) -> dict[str, float]:
        seen = [(w, t) for w, t in self.frames if t0 <= w <= t1]
        gaps = [b[0] - a[0] for a, b in zip(seen, seen[1:], strict=False)]
        edges = [seen[0][0] - t0, t1 - seen[-1][0]] if seen else [t1 - t0]
        pace = (seen[-1][1] - seen[0][1]) / (seen[-1][0] - seen[0][0]) if len(seen) > 1 else 0.0
        paces = [p for w, p in self.paces if t0 <= w <= t1]
        out = {"frames": len(seen), "longest_gap_s": round(max(gaps + edges), 3), "pace_x": round(pace, 3)}
        if len(paces) > 1:  # the session's own account of the time it did not keep
            out["slips"] = paces[-1]["slips"] - paces[0]["slips"]
            out["lost_s"] = round(paces[-1]["lost_s"] - paces[0]["lost_s"], 3)
            out["overruns"] = paces[-1]["overruns"] - paces[0]["overruns"]
        return out


async def still_answers(host: str, token: str) -> bool:
    ws = await connect(host, token)
    try:
        await ws.send(json.dumps({"type": "speed", "value": 1, "id": "alive"}))  # changes nothing, needs the thread
        async with asyncio.timeout(30):
            async for text in ws:
                m = json.loads(text)
                if m.get("id") == "alive":
                    return bool(m.get("type") == "reply")
    except TimeoutError:
        return False
    finally:
        await ws.close()
    return False


async def flood(host: str, token: str, messages: list[str], rate: float | None = None,
                answers: Counter[str] | None = None) -> tuple[float, float, Counter[str]]:
    """Send ``messages`` from one page as fast as its socket takes them (or ``rate`` a second); how they were
    answered.  A server that closes the page (its keep-alive ping unanswered behind the flood) ends it."""
    try:
        return await _flood(host, token, messages, rate, answers if answers is not None else Counter())
    except websockets.ConnectionClosed as exc:
        now = time.perf_counter()
        counted = answers if answers is not None else Counter()
        counted[f"closed by the server: {exc.rcvd.reason if exc.rcvd else exc}"] += 1
        return now, now, counted


async def _flood(host: str, token: str, messages: list[str], rate: float | None,
                 answers: Counter[str]) -> tuple[float, float, Counter[str]]:
    ws = await connect(host, token)

    async def read() -> None:
        async for text in ws:
            m = json.loads(text)
            kind = m.get("type")
            if m.get("id") == "end":
                answers["end"] += 1
                continue
            if kind == "error" and "dropped" in m:  # one notice a window for the messages dropped unread
                answers["dropped unread: messages"] += int(m["dropped"])
                kind = "dropped unread: notices"
            elif kind == "error":
                kind = "refused: page queue full" if "commands waiting" in m["error"] else "error: " + m["error"][:60]
            answers[kind] += 1

    reader = asyncio.create_task(read())
    t0 = time.perf_counter()
    for i, text in enumerate(messages):
        await ws.send(text)
        if rate is not None and i % 50 == 49:
            await asyncio.sleep(max(0.0, t0 + (i + 1) / rate - time.perf_counter()))
    # the server reads a page at most MESSAGE_RATE messages a second: the rest waits in this page's TCP
    # connection; the flood is over when the server has read the last message (answered, or refused)
    # (asked again every 2 s: a page that floods also overflows its own outbox, and an answer may be dropped)
    with contextlib.suppress(TimeoutError):
        async with asyncio.timeout(1800):
            while not answers["end"]:
                await ws.send(json.dumps({"type": "speed", "value": 1, "id": "end"}))
                for _ in range(40):
                    if answers["end"]:
                        break
                    await asyncio.sleep(0.05)
    t1 = time.perf_counter()
    reader.cancel()
    await ws.close()
    return t0, t1, answers


async def probe(n_flood: int, n_posts: int) -> dict[str, Any]:
    with tempfile.TemporaryDirectory() as tmp:
        proc, host, token = start_gui(Path(tmp))
        out: dict[str, Any] = {}
        viewer = Viewer(host, token)
        try:
            quiet = time.perf_counter()
            await asyncio.sleep(10)  # running at x1; the heap settles
            idle = rss_mb(proc.pid)
            out["rss_idle_mb"] = round(idle, 1)
            out["quiet"] = viewer.between(quiet + 4, time.perf_counter())
            t0, t1, answers = await flood(host, token, [json.dumps({"type": "hello", "id": i})
                                                        for i in range(n_flood)])
            out["flood"] = {"messages": n_flood, "read_in_s": round(t1 - t0, 2), **viewer.between(t0, t1),
                            "answers": dict(answers)}
            out["flood"]["session_alive"] = proc.poll() is None and await still_answers(host, token)
            # four pages, each at 450 a second (the server reads a page at 500): all are read, none is closed
            pages = 4
            share = [[json.dumps({"type": "post", "chart": "Control", "event": "button", "id": i})
                      for i in range(k, n_posts, pages)] for k in range(pages)]
            spans = await asyncio.gather(*(flood(host, token, part, rate=450.0) for part in share))
            p0, p1 = min(a for a, _, _ in spans), max(b for _, b, _ in spans)
            answers = sum((c for _, _, c in spans), Counter())
            await asyncio.sleep(5)
            out["posts"] = {"messages": n_posts, "pages": pages, "read_in_s": round(p1 - p0, 2),
                            "rss_after_mb": round(rss_mb(proc.pid), 1),
                            "rss_above_idle_mb": round(rss_mb(proc.pid) - idle, 1),
                            **viewer.between(p0, p1), "answers": dict(answers)}
            out["posts"]["session_alive"] = proc.poll() is None and await still_answers(host, token)
            out["deaths"] = int(not out["flood"]["session_alive"]) + int(not out["posts"]["session_alive"])
        finally:
            viewer.stop()
            proc.send_signal(signal.SIGINT)
            try:
                proc.communicate(timeout=60)
            except subprocess.TimeoutExpired:
                proc.kill()
            out["exit_status"] = proc.returncode
        return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    ap.add_argument("--flood", type=int, default=20_000)
    ap.add_argument("--posts", type=int, default=200_000)
    args = ap.parse_args()
    print(json.dumps(asyncio.run(probe(args.flood, args.posts)), indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
