"""Save -> what the /lab page shows, measured: ``python tools/bench_lab_reload.py [--saves 20]``.

A live ``gui --lab`` cockpit (paused, so the machine's time goes to the
reloads) on a fresh DriveInit3 folder with the tutorial's solution; Chromium
on its /lab page.  The file is saved over and over, alternately with a syntax
error (timed until the page shows the error's file:line) and fixed with a
renamed state (timed until the page shows the diagram drawn anew with it).
Prints p50 / p95 of each, in ms, as JSON.  Tests never assert on wall-clock
time; this is what the notes on issue 23 report.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from browser_fixtures import CHROMIUM_FLAGS, DEFAULT_CHROMIUM  # noqa: E402
from ttt_sm.debug.debugger import Debugger  # noqa: E402
from ttt_sm.params import load_params  # noqa: E402
from ttt_sm.web.lab_watch import LabTask, LabWatch  # noqa: E402
from ttt_sm.web.session import Session  # noqa: E402
from web.conftest import served  # noqa: E402
from web.lab_files import broken, broken_line, lab_folder, reference_solution, save  # noqa: E402


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--saves", type=int, default=20, help="saves of each kind (default 20)")
    args = parser.parse_args()
    from playwright.sync_api import sync_playwright

    with tempfile.TemporaryDirectory() as tmp, sync_playwright() as pw:
        folder = Path(tmp) / "my_init3"
        ex = lab_folder(folder)
        argv = (sys.executable, "-m", "ttt_sm.lab.live", str(folder), "--nice", "10")
        watch = LabWatch(LabTask(ex.title, ex.slot, ex.chart_file, ex.class_name, argv))
        session = Session(Debugger.build(load_params(), seed=0, slots=watch.first_slots()), speed=None,
                          running=False)
        browser = pw.chromium.launch(executable_path=DEFAULT_CHROMIUM, args=list(CHROMIUM_FLAGS))
        page = browser.new_page()
        error_ms: list[float] = []
        redraw_ms: list[float] = []
        with served(session, lab=watch) as cockpit:
            page.goto(cockpit.page_url("/lab"))
            page.wait_for_selector('[data-role=diagram] [data-state="DriveInit3.approach"]', timeout=120_000)
            where = f"{ex.chart_file}:{broken_line()}: syntax error"
            for k in range(args.saves):
                t0 = time.perf_counter()
                save(ex.chart_file, broken())
                page.wait_for_function("(w) => document.querySelector('[data-role=error]').textContent"
                                       ".startsWith(w)", arg=where, timeout=120_000, polling="raf")
                error_ms.append((time.perf_counter() - t0) * 1e3)
                name = f"seek_{k}"
                t0 = time.perf_counter()
                save(ex.chart_file, reference_solution().replace("approach", name))
                page.wait_for_selector(f'[data-role=diagram] [data-state="DriveInit3.{name}"]', timeout=120_000)
                redraw_ms.append((time.perf_counter() - t0) * 1e3)
        browser.close()
    report = {"saves": args.saves}
    for key, xs in (("save_to_error_in_page_ms", error_ms), ("save_to_redrawn_diagram_ms", redraw_ms)):
        report[key + "_p50"] = round(float(np.percentile(xs, 50)), 1)
        report[key + "_p95"] = round(float(np.percentile(xs, 95)), 1)
    print(json.dumps(report, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
