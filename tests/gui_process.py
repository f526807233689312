"""A real ``ttt-sm gui`` process for the tests that need one: started, its printed address read, stopped.

The tests that start the cockpit as a person does (tests/web/test_access.py, tests/web/test_gui_open.py,
tests/test_one_writer.py, tests/web/test_session_death.py) share this instead of each reading the
address its own way.  The child gets this process's ``PYTHONPATH`` with every entry made absolute,
so a child started in another folder imports the same ``ttt_sm`` as the test.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

#: The address ``ttt-sm gui`` prints once the robot is built (docs/gui.md): host, port, token.
ADDRESS = re.compile(r"http://([^/:\s]+):(\d+)/charts\?token=([\w-]+)")


def child_env(extra: Mapping[str, str] | None = None) -> dict[str, str]:
    """This process's environment for a child, its PYTHONPATH absolute, with ``extra`` on top."""
    env = dict(os.environ)
    if env.get("PYTHONPATH"):
        env["PYTHONPATH"] = os.pathsep.join(str(Path(p).resolve()) for p in env["PYTHONPATH"].split(os.pathsep))
    env.update(extra or {})
    return env


@dataclass
class RunningGui:
    """A started ``ttt-sm gui``: its process and the address it printed (None: it printed none)."""

    proc: subprocess.Popen[str]
    host: str | None
    port: int | None
    token: str | None

    @property
    def url(self) -> str:
        """The address as printed: ``http://HOST:PORT/charts?token=...``."""
        assert self.host is not None, "no address printed"
        return f"http://{self.host}:{self.port}/charts?token={self.token}"

    @property
    def base(self) -> str:
        return f"http://{self.host}:{self.port}"

    def stop(self, sig: int = signal.SIGINT, timeout: float = 60) -> tuple[int, str]:
        """Send ``sig`` (Ctrl-C), wait for the end: its exit status and standard error."""
        self.proc.send_signal(sig)
        _, err = self.proc.communicate(timeout=timeout)
        return self.proc.returncode, err

    def wait(self, timeout: float = 120) -> tuple[int, str]:
        """Wait for it to end by itself: its exit status and standard error."""
        _, err = self.proc.communicate(timeout=timeout)
        return self.proc.returncode, err


@contextmanager
def running_gui(*args: str, cwd: Path | None = None, env: Mapping[str, str] | None = None,
                lines: int = 20) -> Iterator[RunningGui]:
    """``ttt-sm gui --port 0 ARGS``, read up to its printed address (at most ``lines`` lines); killed on
    leaving if it still runs."""
    proc = subprocess.Popen([sys.executable, "-m", "ttt_sm.cli", "gui", "--port", "0", *args],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=cwd,
                            env=child_env(env))
    try:
        assert proc.stdout is not None
        found = None
        for _ in range(lines):
            line = proc.stdout.readline()
            found = ADDRESS.search(line)
            if found or not line:
                break
        host, port, token = found.groups() if found else (None, None, None)
        yield RunningGui(proc, host, int(port) if port else None, token)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
