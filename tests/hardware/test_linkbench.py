"""``ttt-sm bench``'s link section: what it measures, on a short run (its numbers are the bench's to report)."""

from __future__ import annotations

import pytest

from ttt_sm.hardware.linkbench import bench_link
from ttt_sm.twin.workspace import load_arm

P = load_arm(None)


@pytest.fixture(scope="module")
def result():
    return bench_link(P, seconds=1.5, priority=False)


def test_the_link_section_reports_every_key_the_issue_names(result):
    for key in ("link_late_frames_pct", "link_jitter_ms_p99", "link_bytes_per_s_pc_to_fw", "link_bytes_per_s_fw_to_pc"):
        assert key in result
    assert result["link_chart_steps"] > 0 and result["link_priority_note"] == "not asked"
    assert 0 <= result["link_late_frames_pct"] <= 100 and result["link_jitter_ms_p99"] >= 0


def test_the_bytes_each_way_are_the_frames_of_the_chart_steps(result):
    if result["link_lost"] is not None:  # a loaded machine held the PC up past the firmware's watchdog
        assert "safe_stop" in result["link_lost"] or "no status" in result["link_lost"]
        return
    steps, seconds = result["link_chart_steps"], result["link_seconds"]
    # one SETPOINTS frame (28 bytes on the wire) per chart step the PC ran, a few heartbeats at most
    per_step = result["link_bytes_per_s_pc_to_fw"] * seconds / steps
    assert 27.5 <= per_step <= 31
    # the firmware sends a STATUS (52 bytes) every chart step of its own clock, whether the PC keeps up or not
    assert result["link_bytes_per_s_fw_to_pc"] * seconds >= 52 * steps * 0.95
