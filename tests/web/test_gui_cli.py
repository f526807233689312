"""``ttt-sm gui`` as a person starts it: the printed address serves the pages, Ctrl-C stops it and saves the trace."""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import urllib.request
from pathlib import Path

import pytest

from ttt_sm.cli.gui import beyond_this_machine


def test_gui_serves_the_printed_address_and_ctrl_c_saves_the_trace(tmp_path: Path) -> None:
    trace = tmp_path / "trace.jsonl"
    proc = subprocess.Popen([sys.executable, "-m", "ttt_sm.cli", "gui", "--port", "0", "--speed", "max",
                             "--trace", str(trace)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert proc.stdout is not None
        url = None
        for _ in range(10):
            line = proc.stdout.readline()
            found = re.search(r"(http://127\.0\.0\.1:\d+/charts\?token=[\w-]+)", line)
            if found:
                url = found.group(1)
                break
        assert url is not None, "no address printed"
        # opened at once, as a person or .ci/run does: the port listens from the moment it is printed
        page = urllib.request.urlopen(url, timeout=60).read().decode()
        assert 'data-role="sim-time"' in page
        index = urllib.request.urlopen(url.replace("/charts", "/"), timeout=5).read().decode()  # the token too
        assert 'href="/charts"' in index
        proc.send_signal(signal.SIGINT)
        out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 0, err
    assert f"trace saved to {trace}" in out
    assert trace.is_file()


@pytest.mark.parametrize("host, beyond", [("127.0.0.1", False), ("localhost", False), ("::1", False),
                                          ("0.0.0.0", True), ("192.168.1.5", True), ("robot.lab", True)])
def test_every_host_but_loopback_is_said_to_reach_beyond_this_machine(host: str, beyond: bool) -> None:
    assert beyond_this_machine(host) is beyond


def test_the_printed_port_takes_connections_before_the_server_runs(tmp_path: Path, monkeypatch, capsys) -> None:
    # .ci/run once fetched the printed address in the moment before uvicorn listened: connection refused
    import socket

    import uvicorn

    from ttt_sm.cli import main

    taken = []

    def run(self: uvicorn.Server, sockets: list[socket.socket]) -> None:  # the server never starts
        port = sockets[0].getsockname()[1]
        assert f"127.0.0.1:{port}/charts?token=" in capsys.readouterr().out  # the address is out already
        with socket.create_connection(("127.0.0.1", port), timeout=5):
            taken.append(port)

    monkeypatch.setattr(uvicorn.Server, "run", run)
    assert main(["gui", "--port", "0", "--paused", "--trace", str(tmp_path / "trace.jsonl")]) == 0
    assert len(taken) == 1
