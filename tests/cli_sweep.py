"""Run ``ttt-sm`` command lines each in a process of its own, quickly: the driver of tests/test_cli_sweep.py.

Reads a JSON list of argument lists on standard input; imports the CLI once,
then forks one child per command line.  The child is a process of its own
with its own standard output and error (pipes the driver reads) and its own
exit status; it runs :func:`ttt_sm.cli.main` as the console script does
(``sys.exit(main())``), and an exception that escapes it is printed the way
the interpreter would (a ``Traceback``), so the test sees what a user would.
Prints one JSON list: for each command line its ``status``, ``out``, ``err``
and whether it ``timed_out`` (killed after ``TIMEOUT_S``: a bad argument must
be refused before anything runs, not after a simulation).
"""

from __future__ import annotations

import json
import os
import selectors
import signal
import sys
import time
import traceback

TIMEOUT_S = float(os.environ.get("TTT_SM_SWEEP_TIMEOUT", "60"))
#: What the commands import when they run, imported by the driver before it forks.
WARM = ("ttt_sm.cli", "ttt_sm.app.game", "ttt_sm.app.play", "ttt_sm.app.init_wiring", "ttt_sm.twin.workspace",
        "ttt_sm.vision", "ttt_sm.scenario.suite", "ttt_sm.debug", "ttt_sm.bench", "ttt_sm.runtime.export")


def _child(argv: list[str], out_w: int, err_w: int) -> None:
    os.dup2(out_w, 1)
    os.dup2(err_w, 2)
    devnull = os.open(os.devnull, os.O_RDONLY)
    os.dup2(devnull, 0)  # no one types: the commands must not wait for input
    sys.stdin = open(0, closefd=False)  # noqa: SIM115 - the child's whole life
    sys.stdout = open(1, "w", closefd=False)  # noqa: SIM115
    sys.stderr = open(2, "w", closefd=False)  # noqa: SIM115
    from ttt_sm.cli import main

    status = 1
    try:
        status = main(argv)
    except SystemExit as exc:  # argparse's usage errors, as the console script would end
        code = exc.code
        status = code if isinstance(code, int) else (0 if code is None else 1)
        if not isinstance(code, int) and code is not None:
            print(code, file=sys.stderr)
    except BaseException:  # what escapes main(): printed as the interpreter would
        traceback.print_exc()
        status = 1
    finally:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except OSError:
                pass
        os._exit(status)


def run(argv: list[str]) -> dict[str, object]:
    t0 = time.monotonic()
    out_r, out_w = os.pipe()
    err_r, err_w = os.pipe()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        os.close(out_r)
        os.close(err_r)
        _child(argv, out_w, err_w)
    os.close(out_w)
    os.close(err_w)
    chunks: dict[int, list[bytes]] = {out_r: [], err_r: []}
    sel = selectors.DefaultSelector()
    for fd in chunks:
        sel.register(fd, selectors.EVENT_READ)
    deadline = time.monotonic() + TIMEOUT_S
    timed_out = False
    open_fds = set(chunks)
    while open_fds:
        left = deadline - time.monotonic()
        if left <= 0:
            timed_out = True
            os.kill(pid, signal.SIGKILL)
            break
        for key, _ in sel.select(min(left, 1.0)):
            data = os.read(key.fd, 65536)
            if data:
                chunks[key.fd].append(data)
            else:
                sel.unregister(key.fd)
                open_fds.discard(key.fd)
    _, wait_status = os.waitpid(pid, 0)
    for fd in chunks:
        os.close(fd)
    return {"argv": argv, "wall_s": round(time.monotonic() - t0, 2),
            "status": os.waitstatus_to_exitcode(wait_status), "timed_out": timed_out,
            "out": b"".join(chunks[out_r]).decode(errors="replace"),
            "err": b"".join(chunks[err_r]).decode(errors="replace")}


def main() -> None:
    cases = json.load(sys.stdin)
    import importlib

    for module in WARM:  # imported once, before the forks: each child starts at once
        importlib.import_module(module)

    results = [run(argv) for argv in cases]
    json.dump(results, sys.stdout)


if __name__ == "__main__":
    main()
