"""A ``ttt-sm gui`` process whose session's simulation thread dies stops serving and exits with status 2.

The unit-level test (test_session_limits.py) holds the session's side: pages told, commands refused, the
listeners called.  Here the whole process: a real ``ttt-sm gui``, a real WebSocket, the thread killed by the
test-only fault hook ``TTT_SM_TEST_SESSION_FAULT`` (``ttt_sm.web.session.FAULT_ENV``, docs/gui.md).
"""

from __future__ import annotations

import json
import time
from pathlib import Path

from websockets.sync.client import connect

from gui_process import running_gui
from ttt_sm.runtime.recordfile import read_lines
from ttt_sm.web.session import FAULT_ENV


def test_gui_exits_2_in_one_line_when_its_simulation_thread_dies(tmp_path: Path) -> None:
    trace = tmp_path / "trace.jsonl"
    with running_gui("--paused", "--trace", str(trace), cwd=tmp_path, env={FAULT_ENV: "step"}) as gui:
        assert gui.host is not None, "no address printed"
        deadline = time.monotonic() + 120
        while True:  # the server listens once the address is printed; the socket may still be coming up
            try:
                ws = connect(f"ws://{gui.host}:{gui.port}/ws", open_timeout=30,
                             additional_headers={"Cookie": f"ttt_sm_token_{gui.port}={gui.token}"})
                break
            except OSError:
                assert time.monotonic() < deadline and gui.proc.poll() is None, "the cockpit did not start"
                time.sleep(0.2)
        heard = []
        with ws:
            ws.send(json.dumps({"type": "hello"}))
            while not any(m.get("type") == "frame" for m in heard):  # joined: the paused session's thread now
                heard.append(json.loads(ws.recv(timeout=120)))  # waits idle for the next command
            # the command the fault hook dies on, taken by the idle thread (a CI run once sent it before the
            # hello was handled, and the hook, then checked only where waiting commands are drained, missed it)
            ws.send(json.dumps({"type": "step", "id": 1}))
            until = time.monotonic() + 120  # a bound for a loaded machine (a server that never closes the
            try:  # page's socket fails here, not by hanging the run), not a measurement
                while time.monotonic() < until:
                    heard.append(json.loads(ws.recv(timeout=max(0.1, until - time.monotonic()))))
            except Exception:  # noqa: BLE001  the server going away ends the page's socket, however it closes
                pass
        status, err = gui.wait(timeout=120)
    lines = err.strip().splitlines()
    assert status == 2, err[-2000:]
    assert lines[-1].startswith("ttt-sm gui: error: the session stopped (") and lines[-1].endswith(
        "; restart ttt-sm gui"), lines[-1]
    assert FAULT_ENV in lines[-1] and "Traceback (most recent call last)" not in "\n".join(lines[-3:])
    fatal = [m for m in heard if m.get("type") == "error" and m.get("fatal")]
    assert fatal and "the session stopped" in fatal[0]["error"]  # the page was told before the server went
    last = read_lines(trace)[-1]  # the trace ends saying why
    assert last["event"] == "error" and last["message"] == lines[-1].removeprefix("ttt-sm gui: error: ")
