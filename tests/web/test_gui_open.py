"""``ttt-sm gui --open`` opens the cockpit in the person's browser: Python's ``webbrowser``, which honours
``BROWSER``.  Here ``BROWSER`` is a small script that writes down the address it was given."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
import urllib.request
from pathlib import Path


def test_gui_open_gives_the_printed_address_to_the_browser_named_in_BROWSER(tmp_path: Path) -> None:  # noqa: N802
    opened = tmp_path / "opened.txt"
    browser = tmp_path / "browser.py"
    browser.write_text("import sys\n"
                       f"with open({str(opened)!r}, 'a') as f:\n"
                       "    f.write(' '.join(sys.argv[1:]) + '\\n')\n")
    env = {**os.environ, "BROWSER": f"{sys.executable} {browser} %s", "DISPLAY": "", "WAYLAND_DISPLAY": ""}
    proc = subprocess.Popen([sys.executable, "-m", "ttt_sm.cli", "gui", "--port", "0", "--paused", "--open",
                             "--trace", str(tmp_path / "trace.jsonl")],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env, cwd=tmp_path)
    try:
        assert proc.stdout is not None
        url = None
        for _ in range(10):
            found = re.search(r"(http://127\.0\.0\.1:\d+/charts\?token=[\w-]+)", proc.stdout.readline())
            if found:
                url = found.group(1)
                break
        assert url is not None, "no address printed"
        deadline = time.monotonic() + 120
        while not (opened.exists() and opened.read_text().endswith("\n")) and time.monotonic() < deadline \
                and proc.poll() is None:
            time.sleep(0.05)
        assert opened.read_text().splitlines() == [url]  # once, the address printed, its token too
        page = urllib.request.urlopen(url, timeout=10).read().decode()  # and it serves the cockpit
        assert 'data-role="sim-time"' in page
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0, err
