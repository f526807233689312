"""``ttt-sm camera``: serve emulated camera frames on a pseudo-terminal, or read them from a port.

``ttt-sm camera serve [--link PATH] [--board TEXT] [--rate HZ]`` runs the
camera emulator until Ctrl-C (or ``--duration``); ``ttt-sm camera read
--port PATH [--count N] [--json]`` reads frames from any port pyserial can
open (the emulator's link, ``/dev/ttyUSB0``, ``socket://...``).  Errors are
one line on standard error and exit status 2.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import itertools
import logging
import math
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from ..smartcam.emulator import CameraEmulator, Fault
from ..smartcam.errors import SerialLinkError
from ..smartcam.link import ReconnectPolicy
from ..smartcam.reader import SerialCameraReader
from ..smartcam.sources import board_source
from .common import add_group, print_json, seed

DEFAULT_LINK = str(Path(tempfile.gettempdir()) / "ttt-sm-camera")
"""Where ``serve`` puts its stable link and ``read`` looks by default."""
DEMO_BOARD = "X...O/...../..X../...../....."

_DEMO_FAULTS = (Fault.corrupt_checksum(), Fault.truncate(), Fault.out_of_range(cell=7), Fault.garbage(),
                Fault.skip(2), Fault.not_finite(cell=13), Fault.duplicate(), Fault.field_count())


def register(sub: Any) -> argparse.ArgumentParser:
    """Add the ``camera`` command to the subcommands of ``ttt-sm`` (``build_parser``'s ``sub``)."""
    help_ = "the smart camera's serial link: emulate the camera on a pseudo-terminal, or read its frames"
    sp, actions = add_group(sub, "camera", help_)

    serve = actions.add_parser("serve", help="send frames on a pseudo-terminal until Ctrl-C",
                               description="Emulate the smart camera: frames of a fixed board on a"
                               " pseudo-terminal, reachable through a stable symlink (see docs/smartcam.md).")
    serve.add_argument("--link", default=DEFAULT_LINK, help=f"stable symlink to the pty (default {DEFAULT_LINK})")
    serve.add_argument("--board", default=DEMO_BOARD,
                       help=f"25 cells of . X O, rows split by / (default {DEMO_BOARD})")
    serve.add_argument("--rate", type=float, default=10.0, help="frames per second (default 10)")
    serve.add_argument("--seed", type=seed, default=0, help="seed of the pixel noise (default 0)")
    serve.add_argument("--duration", type=float, default=None, help="stop after this many seconds (default: Ctrl-C)")
    serve.add_argument("--fault-every", type=int, default=0, metavar="N",
                       help="spoil every Nth frame with the next fault of a fixed cycle, to watch a reader cope"
                            " (default 0: none)")
    serve.add_argument("--json", action="store_true", help="print the emulator's counts as one JSON document")
    serve.set_defaults(func=cmd_camera_serve)

    read = actions.add_parser("read", help="read frames from a serial port and print them",
                              description="Read camera frames; exit status 0 if all COUNT frames came, 2 if"
                              " the port cannot be opened, is lost, or stays silent.")
    read.add_argument("--port", default=DEFAULT_LINK, help=f"pyserial URL or device (default {DEFAULT_LINK})")
    read.add_argument("--count", type=int, default=5, help="frames to read (default 5)")
    read.add_argument("--timeout", type=float, default=5.0, help="longest wait for one frame, s (default 5)")
    read.add_argument("--give-up", type=float, default=10.0, metavar="SECONDS",
                      help="stop reopening a lost port after this long (default 10)")
    read.add_argument("--baud", type=int, default=115200, help="baud rate of a real port (default 115200)")
    read.add_argument("--json", action="store_true", help="print one JSON document: frames and counts")
    read.add_argument("-v", "--verbose", action="store_true", help="log opens and reconnects too, not only problems")
    read.set_defaults(func=cmd_camera_read)
    return sp


def _fail(command: str, message: str) -> int:
    print(f"ttt-sm camera {command}: error: {message}", file=sys.stderr)
    return 2


@contextlib.contextmanager
def _log_to_stderr(level: int) -> Iterator[None]:
    """Show the link's log (rejections, reconnects) on standard error while the command runs."""
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(levelname)s %(message)s"))
    log = logging.getLogger("ttt_sm.smartcam")
    old_level = log.level
    log.addHandler(handler)
    log.setLevel(level)
    try:
        yield
    finally:
        log.removeHandler(handler)
        log.setLevel(old_level)


def cmd_camera_serve(args: argparse.Namespace) -> int:
    """Serve frames of ``--board`` on a pty until Ctrl-C or ``--duration``."""
    if not (args.rate > 0 and math.isfinite(args.rate)):
        return _fail("serve", f"--rate must be a positive number of frames per second, got {args.rate}")
    if args.duration is not None and not args.duration >= 0:
        return _fail("serve", f"--duration must be >= 0 seconds, got {args.duration}")
    if args.fault_every < 0:
        return _fail("serve", f"--fault-every must be >= 0, got {args.fault_every}")
    try:
        source = board_source(args.board, seed=args.seed)
    except ValueError as exc:
        return _fail("serve", f"--board: {exc}")
    try:
        cam = CameraEmulator(source, rate_hz=args.rate, link=args.link)
    except (ValueError, SerialLinkError) as exc:
        return _fail("serve", str(exc))
    faults = itertools.cycle(_DEMO_FAULTS)
    try:
        with _log_to_stderr(logging.WARNING), cam:
            print(f"camera: serving {args.rate:g} frames/s on {cam.port} -> {cam.device};"
                  f" read it with: ttt-sm camera read --port {cam.port}"
                  + ("" if args.duration is not None else "; Ctrl-C stops"), file=sys.stderr, flush=True)
            end = math.inf if args.duration is None else time.monotonic() + args.duration
            next_fault_at = args.fault_every
            while time.monotonic() < end:
                time.sleep(min(0.05, max(0.0, end - time.monotonic())))
                made = cam.stats.frames_sent + cam.stats.frames_dropped
                if args.fault_every and made >= next_fault_at:
                    next_fault_at = made + args.fault_every
                    cam.inject(next(faults))
    except KeyboardInterrupt:
        pass
    stats = dataclasses.asdict(cam.stats)
    if args.json:
        print_json({"link": args.link, "stats": stats})
    else:
        print("camera: stopped; " + ", ".join(f"{k} {v}" for k, v in stats.items()), file=sys.stderr)
    return 0


def cmd_camera_read(args: argparse.Namespace) -> int:
    """Read ``--count`` frames from ``--port`` and print them (5 x 5 grids, or JSON)."""
    if args.count < 1:
        return _fail("read", f"--count must be at least 1, got {args.count}")
    if not (0 < args.timeout < math.inf and 0 <= args.give_up < math.inf):
        return _fail("read", f"--timeout must be > 0 and --give-up >= 0 seconds, got {args.timeout}, {args.give_up}")
    policy = ReconnectPolicy(max_duration_s=args.give_up)
    frames = []
    error: SerialLinkError | None = None
    reader = SerialCameraReader(args.port, args.timeout, baudrate=args.baud, reconnect=policy)
    try:
        with _log_to_stderr(logging.INFO if args.verbose else logging.WARNING):
            for frame in reader.frames(args.count, idle_timeout_s=args.timeout):
                frames.append(frame)
                if not args.json:
                    print(_grid(frame), flush=True)
    except SerialLinkError as exc:
        error = exc
    finally:
        reader.close()
    stats = reader.stats
    if args.json:
        # The frames read before the link was lost are kept: the document says what came and why it stopped.
        doc = {"port": args.port, "frames": [{"seq": f.seq, "percentages": list(f.percentages)} for f in frames],
               "stats": {**dataclasses.asdict(stats), "rejected_total": stats.rejected_total},
               "complete": error is None, "error": None if error is None else str(error)}
        print_json(doc)
    if error is not None:
        return _fail("read", f"{error} ({len(frames)} of {args.count} frames read)")
    if not args.json:
        why = ", ".join(f"{k} {v}" for k, v in sorted(stats.rejected.items()))
        print(f"{stats.frames_ok} frames, rejected {stats.rejected_total}{f' ({why})' if why else ''},"
              f" gaps {stats.gaps} ({stats.frames_missed} frames missed), reconnects {stats.reconnects}",
              file=sys.stderr)
    return 0


def _grid(frame: Any) -> str:
    rows = [" ".join(f"{frame.cell(r, c):5.1f}" for c in range(1, 6)) for r in range(1, 6)]
    return f"frame {frame.seq} (percent of dark pixels per field):\n  " + "\n  ".join(rows)
