"""The link at the chart rate against the emulator in real time: late frames, jitter, bytes each way.

What ``ttt-sm bench`` reports as its ``link`` section (docs/hardware.md,
"The link at the chart rate").  ``ttt-sm arm serve --pace realtime`` runs
in a process of its own, the firmware stepping on the wall clock at the
control rate as on a board, sending only what a board sends (no
``EMU_TRUTH``).  This process is the PC: a :class:`SerialArm` streams one
``SETPOINTS`` frame per chart step (drive 1 swings on a slow sine, the
others hold), each answering the firmware's last ``STATUS``, as the chart
loop does.

* A ``SETPOINTS`` frame is late when it reaches the firmware more than 2
  control steps (2 ms) after the step it was meant for: the firmware's own
  ``late`` count, read back with a ``HEARTBEAT`` at the end.
* A ``STATUS`` frame is late when it reaches the PC more than 2 ms later
  than the earliest one did, both measured from the firmware step it was
  sent at (``arrival - step * dt``; the earliest of these is the link's
  least delay).
* Jitter: how far each status arrives from one period after the one
  before it (``|interval - steps * dt|``), its 99th percentile.

A loss (the firmware's watchdog stopped the arm because the PC fell silent
for 50 ms, or no status for 50 ms) is counted, and the PC opens the link
again (``HELLO``, gains, ``START``) and goes on until the time is up:
``link_losses`` and the first one's words in ``link_lost``.
"""

from __future__ import annotations

import gc
import json
import math
import os
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from ..params import ArmParams
from ..ptylink import realtime_priority
from ..twin.gains_cache import kept_gains
from .serial_arm import SerialArm

#: A frame is late after this long (issue 13: 2 ms).
LATE_S = 0.002


def _serve(link: Path, seed: int, priority: bool) -> subprocess.Popen[str]:
    proc = subprocess.Popen([sys.executable, "-m", "ttt_sm.cli", "arm", "serve", "--link", str(link), "--pace",
                             "realtime", "--no-truth", "--seed", str(seed), "--json",
                             *(["--realtime-priority"] if priority else [])],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    give_up = time.monotonic() + 120  # the first run compiles the firmware
    while not link.is_symlink():
        if proc.poll() is not None:
            raise RuntimeError(f"ttt-sm arm serve stopped: {proc.communicate()[1].strip()[-500:]}")
        if time.monotonic() > give_up:
            proc.kill()
            raise RuntimeError("ttt-sm arm serve made no link within 120 s")
        time.sleep(0.02)
    return proc


def _stop(proc: subprocess.Popen[str]) -> dict[str, Any]:
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
    try:
        out, _err = proc.communicate(timeout=30)
    except subprocess.TimeoutExpired:
        proc.kill()
        return {}
    try:
        return dict(json.loads(out)["stats"])
    except (ValueError, KeyError):
        return {}


def bench_link(params: ArmParams, seconds: float = 600.0, seed: int = 0,
               progress: Callable[[str], None] | None = None, priority: bool = True) -> dict[str, Any]:
    """Stream setpoints at the chart rate for `seconds` to the emulator in real time; the ``link_*`` keys.

    `priority`: both processes ask for ``SCHED_FIFO`` (:func:`ttt_sm.ptylink.realtime_priority`), as a
    chart loop on a desktop operating system must to keep a 2 ms period; ``link_realtime_priority``
    says whether the PC's side got it, ``link_priority_note`` why not.
    """
    if not (math.isfinite(seconds) and seconds > 0):
        raise ValueError(f"the link bench runs a positive number of seconds, got {seconds}")
    say = progress or (lambda _m: None)
    policy = os.sched_getscheduler(0) if hasattr(os, "sched_getscheduler") else None
    policy_param = os.sched_getparam(0) if policy is not None else None
    note = realtime_priority() if priority else "not asked"
    try:
        return _measure(params, seconds, seed, say, priority, note)
    finally:
        if policy is not None and policy_param is not None and note is None:  # the rest of the bench as before
            os.sched_setscheduler(0, policy, policy_param)


def _measure(params: ArmParams, seconds: float, seed: int, say: Callable[[str], None], priority: bool,
             note: str | None) -> dict[str, Any]:
    dt, divider = params.control.dt, params.control.chart_divider
    gains = kept_gains(params)
    losses: list[str] = []
    sessions: list[list[tuple[int, float]]] = []
    sent = received = pc_rejected = 0
    with tempfile.TemporaryDirectory(prefix="ttt-linkbench-") as folder:
        port = str(Path(folder) / "arm")
        proc = _serve(Path(folder) / "arm", seed, priority)
        try:
            say(f"link bench: {seconds:g} s at the chart rate ({1 / (dt * divider):g} Hz) against the emulator"
                " in real time")
            gc.freeze()  # what is built stays: a collection then walks only what the loop makes
            start = time.monotonic()
            end = start + seconds
            while time.monotonic() < end:  # a session; after a loss, the PC says HELLO again, as it would
                arm = SerialArm(port, params, gains)
                arrivals: list[tuple[int, float]] = []
                sessions.append(arrivals)
                try:
                    q0, servo = arm.encoder_angles(), arm.servo_setpoint
                    bytes0 = (arm.bytes_sent, arm.bytes_received)
                    while time.monotonic() < end:
                        t = arm.t
                        arm.set_setpoints([q0[0] + 0.2 * math.sin(2 * math.pi * 0.25 * t), q0[1], q0[2], servo])
                        arm.step(divider)
                        if not arm.link_ok:
                            losses.append(f"{arm.link_fault} after {time.monotonic() - start:.1f} s")
                            break
                        arrivals.append((arm.status_step, arm.status_at))
                    sent += arm.bytes_sent - bytes0[0]
                    received += arm.bytes_received - bytes0[1]
                    pc_rejected += arm.rx.rejected
                finally:
                    arm.close()
            wall = time.monotonic() - start
        finally:
            served = _stop(proc)
    arrivals = [a for session in sessions for a in session]
    steps = np.array([s for s, _ in arrivals], dtype=float)
    times = np.array([t for _, t in arrivals])
    delay = times - steps * dt
    late_status = int((delay - delay.min() > LATE_S).sum()) if len(delay) else 0
    within = [np.array(session) for session in sessions if len(session) > 1]
    intervals = np.concatenate([np.diff(a[:, 1]) - np.diff(a[:, 0]) * dt for a in within]) if within else np.zeros(0)
    jitter = np.abs(intervals) * 1e3
    skipped = int(sum((np.diff(a[:, 0]) > divider).sum() for a in within))
    late_setpoints = served.get("rejections", {}).get("late", 0)
    setpoints = len(arrivals)
    frames = setpoints + len(arrivals)
    return {
        "link_seconds": round(wall, 1),
        "link_chart_steps": setpoints,
        "link_late_frames_pct": round(100.0 * (late_setpoints + late_status) / max(frames, 1), 4),
        "link_late_setpoints": int(late_setpoints),
        "link_late_statuses": late_status,
        "link_jitter_ms_p99": round(float(np.percentile(jitter, 99)), 4) if len(jitter) else None,
        "link_jitter_ms_p50": round(float(np.percentile(jitter, 50)), 4) if len(jitter) else None,
        "link_jitter_ms_max": round(float(jitter.max()), 3) if len(jitter) else None,
        "link_skipped_chart_steps": skipped,
        "link_bytes_per_s_pc_to_fw": round(sent / wall, 1) if wall > 0 else None,
        "link_bytes_per_s_fw_to_pc": round(received / wall, 1) if wall > 0 else None,
        "link_rejected_pc": int(pc_rejected),
        "link_rejected_fw": int(sum(served.get("rejections", {}).values())) if served else None,
        "link_losses": len(losses),
        "link_lost": losses[0] if losses else None,
        "link_load_average": [round(v, 2) for v in os.getloadavg()],
        "link_realtime_priority": note is None,
        "link_priority_note": note,
    }


__all__ = ["bench_link", "LATE_S"]
