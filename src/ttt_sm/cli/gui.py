"""``ttt-sm gui``: the browser cockpit over one running robot (docs/gui.md).

:func:`register` adds the command; the web app, the robot and uvicorn are
imported only when it runs, so the CLI starts fast.
"""

from __future__ import annotations

import argparse
import ipaddress
import math
import secrets
import sys
import threading
import webbrowser
from pathlib import Path
from typing import Any

from .commands import open_arm
from .common import CliError, add_arm_option, out_dir, seed, trace_file

DEFAULT_PORT = 8765
LOOPBACK = ("127.0.0.1", "localhost", "::1")


def register(sub: Any) -> argparse.ArgumentParser:
    """Add the ``gui`` subcommand to the subparsers of ``ttt-sm``."""
    help_ = "the live chart cockpit in a browser: diagrams, data, breakpoints, replay, coverage"
    sp: argparse.ArgumentParser = sub.add_parser("gui", help=help_, description=help_)
    sp.set_defaults(func=cmd_gui)
    sp.add_argument("--host", default="127.0.0.1",
                    help="address to listen on (default 127.0.0.1; 0.0.0.0: every interface, for other machines);"
                         " every request needs the token in the printed URL")
    sp.add_argument("--port", type=int, default=DEFAULT_PORT, help=f"port (default {DEFAULT_PORT}; 0: any free one)")
    sp.add_argument("--seed", type=seed, default=0, help="seed of the simulated arm (default 0)")
    add_arm_option(sp)
    sp.add_argument("--game", action="store_true",
                    help="a whole game: the Game and AlgorithmActivator charts too; the person plays in the"
                         " /game page")
    sp.add_argument("--person", choices=("page", "simulated"), default="page",
                    help="with --game: who plays against the robot, you in the /game page (default) or a"
                         " simulated person")
    sp.add_argument("--speed", default="1",
                    help="times real time, 0.1 to 10, or 'max' for as fast as it goes (default 1)")
    sp.add_argument("--paused", action="store_true", help="start paused at power-on")
    sp.add_argument("--open", action="store_true", help="open the cockpit in a web browser")
    sp.add_argument("--scenarios", metavar="DIR", default=None,
                    help="scenario files the page may run for coverage (default: tests/scenarios when it exists)")
    sp.add_argument("--out", metavar="DIR", default="out/gui",
                    help="with --game: where each game's record (game-N/game.jsonl, as ttt-sm play writes it) and"
                         " board pictures go (default out/gui)")
    sp.add_argument("--camera", metavar="CAMERA", default=None,
                    help="a camera outside the simulation, shown in the /game page: an OpenCV capture device"
                         " index (0), a folder of pictures (shown in name order) or the serial smart camera"
                         " (serial:PORT)")
    sp.add_argument("--lab", metavar="DIR", default=None,
                    help="live while writing: watch the chart of the exercise folder DIR (made by ttt-sm lab start);"
                         " each save rebuilds the robot with it, redraws it and reruns the checks in the /lab page")
    sp.add_argument("--trace", metavar="FILE", default="out/gui/trace.jsonl",
                    help="the trace of transitions, written as they happen (JSON Lines, flushed line by line;"
                         " the last line says how the cockpit stopped; default out/gui/trace.jsonl)")
    return sp


def parse_speed(text: str) -> float | None:
    """``"max"`` -> None, else a factor from 0.1 to 10."""
    if text.strip().lower() == "max":
        return None
    try:
        value = float(text)
    except ValueError:
        raise CliError(f"--speed: expected a number from 0.1 to 10 or 'max', got {text!r}") from None
    if not (math.isfinite(value) and 0.1 <= value <= 10):
        raise CliError(f"--speed: expected a number from 0.1 to 10 or 'max', got {text!r}")
    return value


def beyond_this_machine(host: str) -> bool:
    """Whether a listening address is reachable from other machines (everything but loopback)."""
    if host in LOOPBACK:
        return False
    try:
        return not ipaddress.ip_address(host).is_loopback
    except ValueError:
        return True


def cmd_gui(args: argparse.Namespace) -> int:
    """Build the robot and its debugger, start the session and serve the pages until Ctrl-C."""
    import signal
    import socket

    import uvicorn

    from ..debug.debugger import Debugger
    from ..runtime.recordfile import ending_of
    from ..twin.workspace import load_arm
    from ..web.access import allowed_hosts, bracket, reachable_host
    from ..web.camera_feed import CameraFeedError, open_feed
    from ..web.coverage import scenario_dir_files
    from ..web.server import create_app
    from ..web.session import Session

    speed = parse_speed(args.speed)
    if not 0 <= args.port <= 65535:
        raise CliError(f"--port: expected 0 to 65535, got {args.port}")
    folder = Path(args.scenarios) if args.scenarios else Path("tests/scenarios")
    if args.scenarios and not folder.is_dir():
        raise CliError(f"--scenarios: {args.scenarios} is not a folder")
    feed = None
    if args.camera is not None:  # before the port is taken: a camera that is not there is refused first
        try:
            feed = open_feed(args.camera)
        except CameraFeedError as exc:
            raise CliError(str(exc)) from None
    record_root = out_dir(args.out, "--out") if args.game else None
    trace = trace_file(args.trace)  # refused now if it cannot be written, not when the cockpit stops
    params = load_arm(getattr(args, "params", None))
    lab = lab_watch(args) if args.lab is not None else None
    token = secrets.token_urlsafe(24)  # on every start, loopback included: any local process or user could drive
    try:
        sock = socket.socket(socket.AF_INET6 if ":" in args.host else socket.AF_INET, socket.SOCK_STREAM)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        sock.bind((args.host, args.port))
        # listening before the address is printed: a page or script that opens it while the robot is built
        # and uvicorn starts waits in the backlog instead of being refused (uvicorn's own backlog)
        sock.listen(2048)
    except OSError as exc:
        raise CliError(f"cannot listen on {args.host}:{args.port}: {exc.strerror or exc}") from None
    port = sock.getsockname()[1]
    print(f"ttt-sm gui: building the robot (seed {args.seed}) ...", file=sys.stderr, flush=True)
    conn = open_arm(args, params)
    dbg = Debugger.build(params, seed=args.seed, game=args.game, person=args.person, trace_path=trace,
                         record_root=record_root, arm=conn.arm if conn else None, truth=conn.truth if conn else None,
                         slots=lab.first_slots() if lab is not None else None)
    try:
        session = Session(dbg, speed=speed, running=not args.paused, scenarios=scenario_dir_files(folder),
                          camera_feed=feed)
        shown = bracket(reachable_host(args.host))
        app = create_app(session, token=token, hosts=allowed_hosts(args.host, port), lab=lab)
        url = f"http://{shown}{'' if port == 80 else f':{port}'}/charts?token={token}"
        print(f"ttt-sm gui: the chart cockpit is at {url}", flush=True)
        if lab is not None:
            print(f"ttt-sm gui: your chart, live while you write it, is at {url.replace('/charts', '/lab', 1)}"
                  + (f" (it does not load yet: {lab.error})" if lab.error else ""), flush=True)
        if args.game and args.person == "page":
            print(f"ttt-sm gui: play at {url.replace('/charts', '/game', 1)}", flush=True)
        if record_root is not None:
            print(f"ttt-sm gui: each game's record goes to {record_root}/game-N/game.jsonl", flush=True)
        if feed is not None:
            print(f"ttt-sm gui: the {feed.kind} camera {feed.name} is shown in the /game page", flush=True)
        if beyond_this_machine(args.host):
            print("ttt-sm gui: listening beyond this machine: the token in that URL is what lets a browser in;"
                  " keep it to yourself", flush=True)
        print("ttt-sm gui: Ctrl-C stops it (the trace is written to " + args.trace + " as it happens)", flush=True)
        if args.open:  # the game's page when you play there, the lab's with --lab, else the chart cockpit
            shown_url = (url.replace("/charts", "/game", 1) if args.game and args.person == "page" else
                         url.replace("/charts", "/lab", 1) if lab is not None else url)
            threading.Timer(1.0, webbrowser.open, args=(shown_url,)).start()
        config = uvicorn.Config(app, log_level="warning", ws_max_size=1 << 20, lifespan="on")
        server = uvicorn.Server(config)
        handle_exit = server.handle_exit

        def stop_on(sig: int, frame: Any) -> None:  # the trace's last line names the signal that stopped it
            if session.ending is None:
                session.ending = ("interrupted", {"signal": signal.Signals(sig).name})
            handle_exit(sig, frame)

        server.handle_exit = stop_on  # type: ignore[method-assign]  # uvicorn installs it for SIGINT, SIGTERM

        def session_died(why: str) -> None:  # not a corpse that serves pages: the server stops, the status says so
            try:  # in the dying simulation thread: the pages first get what they were sent (why it died)
                app.state.flush_pages()
            finally:  # whatever happened there, the server stops
                server.should_exit = True

        session.death_listeners.append(session_died)
        try:
            server.run(sockets=[sock])
        except KeyboardInterrupt:
            pass  # uvicorn shut down (the session stopped, the trace saved), then passed the Ctrl-C on
        if session.error is not None:
            raise CliError(session.error)
    except BaseException as exc:  # before the server ran, or it broke: the trace's last line says so
        how, data = ending_of(exc)
        dbg.end_trace(how, **data)  # nothing if the session ended it already
        raise
    finally:
        if conn is not None:
            conn.close()
    dbg.end_trace("finished")  # nothing if the session ended it already
    print("ttt-sm gui: stopped", flush=True)
    if dbg.trace_failure is not None:  # the session went on without its trace: the last line says which, why
        raise dbg.trace_failure
    return 0


def lab_watch(args: argparse.Namespace) -> Any:
    """``--lab DIR``: the watcher of the exercise folder's chart (web/lab_watch.py); one line if DIR is none."""
    from ..lab.exercise import LabError, read_exercise
    from ..web.lab_watch import LabTask, LabWatch

    folder = Path(args.lab)
    if not folder.is_dir():
        raise CliError(f"--lab: {args.lab} is not a folder: make one with ttt-sm lab start EXERCISE {args.lab}")
    if args.arm != "sim":
        raise CliError("--lab runs your chart on the twin: leave out --arm")
    try:
        ex = read_exercise(folder)
    except LabError as exc:
        raise CliError(f"--lab: {exc}") from None
    argv = [sys.executable, "-m", "ttt_sm.lab.live", str(folder), "--nice", "10"]
    if getattr(args, "params", None):
        argv += ["--params", str(args.params)]
    return LabWatch(LabTask(ex.title, ex.slot, ex.chart_file, ex.class_name, tuple(argv)))
