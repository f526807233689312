"""Slider move -> the /kinematics workspace redrawn, measured in Chromium; screenshots of the page.

``python tools/bench_kinematics_page.py [--moves 40] [--shots DIR]``: serves a paused
cockpit on 127.0.0.1, opens ``/kinematics`` at 1280x720 in headless Chromium, moves
the L2 and q3-limit sliders ``--moves`` times (each move waits for its redraw) and prints
one JSON line: the redraw times (input event -> both views drawn, ms) p50, p95, max.
``--shots DIR`` also writes kinematics_1280x720.png and kinematics_1920x1080.png (the whole
page) and kinematics_race_corner.png (the race at the board's far corner) there.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from browser_fixtures import CHROMIUM_FLAGS, DEFAULT_CHROMIUM  # noqa: E402
from ttt_sm.debug.debugger import Debugger  # noqa: E402
from ttt_sm.params import load_params  # noqa: E402
from ttt_sm.web.session import Session  # noqa: E402
from web.conftest import served  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--moves", type=int, default=40)
    ap.add_argument("--shots", type=Path, default=None)
    args = ap.parse_args()
    from playwright.sync_api import sync_playwright

    session = Session(Debugger.build(load_params(), seed=0), speed=None, running=False)
    with served(session) as cockpit, sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=DEFAULT_CHROMIUM, args=list(CHROMIUM_FLAGS))
        page = browser.new_page(viewport={"width": 1280, "height": 720})
        page.goto(cockpit.page_url("/kinematics"))
        page.wait_for_function("document.body.dataset.ready === 'true'", timeout=60_000)
        base = page.evaluate("window.kinematics.redraws.length")
        for i in range(args.moves):
            role, value = ("L2", f"{0.18 + 0.002 * (i % 20):.3f}") if i % 2 == 0 else ("q3max", str(10 + 3 * (i % 30)))
            n = page.evaluate("window.kinematics.redraws.length")
            page.eval_on_selector(f"[data-role={role}]",
                                  "(el, v) => { el.value = v; el.dispatchEvent(new Event('input')); }", value)
            page.wait_for_function(f"window.kinematics.redraws.length > {n} && window.kinematics.idle()",
                                   timeout=30_000)
        times = np.array(page.evaluate(f"window.kinematics.redraws.slice({base})"))
        result = {"moves": len(times), "redraw_ms_p50": round(float(np.percentile(times, 50)), 1),
                  "redraw_ms_p95": round(float(np.percentile(times, 95)), 1),
                  "redraw_ms_max": round(float(times.max()), 1), "viewport": "1280x720"}
        if args.shots:
            args.shots.mkdir(parents=True, exist_ok=True)
            page.click("[data-role=ws-reset]")
            page.wait_for_timeout(500)
            page.screenshot(path=str(args.shots / "kinematics_1280x720.png"), full_page=True)
            page.set_viewport_size({"width": 1920, "height": 1080})
            page.wait_for_timeout(300)
            page.screenshot(path=str(args.shots / "kinematics_1920x1080.png"), full_page=True)
            page.click("[data-role=race-corner]")
            page.wait_for_function("window.kinematics.race && window.kinematics.race.target[0] > 0.1")
            page.locator("#race").screenshot(path=str(args.shots / "kinematics_race_corner.png"))
        browser.close()
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
