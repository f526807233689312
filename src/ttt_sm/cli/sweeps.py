"""The sweeps of ``ttt-sm``: init and faults, many runs over seeds on a pool or a cluster.

``init`` initialises the drives with the init charts from random power-on
poses; ``faults`` injects each fault of the arm in each phase and measures
what the Safety chart does (``--link``: the serial link's faults, in real
time).  Both run their runs on a :class:`~ttt_sm.runner.Runner` (``--workers
N`` local processes, or ``--dask ADDRESS``), print what was done on Ctrl-C,
and exit 0 only when every run met its limits.  See docs/reliability.md and
docs/safety.md.
"""

from __future__ import annotations

import argparse
import logging
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

from .commands import load_arm, open_arm
from .common import (
    CliError,
    add_arm_option,
    add_command,
    add_runner_options,
    clear_status,
    emit,
    status_line,
)

if TYPE_CHECKING:
    from ..runner import Runner


#: Most power-on poses one ``init`` runs (each takes about half a second of computing: 10000 is a long sweep,
#: best on a pool or a cluster, ``--workers``/``--dask``).
MAX_STARTS = 10000


def sweep_runner(args: argparse.Namespace, preload: tuple[str, ...] = ()) -> Runner:
    """The runner of a sweep's ``--workers N`` / ``--dask ADDRESS`` (:mod:`ttt_sm.runner`)."""
    from ..runner import Runner, dask_client

    if args.dask is not None:
        if args.workers != 1:
            raise CliError(f"--workers {args.workers} and --dask: the cluster's workers run the tasks; give one")
        return Runner(client=dask_client(args.dask))
    return Runner(workers=args.workers, preload=preload)


def in_this_process(args: argparse.Namespace, why: str, drop: str = "") -> None:
    """Refuse ``--workers``/``--dask`` for a run that must stay in this process: `why`, then what to drop."""
    if args.workers != 1 or args.dask is not None:
        option = f"--workers {args.workers}" if args.dask is None else "--dask"
        raise CliError(f"{option}: {why}; drop {option}{drop}")


@contextmanager
def sweeping(args: argparse.Namespace, preload: tuple[str, ...],
             emit: Callable[[dict[str, Any], argparse.Namespace], int]) -> Iterator[Runner]:
    """The runner of a sweep, closed after it; on Ctrl-C, what was done is printed with `emit`, then exit 130."""
    from ..runner import SweepInterrupted

    runner = sweep_runner(args, preload)
    try:
        yield runner
    except SweepInterrupted as stopped:
        clear_status()
        emit(stopped.report, args)  # what was done before the Ctrl-C; the interrupt then exits with 130
        raise
    finally:
        clear_status()
        if runner.client is not None:
            runner.client.close()


def cmd_init(args: argparse.Namespace) -> int:
    from ..app.init_wiring import INIT_PRELOAD, init_report

    if not 1 <= args.starts <= MAX_STARTS:
        raise CliError(f"--starts must lie in 1..{MAX_STARTS}, got {args.starts}")
    if not 0 < args.time_limit <= 3600:
        raise CliError(f"--time-limit must lie in (0, 3600] simulated seconds, got {args.time_limit}")
    params = load_arm(args.params)
    if args.arm != "sim" and args.starts != 1:
        raise CliError(f"--starts {args.starts}: an arm behind a serial link initialises once, from where it stands;"
                       " give --starts 1")
    if args.arm != "sim":
        in_this_process(args, "an arm behind a serial link initialises once, in this process")
    with sweeping(args, INIT_PRELOAD, _emit_init) as runner:
        conn = open_arm(args, params)
        try:
            report = init_report(params, args.starts, seed=args.seed, timeout_s=args.time_limit,
                                 status=status_line(), arm=conn.arm if conn else None,
                                 truth=conn.truth if conn else None, runner=runner)
        except ValueError as exc:
            raise CliError(f"--arm {args.arm}: {exc}") from exc
        finally:
            if conn is not None:
                conn.close()
    return _emit_init(report, args)


def _emit_init(report: dict[str, Any], args: argparse.Namespace) -> int:
    """Print `report` (JSON or text); the exit status it earns: 0 when every run initialised within the limits."""
    text = "\n".join(f"  {k}: {v}" for k, v in report.items())
    title = f"init from {args.starts} random power-on poses" + (
        f" (interrupted after {report['runs']})" if report["interrupted"] else "")
    emit(report, args.json, f"{title}:\n{text}")
    ok = report["successes"] == report["runs"] and not report["limit_violations"] \
        and not report["board_zone_entries"]
    return 0 if ok else 1


#: The phases of ``ttt-sm faults --phases``, by their short names.
FAULT_PHASES = {"init": "initialising", "field": "drawing the field", "symbol": "drawing a symbol",
                "erase": "erasing"}


def _choices(text: str, known: Any, option: str) -> list[str]:
    """A comma-separated list of names from `known`, in the order given; a clear error names a stranger."""
    names = [n.strip() for n in text.split(",") if n.strip()]
    bad = [n for n in names if n not in known]
    if bad or not names:
        raise CliError(f"{option}: {'no name given' if not names else f'unknown {bad[0]!r}'};"
                       f" choose from {', '.join(known)}")
    return names


def fault_arm(text: str) -> str:
    """The ``type`` of ``ttt-sm faults --arm``: ``sim`` or ``emulator`` (a board has no plant to put a fault in)."""
    if text in ("sim", "emulator"):
        return text
    if text.startswith("serial:"):
        raise argparse.ArgumentTypeError(f"{text[:80]!r}: faults go into a simulated plant, which an arm behind a"
                                         " serial link has none of; choose emulator (the C firmware on the twin's"
                                         " plant, behind a pseudo-terminal) or sim")
    raise argparse.ArgumentTypeError(f"expected sim or emulator, got {text[:80]!r}")


def cmd_faults(args: argparse.Namespace) -> int:
    from ..faults.matrix import FAULTS_PRELOAD, fault_matrix
    from ..faults.twin import TWIN_FAULTS
    from ..hardware.firmware import FirmwareError

    if args.link:
        if args.arm is not None:
            raise CliError(f"--arm {args.arm}: the link's faults always run against the firmware emulator in real"
                           " time; drop --arm or --link")
        in_this_process(args, "the link's faults run in real time, one after another in this process (two at once"
                        " would share the processor and change the timing they measure)", drop=" or --link")
        return _link_faults(args)
    arm = args.arm or "sim"
    faults = _choices(args.only, TWIN_FAULTS, "--only") if args.only else list(TWIN_FAULTS)
    phases = [FAULT_PHASES[p] for p in _choices(args.phases, FAULT_PHASES, "--phases")] if args.phases \
        else list(FAULT_PHASES.values())
    params = load_arm(args.params)
    with sweeping(args, FAULTS_PRELOAD, _emit_faults) as runner:
        try:
            report = fault_matrix(params, faults, phases, seed=args.seed, status=status_line(), arm=arm,
                                  runner=runner)
        except (FirmwareError, OSError) as exc:
            raise CliError(f"the firmware emulator cannot run: {exc}") from None
    return _emit_faults(report, args)


def _emit_faults(report: dict[str, Any], args: argparse.Namespace) -> int:
    """Print the fault matrix's `report` (JSON or a table); the exit status it earns: 0 when every cell was
    detected within 100 ms, no limit violated and no record lost."""
    lines = [f"arm: {report['backend']}"] if report["arm"] != "sim" else []
    lines += [f"{'fault':15} {'phase':18} {'detected':>9} {'safe':>8} {'limits':>6} {'zone':>4} {'ink':>7}"
              f" {'record':>6} {'recovered':>9}"]
    for c in report["cells"]:
        detect = f"{c['detect_ms']:.0f} ms" if c["detected"] else "no"
        safe = f"{c['time_to_safe_ms']:.0f} ms" if c["time_to_safe_ms"] is not None else "-"
        lines.append(f"{c['fault']:15} {c['phase']:18} {detect:>9} {safe:>8} {c['limit_violations']:>6}"
                     f" {c['board_zone_entries']:>4} {c['ink_smear_mm']:>4.1f} mm {str(c['record_intact']):>6}"
                     f" {str(c['recovered']):>9}")
    summary = report["summary"]
    lines.append(f"{summary['detected']} of {summary['cells']} detected, {summary['detected_within_100_ms']} within"
                 f" 100 ms; {summary['limit_violations']} limit violations; {summary['records_lost']} records lost;"
                 f" {summary['recovered']} recovered ({report['wall_time_s']:.0f} s)")
    if report["workers"] != 1 or report["runner"] != "local":
        lines.append(f"on {report['workers']} {report['runner']} workers:"
                     f" {report['throughput_per_worker']:g} cells/s per worker")
    lines += [f"error: {e}" for e in report.get("errors", [])]
    if report["interrupted"]:
        lines.append(f"interrupted: {summary['cells']} cells done")
    emit(report, args.json, "\n".join(lines))
    ok = summary["detected_within_100_ms"] == summary["cells"] and not summary["limit_violations"] \
        and not summary["records_lost"]
    return 0 if ok else 1


def _link_faults(args: argparse.Namespace) -> int:
    """``ttt-sm faults --link``: each fault of the serial link against the firmware emulator in real time."""
    from ..faults.link import LINK_FAULTS, link_fault_matrix
    from ..hardware.firmware import FirmwareError

    if args.phases:
        raise CliError("--phases: the link's faults have no phases (the link carries the same frames in each);"
                       " drop --phases or --link")
    faults = _choices(args.only, LINK_FAULTS, "--only") if args.only else list(LINK_FAULTS)
    params = load_arm(args.params)
    # each rejection's log line (hundreds a cell) is counted in the report instead: quiet, and no terminal to slow
    quiet = [logging.getLogger(name) for name in ("ttt_sm.link", "ttt_sm.hardware.emulator")]
    levels = [log.level for log in quiet]
    for log in quiet:
        log.setLevel(logging.ERROR)
    try:
        report = link_fault_matrix(params, faults, seed=args.seed, status=status_line())
    except (FirmwareError, OSError) as exc:
        raise CliError(f"the firmware emulator cannot run: {exc}") from None
    finally:
        clear_status()
        for log, level in zip(quiet, levels, strict=True):
            log.setLevel(level)
    lines = [f"{'fault':20} {'expected':>8} {'rejected fw / pc':>16} {'gaps fw / pc':>12} {'acted on':>8}"
             f" {'fw stop':>8} {'pc lost':>8} {'recovered':>9}"]
    for c in report["cells"]:
        fw_rej, pc_rej = sum(c["rejected_by_firmware"].values()), sum(c["rejected_by_pc"].values())
        stop = f"{c['firmware_stop_ms']:.0f} ms" if c["firmware_stopped"] else "-"
        lost = f"{c['pc_detect_ms']:.0f} ms" if c["pc_declared"] else "-"
        flag = "" if c["as_expected"] else "  NOT AS EXPECTED" + (" (machine held up)" if c["disturbed"] else "")
        gaps = f"{c['lost_frames_firmware']} / {c['lost_frames_pc']}"
        lines.append(f"{c['fault']:20} {c['expected']:>8} {f'{fw_rej} / {pc_rej}':>16} {gaps:>12}"
                     f" {c['bad_frames_acted_on']:>8} {stop:>8} {lost:>8} {str(c['recovered']):>9}{flag}")
    summary = report["summary"]
    lines.append(f"{summary['as_expected']} of {summary['cells']} as expected; {summary['bad_frames_acted_on']} bad"
                 f" frames acted on; {summary['recovered']} recovered ({report['wall_time_s']:.0f} s)")
    emit(report, args.json, "\n".join(lines))
    return 0 if summary["as_expected"] == summary["cells"] and not summary["bad_frames_acted_on"] else 1


def register(sub: Any) -> None:
    """Add init and faults to the subcommands of ``ttt-sm``."""
    sp = add_command(sub, "init", cmd_init, "initialise the drives with the init charts from random power-on poses")
    sp.add_argument("--starts", type=int, default=20,
                    help=f"number of random power-on poses, 1..{MAX_STARTS} (default 20)")
    sp.add_argument("--time-limit", type=float, default=40.0, metavar="SECONDS",
                    help="longest one initialisation may run, simulated seconds (default 40; one takes 6-12)")
    add_runner_options(sp, "initialisations")
    add_arm_option(sp)
    sp = add_command(sub, "faults", cmd_faults,
                     "inject each fault of the arm (twin or emulator) in each phase and measure what the Safety chart"
                     " does")
    sp.add_argument("--only", default=None, metavar="FAULTS",
                    help="comma-separated faults (default all): encoder_frozen,encoder_jump,motor_blocked,"
                         "current_spike,servo_stuck,power_cut,camera_lost")
    sp.add_argument("--phases", default=None, metavar="PHASES",
                    help="comma-separated phases (default all): init,field,symbol,erase")
    sp.add_argument("--arm", type=fault_arm, default=None, metavar="sim|emulator",
                    help="sim (default): each cell on the twin in this process; emulator: on the C firmware on the"
                         " twin's plant (gated), over a pseudo-terminal, as ttt-sm arm serve runs it")
    sp.add_argument("--link", action="store_true",
                    help="the faults of the serial link instead (frames_lost,frames_garbled,frames_duplicated,"
                         "frames_late,frames_out_of_order,link_cut), against the firmware emulator in real time,"
                         " one after another in this process (no --workers, no --dask: they measure timing)")
    add_runner_options(sp, "cells (fault x phase; not the --link faults)")
