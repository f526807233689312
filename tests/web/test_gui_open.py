"""``ttt-sm gui --open`` opens the cockpit in the person's browser: Python's ``webbrowser``, which honours
``BROWSER``.  Here ``BROWSER`` is a small script that writes down the address it was given."""

from __future__ import annotations

import sys
import time
import urllib.request
from pathlib import Path

from gui_process import running_gui


def test_gui_open_gives_the_printed_address_to_the_browser_named_in_BROWSER(tmp_path: Path) -> None:  # noqa: N802
    opened = tmp_path / "opened.txt"
    browser = tmp_path / "browser.py"
    browser.write_text("import sys\n"
                       f"with open({str(opened)!r}, 'a') as f:\n"
                       "    f.write(' '.join(sys.argv[1:]) + '\\n')\n")
    env = {"BROWSER": f"{sys.executable} {browser} %s", "DISPLAY": "", "WAYLAND_DISPLAY": ""}
    with running_gui("--paused", "--open", "--trace", str(tmp_path / "trace.jsonl"), env=env, cwd=tmp_path,
                     lines=10) as gui:
        url = gui.url
        deadline = time.monotonic() + 120
        while not (opened.exists() and opened.read_text().endswith("\n")) and time.monotonic() < deadline \
                and gui.proc.poll() is None:
            time.sleep(0.05)
        assert opened.read_text().splitlines() == [url]  # once, the address printed, its token too
        page = urllib.request.urlopen(url, timeout=10).read().decode()  # and it serves the cockpit
        assert 'data-role="sim-time"' in page
        status, err = gui.stop()
    assert status == 0, err
