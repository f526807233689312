"""``ttt-sm arm serve``: the arm's firmware, emulated on a pseudo-terminal.

The C firmware (``firmware/``, built with the system compiler) runs on the
twin's plant behind a pty reachable through a stable symlink
(docs/hardware.md).  ``--pace realtime`` steps it on the wall clock like a
board; ``--pace gated`` lets the PC's setpoints set the pace.  Errors are
one line on standard error and exit status 2.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from .common import add_group, print_json, seed

DEFAULT_LINK = str(Path(tempfile.gettempdir()) / "ttt-sm-arm")
"""Where ``serve`` puts its stable link by default."""


def register(sub: Any) -> argparse.ArgumentParser:
    """Add the ``arm`` command to the subcommands of ``ttt-sm``."""
    help_ = "the real arm's side: emulate its firmware (the C that is flashed) on a pseudo-terminal"
    sp, actions = add_group(sub, "arm", help_)
    serve = actions.add_parser(
        "serve", help="run the firmware on the twin's plant behind a pseudo-terminal until Ctrl-C",
        description="Emulate the arm: the C firmware coupled to the twin's plant, on a pseudo-terminal reachable"
                    " through a stable symlink (see docs/hardware.md).")
    serve.add_argument("--link", default=DEFAULT_LINK, help=f"stable symlink to the pty (default {DEFAULT_LINK})")
    serve.add_argument("--pace", choices=("gated", "realtime"), default="realtime",
                       help="realtime: control steps on the wall clock, as a board; gated: the PC's setpoints"
                            " set the pace (default realtime)")
    serve.add_argument("--precision", choices=("float", "double"), default="float",
                       help="the firmware's number type (default float, as the reference board)")
    serve.add_argument("--seed", type=seed, default=0, help="seed of the plant's current noise (default 0)")
    serve.add_argument("--no-truth", dest="truth", action="store_false",
                       help="send only what a board sends: no EMU_TRUTH frames (the plant's true angles, which the"
                            " PC's simulated whiteboard and precision figures need)")
    serve.add_argument("--realtime-priority", action="store_true",
                       help="run the emulator at SCHED_FIFO priority, as a board's loop runs first (Linux, root or"
                            " CAP_SYS_NICE; said when refused)")
    serve.add_argument("--duration", type=float, default=None, help="stop after this many seconds (default: Ctrl-C)")
    serve.add_argument("--json", action="store_true", help="print the emulator's counts as one JSON document")
    serve.set_defaults(func=cmd_arm_serve)
    return sp


def _fail(message: str) -> int:
    print(f"ttt-sm arm serve: error: {message}", file=sys.stderr)
    return 2


def cmd_arm_serve(args: argparse.Namespace) -> int:
    """Run the emulator until Ctrl-C or ``--duration``; print what went over the link."""
    from ..hardware.emulator import ArmEmulator, ArmEmulatorError
    from ..hardware.firmware import FirmwareError
    from ..twin.workspace import load_arm

    if args.duration is not None and not (args.duration >= 0 and math.isfinite(args.duration)):
        return _fail(f"--duration must be a finite number >= 0 of seconds, got {args.duration}")
    params = load_arm(args.params)
    try:
        emu = ArmEmulator(params, pace=args.pace, link=args.link, precision=args.precision, seed=args.seed,
                          truth=args.truth, realtime=args.realtime_priority)
    except (ArmEmulatorError, FirmwareError) as exc:
        return _fail(str(exc))
    import gc

    gc.freeze()  # the firmware, the plant and the libraries stay: a collection walks only what the loop makes
    try:
        with emu:
            print(f"arm: the {args.precision} firmware on the twin's plant ({args.pace}) on {emu.port};"
                  + ("" if args.duration is not None else " Ctrl-C stops"), file=sys.stderr, flush=True)
            end = math.inf if args.duration is None else time.monotonic() + args.duration
            time.sleep(0.05)  # the firmware's thread has asked for its priority
            if emu.priority_note:
                print(f"arm: {emu.priority_note}; the firmware runs at the normal priority", file=sys.stderr,
                      flush=True)
            elif args.realtime_priority:
                from ..ptylink import realtime_priority

                realtime_priority()  # this thread too: held off the processor, it could hold the firmware's up
            while time.monotonic() < end:
                time.sleep(min(0.05, max(0.0, end - time.monotonic())))
    except KeyboardInterrupt:
        pass
    fw = emu.firmware
    stats = {"steps": fw.steps, "state": ("idle", "running", "safe_stop")[fw.state], "frames_ok": fw.frames_ok,
             "setpoints_ok": fw.setpoints_ok, "lost": fw.lost,
             "rejections": {name: n for name, n in zip(_REASONS, fw.rejections().values(), strict=True) if n},
             "bytes_in": emu.bytes_in, "bytes_out": emu.bytes_out, "bytes_dropped": emu.bytes_dropped}
    if args.json:
        print_json({"link": args.link, "pace": args.pace, "precision": args.precision, "stats": stats})
    else:
        print("arm: stopped; " + ", ".join(f"{k} {v}" for k, v in stats.items()), file=sys.stderr)
    return 0


_REASONS = ("cobs", "crc", "short", "overlong", "unknown_type", "partial", "length", "duplicate", "out_of_order",
            "late", "refused", "value")
