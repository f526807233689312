"""``ttt-sm --chart SLOT=FILE.py:CLASS gui`` serves the cockpit with the student's class in that slot
(docs/lab.md, "Slots and their contracts"): the diagram the cockpit draws is the student's chart."""

from __future__ import annotations

import re
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path

from web.lab_files import reference_solution


def _get(url: str, proc: subprocess.Popen[str]) -> str:
    """GET `url` once the server listens (it prints its address before it does); a dead server fails."""
    deadline = time.monotonic() + 120  # a generous bound on a busy machine, not a pace the test needs
    while True:
        try:
            return urllib.request.urlopen(url, timeout=120).read().decode()
        except urllib.error.URLError as exc:
            if not isinstance(exc.reason, ConnectionRefusedError) or time.monotonic() > deadline:
                raise
            assert proc.poll() is None, f"the gui ended (status {proc.returncode})"
            time.sleep(0.1)


def test_gui_runs_the_chart_given_with_chart_in_its_slot(tmp_path: Path) -> None:
    mine = tmp_path / "mine.py"
    mine.write_text(reference_solution().replace("approach", "creep"))  # a state of the student's naming
    proc = subprocess.Popen([sys.executable, "-m", "ttt_sm.cli", "--chart", f"DriveInit3={mine}:MyDriveInit3",
                             "gui", "--port", "0", "--paused", "--trace", str(tmp_path / "trace.jsonl")],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=tmp_path)
    try:
        assert proc.stdout is not None
        url = None
        for _ in range(10):  # the address is among the first lines it prints
            found = re.search(r"(http://127\.0\.0\.1:\d+)/charts\?token=([\w-]+)", proc.stdout.readline())
            if found:
                url, token = found.group(1), found.group(2)
                break
        assert url is not None, "no address printed"
        svg = _get(f"{url}/api/diagram/DriveInit3?token={token}", proc)
        assert 'data-state="DriveInit3.creep"' in svg and 'data-state="DriveInit3.approach"' not in svg
        thesis = _get(f"{url}/api/diagram/DriveInit1?token={token}", proc)
        assert 'data-state="DriveInit1.' in thesis  # the other slots keep the thesis' charts
    finally:
        proc.terminate()
        proc.wait(60)
