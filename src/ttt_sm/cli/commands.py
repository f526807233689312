"""The robot's own subcommands of ``ttt-sm``: play, demo, draw, tune, bench, ik, charts, params.

Each ``cmd_*`` parses nothing and prints one result (:func:`.common.emit`);
:func:`register` adds them, with their options, to the ``ttt-sm`` parser.
The application is imported only when a command runs, so the CLI starts fast.
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from typing import TYPE_CHECKING, Any

import numpy as np

from ..params import ArmParams
from .common import (
    CliError,
    add_arm_option,
    add_command,
    clear_status,
    emit,
    end_status,
    out_dir,
    print_json,
    progress,
    status_line,
    whole_number,
)

if TYPE_CHECKING:
    from ..app.arms import ArmConnection
    from ..app.game import GameSession
    from ..runtime.export import ExtraDiagram


def load_arm(path: str | None) -> ArmParams:
    """The parameter file, checked for reach (:func:`ttt_sm.twin.workspace.load_arm`); the twin is
    imported when a command runs, not when the CLI starts."""
    from ..twin.workspace import load_arm as load

    return load(path)


def open_arm(args: argparse.Namespace, params: ArmParams) -> ArmConnection | None:
    """The arm ``--arm`` names, opened (None: the twin, built by the command); one error line if it cannot be."""
    from ..app.arms import ArmChoiceError, connect_arm

    try:
        return connect_arm(getattr(args, "arm", "sim"), params)
    except ArmChoiceError as exc:
        raise CliError(str(exc)) from None


def cmd_demo(args: argparse.Namespace) -> int:
    from ..app.drawing import DrawError
    from ..app.play import run_play
    from ..runtime.recordfile import RecordFile

    out = out_dir(args.out)
    params = load_arm(args.params)
    conn = open_arm(args, params)
    try:
        with RecordFile(out / "demo.jsonl") as record:  # written as the demo goes; its last line says how it ended
            result = run_play(params, seed=args.seed, out_dir=out, progress=progress(True),
                              arm=conn.arm if conn else None, truth=conn.truth if conn else None, record=record)
    except DrawError as exc:
        raise CliError(str(exc)) from exc
    finally:
        if conn is not None:
            conn.close()
    lines = [f"  {k}: {v}" for k, v in result.items() if k != "drawings"]
    emit(result, args.json, "demo:\n" + "\n".join(lines))
    return 0


def cmd_play(args: argparse.Namespace) -> int:
    import signal

    from ..app.game import GameSession
    from ..app.game_outcome import GameInterrupted
    from ..app.game_record import GameRecord
    from ..app.person import SimulatedPerson, TerminalPerson

    if not 0 < args.time_limit < float("inf"):
        raise CliError(f"--time-limit must be a positive number of seconds, got {args.time_limit}")
    # The record is opened before anything runs: a folder that cannot take it is said now, not after the game.
    out = out_dir(args.out)
    record = GameRecord.open(out / "game.jsonl")
    session: GameSession | None = None
    conn: ArmConnection | None = None

    finished = False

    def stop(signum: int, _frame: object) -> None:
        why = signal.Signals(signum).name
        if finished:  # the record already says how the game ended: saving it and the report run to their end
            return
        if session is None:
            raise GameInterrupted(why)  # nothing runs yet: stop setting up at once
        session.interrupt(why)

    handlers = {sig: signal.signal(sig, stop) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        try:
            params = load_arm(args.params)
            conn = open_arm(args, params)
            say = progress(True, keep_status=True)
            opponent = args.opponent
            stdin_open = sys.stdin is not None and not sys.stdin.closed
            if opponent == "auto":
                opponent = "terminal" if stdin_open and sys.stdin.isatty() and not args.json else "simulated"
            elif opponent == "terminal" and not stdin_open:
                raise CliError("--opponent terminal: standard input is closed, so no one can type a move;"
                               " give it a terminal, or play against --opponent simulated")
            person = (TerminalPerson(before_write=end_status) if opponent == "terminal"
                      else SimulatedPerson(args.seed, say, args.person))
            say(f"ttt-sm play: the robot plays {args.robot_symbol} ({args.engine} engine) against a "
                f"{'person at this terminal' if opponent == 'terminal' else f'simulated person ({args.person})'}; "
                f"camera {'behind a serial port' if args.camera == 'serial' else 'read directly'}")
            session = GameSession(params, seed=args.seed, robot_symbol=args.robot_symbol, person=person,
                                  engine=args.engine, camera=args.camera, progress=say, out_dir=out,
                                  time_limit_s=args.time_limit, status=status_line(), record=record,
                                  arm=conn.arm if conn else None, truth=conn.truth if conn else None)
        except BaseException as exc:  # before the game: the record says so in its one line
            how = "interrupted" if isinstance(exc, (GameInterrupted, KeyboardInterrupt)) else "error"
            record.add(0.0, how, tick=0, waiting_for="setting up the robot (nothing ran yet)",
                       **({"signal": getattr(exc, "why", "SIGINT")} if how == "interrupted" else
                          {"message": str(exc) or type(exc).__name__}))
            record.close()
            raise
        report = _play_game(session)
        finished = True
        report.update(session.save())
        report["opponent"] = opponent if opponent == "terminal" else f"simulated {args.person}"
        lines = [f"  {k}: {v}" for k, v in report.items() if k not in ("moves", "camera_link")]
        emit(report, args.json, "play:\n" + "\n".join(lines))
    except GameInterrupted as exc:
        clear_status()
        t = session.robot.t if session is not None else 0.0
        files = session.save() if session is not None else {"record": str(record.path)}
        print(f"ttt-sm play: interrupted ({exc.why}) at t = {t:.1f} s of simulated time; the game so far: "
              f"{', '.join(files.values())}", file=sys.stderr)
        return 128 + (signal.SIGTERM if exc.why == "SIGTERM" else signal.SIGINT)
    finally:
        # The ttt-sm process exits next: once the game ended it keeps ignoring signals (main does the same
        # when any command returns; putting the handlers back first left a moment for a late one to land).
        keep_ignoring = finished and getattr(args, "ttt_sm_process", False)
        for sig, handler in handlers.items():
            signal.signal(sig, signal.SIG_IGN if keep_ignoring else handler)
        clear_status()
        if session is not None:
            session.close()
        if conn is not None:
            conn.close()
    return 0


def _play_game(session: GameSession) -> dict[str, Any]:
    from ..app.game_outcome import GameError

    try:
        return session.play()
    except GameError as exc:
        # what happened up to the failure is kept: the record and the board as it is
        files = session.save()
        raise CliError(f"{exc} (the game so far: {', '.join(files.values())})") from exc


def cmd_draw(args: argparse.Namespace) -> int:
    from ..app.drawing import DrawError, DrawSession, check_request

    out = out_dir(args.out)
    params = load_arm(args.params)
    speed = None if args.speed is None else args.speed / 1000
    size = None if args.size is None else args.size / 1000
    spacing = None if args.spacing is None else args.spacing / 1000
    try:
        check_request(params, args.kind, args.row, args.column, speed, size, spacing)
    except DrawError as exc:  # the request's own words, with the option they came from
        text = str(exc)
        option = {"cell": "--row/--column", "speed": "--speed", "size": "--size",
                  "spacing": "--spacing"}.get(text.split(" ", 1)[0])
        raise CliError(f"{option}: {text}" if option else text) from exc
    conn = open_arm(args, params)
    try:
        session = DrawSession(params, seed=args.seed, progress=progress(True), arm=conn.arm if conn else None,
                              truth=conn.truth if conn else None)
        session.start()
        result = session.draw(args.kind, args.row, args.column, speed=speed, size=size, out_dir=out,
                              spacing=spacing)
    except DrawError as exc:
        raise CliError(str(exc)) from exc
    finally:
        if conn is not None:
            conn.close()
    data = dataclasses.asdict(result)
    emit(data, args.json, "\n".join(f"  {k}: {v}" for k, v in data.items()))
    return 0


def cmd_tune(args: argparse.Namespace) -> int:
    from ..twin.step_response import report_text, tune_report

    out = out_dir(args.out)
    params = load_arm(args.params)
    rows = tune_report(params, out)
    if args.preset != "thesis":
        emit(rows, args.json, report_text(rows))
        return 0
    # the thesis' tuning beside ours (docs/tuning.md): both tables, both sets of plots
    thesis = tune_report(params, out, "thesis")
    emit({"ours": rows, "thesis": thesis}, args.json,
         "ours (designed from the parameter file):\n" + report_text(rows)
         + "\n\nthesis (its structure, gains set by hand to reproduce figs. 3.7-3.9; thesis at 0.5 s: 0.007,"
           " 0.0035, 0.003 rad):\n" + report_text(thesis))
    return 0


def cmd_bench(args: argparse.Namespace) -> int:
    """The bench: ``--out``/bench.jsonl streamed (a line per section as it ends, then how the run ended);
    ``--json``: one document at the end, also when interrupted (``"complete": false`` and the ending)."""
    from ..bench import OPT_IN, SECTIONS, run_bench
    from ..runtime.recordfile import RecordFile, ending_of

    out = out_dir(args.out)
    params = load_arm(args.params)
    only = [s.strip() for s in args.only.split(",")] if args.only else None
    unknown = [name for name in only or () if name not in SECTIONS]
    if unknown:
        raise CliError(f"--only: unknown bench section(s) {', '.join(unknown)}; choose from {', '.join(SECTIONS)}")
    if args.gui_soak is not None and not args.gui_soak > 0:
        raise CliError(f"--gui-soak: expected a positive number of minutes, got {args.gui_soak}")
    if args.link_minutes is not None and not 0 < args.link_minutes <= 1440:
        raise CliError(f"--link-minutes: expected a number of minutes in (0, 1440], got {args.link_minutes}")
    names = only or [n for n in SECTIONS if n not in OPT_IN]
    record = RecordFile(out / "bench.jsonl")
    record.add({"event": "bench", "sections": names, "seed": args.seed, "quick": args.quick,
                "gui_soak_min": args.gui_soak})
    done: dict[str, Any] = {}
    running: list[str] = []
    finished: list[str] = []

    def on_section(name: str, values: dict[str, Any] | None) -> None:
        if values is None:
            running[:] = [name]
            return
        running.clear()
        finished.append(name)
        done.update(values)
        record.add({"event": "section", "section": name, "results": values})

    try:
        try:
            result = run_bench(params, only=only, seed=args.seed, quick=args.quick, out=out,
                               progress=progress(True), gui_soak_min=args.gui_soak or 0.0, on_section=on_section,
                               link_minutes=args.link_minutes, sweep_starts=args.sweep_starts)
        except ValueError as exc:
            raise CliError(str(exc)) from exc
    except BaseException as exc:  # the record and the --json document say what was measured and where it stopped
        how, data = ending_of(exc)
        ended = {"event": how, **data, "section": running[0] if running else None,
                 "sections_done": finished}
        record.end(how, **{k: v for k, v in ended.items() if k != "event"})
        if args.json:
            print_json({**done, "complete": False, "ended": ended})
        raise
    record.end("finished", sections=names)
    emit({**result, "complete": True}, args.json)
    return 0


def cmd_ik(args: argparse.Namespace) -> int:
    """One pose by one of three methods (docs/kinematics.md): ``dls`` (the control loop's: eq. 3.35 with
    adaptive damping), ``dls-fixed`` (the thesis' own loop: lambda fixed at ``[ik] damping``), ``closed``
    (the geometric solution, elbow up or down); ``--trace`` prints each iteration's residual."""
    from ..twin.kinematics import HOME_Q, IKSolver, damped_least_squares, fk, ik_closed_form

    bad = [f"{name} = {value}" for name, value in (("x", args.x), ("y", args.y), ("z", args.z), ("--phi", args.phi))
           if not np.isfinite(value)]
    if bad:
        raise CliError(f"the target must be finite numbers (mm, degrees), got {', '.join(bad)}")
    if args.elbow is not None and args.method != "closed":
        raise CliError(f"--elbow {args.elbow}: the iterative methods start from the home pose (elbow up);"
                       " --elbow picks the branch of --method closed")
    if args.trace and args.method == "closed":
        raise CliError("--trace: the closed form does not iterate; trace --method dls or dls-fixed")
    params = load_arm(args.params)
    g = params.geometry
    target = np.array([args.x / 1000, args.y / 1000, args.z / 1000, np.radians(args.phi)])
    trace: list[dict[str, Any]] = []
    if args.method == "closed":
        q = ik_closed_form(target, g, elbow_up=args.elbow != "down")
        iterations = 0
        residual = float(np.linalg.norm(fk(q, g) - target))
    else:
        adaptive = args.method == "dls"
        res = IKSolver(params, adaptive=adaptive).solve(target)  # a fresh solver starts from HOME_Q
        q, iterations, residual = res.q, res.iterations, res.residual
        for k in range(1, iterations + 1) if args.trace else ():
            # the same compiled loop stopped after k steps: the trace is the solver's own path
            step = damped_least_squares(target, HOME_Q, g, dataclasses.replace(params.ik, max_iterations=k),
                                        adaptive=adaptive)
            trace.append({"iteration": k, "residual": step.residual,
                          "q_deg": np.degrees(step.q).round(4).tolist()})
    reached = fk(q, g)
    lo, hi = np.array(params.joint_min), np.array(params.joint_max)
    data = {"method": args.method, "q_deg": np.degrees(q).round(4).tolist(), "iterations": iterations,
            "residual": residual, "reached_mm_deg": [*(reached[:3] * 1000).round(4).tolist(),
                                                     round(float(np.degrees(reached[3])), 4)],
            "within_limits": bool(np.all((q >= lo) & (q <= hi))), "damping": params.ik.damping,
            "tolerance": params.ik.tolerance}
    if trace:
        data["trace"] = trace
    lines = [f"  {t['iteration']:3d}: residual {t['residual']:.3e}, q = {t['q_deg']} deg" for t in trace]
    how = {"dls": "eq. 3.35, adaptive damping", "dls-fixed": f"eq. 3.35, lambda fixed at {params.ik.damping:g}",
           "closed": f"closed form, elbow {args.elbow or 'up'}"}[args.method]
    text = "\n".join([*lines, f"q = {data['q_deg']} deg after {iterations} iterations (residual {residual:.2e};"
                                f" {how})" + ("" if data["within_limits"] else "; outside the joint limits")])
    emit(data, args.json, text)
    return 0


#: What `charts export` writes by default: what charts/ in the repository holds.
REPO_CHART_FORMATS = ("svg", "mermaid")


def repo_chart_extras() -> tuple[ExtraDiagram, ...]:
    """What `charts export` draws beside the charts: how the application wires them."""
    from ..app.wiring_diagram import wiring_diagrams

    return wiring_diagrams()


def cmd_charts(args: argparse.Namespace) -> int:
    from ..charts import ALL_CHARTS
    from ..runtime.export import FORMATS, export_command

    formats = tuple(f.strip() for f in args.format.split(",")) if args.format else REPO_CHART_FORMATS
    unknown = [f for f in formats if f not in FORMATS]
    if unknown:
        raise CliError(f"--format: unknown format(s) {', '.join(unknown)}; choose from {', '.join(FORMATS)}")
    if args.action == "export":
        out_dir(args.out)
    result = export_command(ALL_CHARTS, args.out, check=args.action == "check", formats=formats,
                            extras=repo_chart_extras())
    if args.action == "check":
        text = "charts are up to date" if result["ok"] else \
            "stale (run `ttt-sm charts export`):\n" + "\n".join(f"  {f}" for f in result["stale"])  # type: ignore
    else:
        text = "wrote:\n" + "\n".join(f"  {f}" for f in result["written"])  # type: ignore[attr-defined]
    emit(result, args.json, text)
    return 0 if result.get("ok", True) else 1


def cmd_params(args: argparse.Namespace) -> int:
    params = load_arm(args.params)
    emit(dataclasses.asdict(params), args.json)
    return 0


def register(sub: Any) -> None:
    """Add the robot's subcommands to the subcommands of ``ttt-sm`` (``build_parser``'s ``sub``)."""
    sp = add_command(sub, "play", cmd_play,
                     "the main job: the robot initialises, draws the field and plays a game against you")
    sp.add_argument("--opponent", choices=["auto", "terminal", "simulated"], default="auto",
                    help="auto (default): the terminal when standard input is one, else a simulated person")
    sp.add_argument("--robot-symbol", choices=["X", "O"], default="O", help="the robot's symbol; X starts")
    sp.add_argument("--engine", choices=["strong", "thesis"], default="strong", help="the game algorithm")
    sp.add_argument("--camera", choices=["serial", "direct"], default="serial",
                    help="serial (default): the smart camera emulated on a pseudo-terminal; direct: in-process")
    sp.add_argument("--person", choices=["random", "greedy", "thesis", "perfect"], default="greedy",
                    help="how the simulated person plays (default greedy: wins and blocks when it can; "
                         "perfect never lets the robot force a win); see docs/play.md")
    sp.add_argument("--time-limit", type=float, default=1200.0, metavar="SECONDS",
                    help="longest the game may run in simulated seconds (default 1200; a game takes ~190)")
    sp.add_argument("--out", default="out/play", help="folder for the game record and the board PNGs")
    add_arm_option(sp)
    sp = add_command(sub, "demo", cmd_demo, "initialise, draw the field, an X and an O, erase, finish (no game)")
    sp.add_argument("--out", default="out/demo",
                    help="folder for the board PNGs and demo.jsonl, its record written as it goes (default out/demo)")
    add_arm_option(sp)
    sp = add_command(sub, "draw", cmd_draw,
                     "draw one thing with the Control chart and measure its precision (thesis 3.5)")
    sp.add_argument("kind", choices=["field", "X", "O", "sine", "lines"],
                    help="lines: two lines parallel to X on millimetre paper (thesis fig. 3.19)")
    sp.add_argument("--row", type=int, default=3, help="cell row 1..5 for X and O (default 3)")
    sp.add_argument("--column", type=int, default=3, help="cell column 1..5 for X and O (default 3)")
    sp.add_argument("--speed", type=float, default=None, help="drawing speed, mm/s (default 20)")
    sp.add_argument("--size", type=float, default=None, help="symbol size, mm (default 18)")
    sp.add_argument("--spacing", type=float, default=None, metavar="MM",
                    help="lines only: the distance between the two lines, mm (default 50, as fig. 3.19)")
    sp.add_argument("--out", default="out/draw", help="folder for the board PNG and the path plot")
    add_arm_option(sp)
    sp = add_command(sub, "tune", cmd_tune, "design the cascade controllers and step each drive on the nonlinear twin")
    sp.add_argument("--out", default="out/tune", help="folder for the step-response PNGs")
    sp.add_argument("--preset", choices=["ours", "thesis"], default="ours",
                    help="ours (default): the designed gains; thesis: the thesis' hand-set gains beside ours")
    sp = add_command(sub, "bench", cmd_bench, "measure the speed and quality targets")
    sp.add_argument("--only", default=None,
                    help="comma-separated sections: steps,ik,loop,pacing,charts,init,motion,vision,ai,game,gui,link;"
                         " lab_grade (grading a class of 30, minutes long) and init_sweep (init starts on 1 and 2"
                         " local workers and a 2-worker Dask LocalCluster) run only when named here")
    sp.add_argument("--quick", action="store_true", help="short timed runs (to test the command)")
    sp.add_argument("--gui-soak", metavar="MIN", type=float, default=None,
                    help="gui section: also run MIN minutes at x10 and report the memory after 1 and after MIN")
    sp.add_argument("--link-minutes", metavar="MIN", type=float, default=None,
                    help="link section: stream setpoints to the emulator for MIN minutes (default 10; --quick: 5 s)")
    sp.add_argument("--sweep-starts", metavar="N", type=whole_number, default=None,
                    help="init_sweep section: starts on each runner (default 40; --quick: 6; 10000 for the long sweep)")
    sp.add_argument("--out", default="out/bench", help="folder for plots the bench writes")
    sp = add_command(sub, "ik", cmd_ik, "solve inverse kinematics for one tool pose")
    sp.add_argument("x", type=float, help="mm")
    sp.add_argument("y", type=float, help="mm")
    sp.add_argument("z", type=float, help="mm")
    sp.add_argument("--phi", type=float, default=0.0, help="pen angle phi, degrees (default 0)")
    sp.add_argument("--method", choices=["dls", "dls-fixed", "closed"], default="dls",
                    help="dls (default): eq. 3.35 with adaptive damping, as the control loop runs it; dls-fixed:"
                         " the thesis' loop, lambda fixed at [ik] damping (0.001); closed: the geometric solution")
    sp.add_argument("--elbow", choices=["up", "down"], default=None,
                    help="--method closed: the elbow-up (default, the working pose) or elbow-down branch")
    sp.add_argument("--trace", action="store_true",
                    help="print each iteration's residual and joint angles (dls, dls-fixed), from the home pose")
    sp = add_command(sub, "charts", cmd_charts, "export the chart diagrams, or check that charts/ is up to date")
    sp.add_argument("action", choices=["export", "check"])
    sp.add_argument("--format", default=None,
                    help="comma-separated: svg,png,mermaid,dot (default svg,mermaid: what charts/ holds)")
    sp.add_argument("--out", default="charts", help="folder (default charts/)")
    add_command(sub, "params", cmd_params, "print the parameters in force (SI units)")
