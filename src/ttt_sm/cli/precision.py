"""``ttt-sm precision``: the thesis' precision experiments (section 3.5) on the twin.

``ttt-sm precision staircase --axis z|x|y --steps small|big [--tuning ours|thesis]``
runs the staircase of figs. 3.14-3.18 (:mod:`ttt_sm.app.precision`): it
prints the static and dynamic error of each stair for the three
comparisons (desired vs FK of the encoders, FK vs the triangulation sensor,
desired vs sensor) and a short reading, and writes the figure (PNG) and the
samples (JSON, a sensor reading out of range is ``null``) into ``--out``.
"""

from __future__ import annotations

import argparse
from typing import Any

from ..files import write_atomic
from ..runtime.jsonable import dumps
from .common import CliError, add_command, emit, out_dir, progress, whole_number


def _number(text: str) -> float:
    """A finite number (the hold of a stair, s): checked for its range by the experiment."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text[:40]!r}") from None
    if not value == value or value in (float("inf"), float("-inf")):
        raise argparse.ArgumentTypeError(f"expected a finite number of seconds, got {text[:40]}")
    return value


def cmd_staircase(args: argparse.Namespace) -> int:
    from ..app.precision import PrecisionError, StaircaseSpec, run_staircase
    from ..app.precision_plot import save_staircase_plot
    from ..twin.workspace import load_arm

    try:
        StaircaseSpec.of(args.axis, args.steps, args.count, args.hold)  # refused before anything runs
    except PrecisionError as exc:
        option = "--hold" if str(exc).startswith("hold") else "--count"
        raise CliError(f"{option}: {exc}") from None
    out = out_dir(args.out)
    params = load_arm(args.params)
    tuning = args.tuning or params.tuning.preset
    say = progress(True)
    say(f"ttt-sm precision: staircase along {args.axis.upper()}, {args.steps} steps, tuning {tuning!r}"
        " (initialising the drives first)")
    try:
        r = run_staircase(params, args.axis, args.steps, tuning, seed=args.seed, count=args.count,
                          hold_s=args.hold)
    except PrecisionError as exc:
        raise CliError(str(exc)) from exc
    name = f"staircase_{args.axis}_{args.steps}_{tuning}"
    png = save_staircase_plot(r, out / f"{name}.png")
    samples = out / f"{name}.json"
    sensor = [None if v != v else round(float(v), 7) for v in r.series["sensor"]]
    write_atomic(samples, dumps({
        "t_s": [round(float(v), 4) for v in r.t], "desired_m": [round(float(v), 7) for v in r.series["desired"]],
        "fk_m": [round(float(v), 7) for v in r.series["fk"]], "sensor_m": sensor,
        "axis": r.axis, "stair_times_s": [round(v, 4) for v in r.stair_times]}) + "\n")
    report: dict[str, Any] = {**r.report(), "plot": str(png), "samples_file": str(samples)}
    emit(report, args.json, _text(report))
    return 0


def _text(rep: dict[str, Any]) -> str:
    fig = f" (thesis fig. {rep['thesis_figure']})" if rep["thesis_figure"] else ""

    def mm(v: float | None) -> str:
        return "null" if v is None else f"{v:.4f}"

    names = {"desired_vs_fk": "desired - FK", "fk_vs_sensor": "FK - sensor", "desired_vs_sensor": "desired - sensor",
             "lengths": "of it: lengths", "clearance": "of it: clearance"}
    lines = [f"staircase along {rep['axis'].upper()}, {rep['stairs']} {rep['steps']} stairs of {rep['step_mm']:g} mm,"
             f" tuning {rep['tuning']!r}{fig}", "",
             f"{'':>5} " + " ".join(f"{names.get(n, n):>19}" for n in rep["errors"]),
             f"{'stair':>5} " + " ".join(f"{'static':>9} {'dynamic':>9}" for _ in rep["errors"])]
    for k in range(rep["stairs"]):
        cells = [f"{mm(v[k]['static_mm']):>9} {mm(v[k]['dynamic_mm']):>9}" for v in rep["errors"].values()]
        lines.append(f"{k + 1:>5} " + " ".join(cells))
    lines += ["", f"clearance bound (FK vs sensor): {rep['clearance_bound_mm']:.4f} mm;"
              f" sensor readings out of range: {rep['sensor_out_of_range']} of {rep['samples']}",
              "mm; static: mean error over the last 0.3 s of a stair; dynamic: mean |error| over the first 0.5 s"
              " after it; FK - sensor = lengths (FK with the measured lengths - with the true ones) + clearance",
              "", "reading:", *(f"  {line}" for line in rep["reading"]), "",
              f"figure: {rep['plot']}", f"samples: {rep['samples_file']}"]
    return "\n".join(lines)


def register(sub: Any) -> None:
    """Add ``ttt-sm precision`` and its experiments to the subcommands of ``ttt-sm``."""
    p = sub.add_parser("precision", help="the thesis' precision experiments (section 3.5) on the twin",
                       description="the thesis' precision experiments (section 3.5) on the twin")
    experiments = p.add_subparsers(dest="experiment", required=True)
    sp = add_command(experiments, "staircase", cmd_staircase,
                     "a staircase of setpoints along one axis, measured by the encoders' forward kinematics and a"
                     " triangulation sensor (thesis figs. 3.14-3.18)")
    sp.add_argument("--axis", choices=["z", "x", "y"], default="z", help="the global axis (default z)")
    sp.add_argument("--steps", choices=["small", "big"], default="small",
                    help="small (0.5 mm) or big (10 mm) stairs (default small)")
    sp.add_argument("--tuning", choices=["ours", "thesis"], default=None,
                    help="the cascades' gains (default: the parameter file's [tuning] preset; docs/tuning.md)")
    sp.add_argument("--count", type=whole_number, default=5, help="stairs after the start, 1..20 (default 5)")
    sp.add_argument("--hold", type=_number, default=1.5, metavar="SECONDS",
                    help="how long each stair is held, 0.6..10 s (default 1.5)")
    sp.add_argument("--out", default="out/precision", help="folder for the figure and the samples")
