"""The cockpit measured in a real browser: frame latency, speed with a page attached, frame size, memory.

``ttt-sm bench --only gui`` serves a session on a loopback port, opens the
Charts page in Debian's Chromium (Playwright, ``executable_path``; the same
flags as the browser tests) and measures:

- ``gui_frame_latency_ms_p95``: from a transition in the simulation (stamped by
  the session's listener when the chart takes it) to the page having set its
  highlight: the page acknowledges each frame with transitions from a
  ``requestAnimationFrame`` callback, and the session takes the time the
  acknowledgement arrives (one clock, the server's; the way back is included),
  at x1 while the drives initialise and the field is drawn;
- ``gui_drift_ms_per_min``: simulated time against wall time at x1 over that run,
  read in the simulation thread between two control steps; ``gui_pace_lost_s``
  the time slips gave up in it (a loop more than 0.25 s behind re-anchors
  instead of racing), ``gui_drift_ms_per_min_less_slips`` the drift without it;
- ``gui_realtime_factor_max``: simulated over wall time, as fast as it goes,
  with the page attached and drawing;
- ``gui_frame_bytes_median``: the frames the page received;
- ``gui_game_realtime_factor``: a whole game (a simulated person, seed
  ``seed``) as fast as it goes, with the Tic-tac-toe page (``/game``) open in
  Chromium and drawing every frame (the arm, the boards, the photos), and
  ``gui_game_headless_realtime_factor``: the same game in a session with no
  page attached (:func:`bench_gui_game`); ``ttt-sm bench`` reports them beside
  the headless ``game_realtime_factor`` of its ``game`` section;
- ``gui_plot_rate_hz``: how often the Operational page (``/operate``) redrew its
  graphs with new points, per wall second, at x1 (``gui_plot_points_per_s``: the
  points each graph got per wall second; the session samples 25 a simulated
  second), and ``gui_plot_latency_ms_p95``: from a sample taken in the
  simulation to the page having drawn it (acknowledged from the
  ``requestAnimationFrame`` callback that drew it; the oldest sample of each
  frame), the Charts page closed;
- with ``soak_min`` (``ttt-sm bench --only gui --gui-soak MIN``): the server's
  resident memory after 1 minute and after ``soak_min`` minutes at x10.

Playwright is a test dependency: without it (or without Chromium) the section
says what to install instead of measuring.
"""

from __future__ import annotations

import os
import shutil
import socket
import statistics
import threading
import time
from typing import Any

from ..debug.debugger import Debugger
from ..params import ArmParams
from .server import create_app
from .session import Session

CHROMIUM = "/usr/bin/chromium"
CHROMIUM_FLAGS = ("--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--disable-background-networking",
                  "--disable-component-update", "--disable-sync", "--disable-quic", "--no-first-run")


def rss_mb() -> float:
    """This process's resident memory, MB (Linux)."""
    with open("/proc/self/statm", encoding="ascii") as f:
        pages = int(f.read().split()[1])
    return pages * os.sysconf("SC_PAGE_SIZE") / 1e6


def _serve(session: Session) -> tuple[Any, threading.Thread, str]:
    import uvicorn

    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.bind(("127.0.0.1", 0))
    port = sock.getsockname()[1]
    app = create_app(session, hosts=[f"127.0.0.1:{port}"])
    server = uvicorn.Server(uvicorn.Config(app, log_level="warning", lifespan="on"))
    thread = threading.Thread(target=server.run, kwargs={"sockets": [sock]}, daemon=True)
    thread.start()
    deadline = time.monotonic() + 60
    while not server.started:
        if time.monotonic() > deadline:
            raise RuntimeError("the cockpit's server did not start")
        time.sleep(0.02)
    return server, thread, f"http://127.0.0.1:{port}"


def bench_gui(params: ArmParams, seed: int = 0, x1_s: float = 60.0, max_s: float = 15.0,
              soak_min: float = 0.0, plot_s: float = 30.0, game: bool = True) -> dict[str, Any]:
    """Measure the cockpit in Chromium (see the module's docstring)."""
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        return {"gui_skipped": "Playwright is not installed: pip install -e '.[test]'"}
    executable = os.environ.get("TTT_SM_CHROMIUM") or (CHROMIUM if os.access(CHROMIUM, os.X_OK)
                                                       else shutil.which("chromium"))
    if not executable:
        return {"gui_skipped": "Chromium is not installed: sh scripts/setup.sh (Debian's chromium)"}
    dbg = Debugger.build(params, seed=seed)
    dbg.run(0.01)  # the numba-compiled loop warmed up, not timed
    session = Session(dbg, speed=1.0, running=False)
    server, thread, url = _serve(session)
    sizes: list[int] = []
    out: dict[str, Any] = {}
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=executable, args=list(CHROMIUM_FLAGS))
            page = browser.new_page(viewport={"width": 1600, "height": 1000})

            def on_frame(payload: str | bytes) -> None:
                text = payload if isinstance(payload, str) else payload.decode("utf-8", "replace")
                if text.startswith('{"type": "frame"'):
                    sizes.append(len(text.encode("utf-8")))

            def on_ws(ws: Any) -> None:
                ws.on("framereceived", on_frame)

            page.on("websocket", on_ws)
            page.goto(url + "/charts")
            page.wait_for_selector("[data-state]", timeout=60_000)
            page.wait_for_function("document.querySelector('[data-role=mode]').textContent === 'paused'")

            # x1: real time while the drives initialise and the Control chart starts drawing.
            # Drift: simulated against wall time, both read in the simulation thread between two
            # control steps of one paced run (the clicks' own delays are not in it).
            def sample(d: Debugger) -> tuple[float, float, float]:
                return d.robot.t, time.perf_counter(), session.clock.stats().lost_s

            page.get_by_role("button", name="Run", exact=True).click()
            page.wait_for_function("document.querySelector('[data-role=mode]').textContent === 'running'")
            t0, wall0, lost0 = session.call(sample)
            time.sleep(x1_s)
            t1, wall1, lost1 = session.call(sample)
            page.get_by_role("button", name="Pause", exact=True).click()
            page.wait_for_function("document.querySelector('[data-role=mode]').textContent === 'paused'")
            stats = session.clock.stats()
            latency = sorted(session.latency_ms())
            run_wall = wall1 - wall0
            out.update({
                "gui_x1_seconds": round(run_wall, 1),
                "gui_frame_latency_ms_p95": round(latency[int(0.95 * (len(latency) - 1))], 1) if latency else None,
                "gui_frame_latency_ms_median": round(statistics.median(latency), 1) if latency else None,
                "gui_frame_latency_samples": len(latency),
                "gui_drift_ms_per_min": round(((t1 - t0) - run_wall) * 1e3 * 60.0 / run_wall, 2),
                # time given up by slips (more than 0.25 s behind): part of the drift above, never hidden
                "gui_pace_lost_s": round(lost1 - lost0, 3),
                # the drift the pacing itself made: the one above with the slips' time given back
                "gui_drift_ms_per_min_less_slips": round(
                    ((t1 - t0) - run_wall + (lost1 - lost0)) * 1e3 * 60.0 / run_wall, 2),
                "gui_pace_lag_max_ms": round(stats.lag_max_s * 1e3, 2),
                "gui_pace_overruns": stats.overruns,
                "gui_pace_slips": stats.slips,
            })

            # as fast as it goes, with the page attached
            session.submit(0, _command("speed", value=None))
            t0 = session.call(lambda d: d.robot.t)
            wall0 = time.perf_counter()
            page.get_by_role("button", name="Run", exact=True).click()
            time.sleep(max_s)
            t1 = session.call(lambda d: d.robot.t)
            wall1 = time.perf_counter()
            out["gui_realtime_factor_max"] = round((t1 - t0) / (wall1 - wall0), 1)
            page.get_by_role("button", name="Pause", exact=True).click()

            out["gui_frame_bytes_median"] = int(statistics.median(sizes)) if sizes else None
            out["gui_frames_received"] = len(sizes)

            page.close()
            out.update(_measure_plots(browser, session, url, plot_s))

            if soak_min > 0:
                page = browser.new_page(viewport={"width": 1600, "height": 1000})
                page.goto(url + "/charts")
                page.wait_for_selector("[data-state]", timeout=60_000)
                session.submit(0, _command("speed", value=10.0))
                page.get_by_role("button", name="Run", exact=True).click()
                time.sleep(60.0)
                out["gui_rss_mb_1min"] = round(rss_mb(), 1)
                time.sleep(max(0.0, soak_min * 60.0 - 60.0))
                out["gui_rss_mb_end"] = round(rss_mb(), 1)
                out["gui_soak_minutes"] = soak_min
                out["gui_soak_sim_s"] = round(session.call(lambda d: d.robot.t), 1)
                page.get_by_role("button", name="Pause", exact=True).click()
            browser.close()
    finally:
        server.should_exit = True
        thread.join(30)
    if game:
        out.update(bench_gui_game(params, seed, executable))
    return out


def _game_over(d: Debugger) -> bool:
    game = d.game
    return game is not None and game.driver is not None and not game.driver.running


def _play_whole_game(session: Session, on_start: Any = None, limit_s: float = 900.0) -> tuple[float, float, str]:
    """Run the session's game as fast as it goes to its end: (simulated s, wall s, outcome)."""
    t0 = session.call(lambda d: d.robot.t)
    wall0 = time.perf_counter()
    session.submit(0, _command("run"))
    if on_start is not None:
        on_start()
    while not session.call(_game_over):
        if time.perf_counter() - wall0 > limit_s:
            raise RuntimeError(f"the game did not end within {limit_s:g} s of wall time")
        time.sleep(0.05)
    wall = time.perf_counter() - wall0
    t1, outcome = session.call(lambda d: (d.robot.t, getattr(d.game, "outcome", None)))
    session.submit(0, _command("pause"))
    return t1 - t0, wall, str(outcome)


def _game_session(params: ArmParams, seed: int) -> Session:
    dbg = Debugger.build(params, seed=seed, game=True, person="simulated")
    dbg.run(0.01)  # the numba-compiled loop warmed up, not timed
    return Session(dbg, speed=None, running=False)


def bench_gui_game(params: ArmParams, seed: int = 0, executable: str | None = None) -> dict[str, Any]:
    """A whole game as fast as it goes, headless and then with the ``/game`` page open in Chromium.

    The same game twice (seed ``seed``, the simulated person, the camera read
    in-process): first in a session no page watches, then in a new session
    with Chromium on the Tic-tac-toe page, receiving and drawing every frame.
    """
    session = _game_session(params, seed)
    session.start()
    try:
        sim, wall, _ = _play_whole_game(session)
    finally:
        session.stop()
    out: dict[str, Any] = {"gui_game_headless_sim_s": round(sim, 1), "gui_game_headless_wall_s": round(wall, 2),
                           "gui_game_headless_realtime_factor": round(sim / wall, 1)}
    from playwright.sync_api import sync_playwright

    session = _game_session(params, seed)
    server, thread, url = _serve(session)
    received = []

    def on_ws(ws: Any) -> None:
        ws.on("framereceived", lambda payload: received.append(len(payload)))

    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=executable, args=list(CHROMIUM_FLAGS))
            page = browser.new_page(viewport={"width": 1400, "height": 1300})
            page.on("websocket", on_ws)
            page.goto(url + "/game")
            page.wait_for_selector('svg[data-role="arm-top"] [data-role="tip"]', timeout=60_000)
            sim, wall, outcome = _play_whole_game(session)
            browser.close()
    finally:
        server.should_exit = True
        thread.join(30)
    out.update({"gui_game_sim_s": round(sim, 1), "gui_game_wall_s": round(wall, 2),
                "gui_game_realtime_factor": round(sim / wall, 1), "gui_game_outcome": outcome,
                "gui_game_messages_received": len(received)})
    return out


def _measure_plots(browser: Any, session: Session, url: str, seconds: float) -> dict[str, Any]:
    """The Operational page's graphs at x1 for ``seconds``: redraws and points per wall second, latency."""
    session.submit(0, _command("speed", value=1.0))
    page = browser.new_page(viewport={"width": 1600, "height": 1000})
    try:
        page.goto(url + "/operate")
        page.wait_for_function("document.querySelector('[data-role=mode]').textContent === 'paused'")
        before = len(session.plot_latency_ms())
        page.get_by_role("button", name="Run_simulation", exact=True).click()
        page.wait_for_function("document.querySelector('[data-role=mode]').textContent === 'running'")
        page.wait_for_function("window.operateStats.points > 0")
        start = page.evaluate("window.operateStats")
        wall0 = time.perf_counter()
        time.sleep(seconds)
        end = page.evaluate("window.operateStats")
        wall = time.perf_counter() - wall0
        session.submit(0, _command("pause"))
        page.wait_for_function("document.querySelector('[data-role=mode]').textContent === 'paused'")
    finally:
        page.close()
    latency = sorted(session.plot_latency_ms()[before:])
    return {
        "gui_plot_seconds": round(wall, 1),
        "gui_plot_rate_hz": round((end["redraws"] - start["redraws"]) / wall, 1),
        "gui_plot_points_per_s": round((end["points"] - start["points"]) / wall, 1),
        "gui_plot_latency_ms_p95": round(latency[int(0.95 * (len(latency) - 1))], 1) if latency else None,
        "gui_plot_latency_ms_median": round(statistics.median(latency), 1) if latency else None,
        "gui_plot_latency_samples": len(latency),
    }


def _command(kind: str, **args: Any) -> Any:
    from .protocol import Command

    return Command(kind, args)
