"""Together, the scenario files of this folder enter every state and take every transition
of the three drive-initialisation charts (thesis section 3.1.2)."""

from __future__ import annotations

from ttt_sm.scenario import RunReport

INIT_CHARTS = ("DriveInit1", "DriveInit2", "DriveInit3")


def test_scenarios_cover_every_state_and_transition_of_the_init_charts(scenario_report: RunReport) -> None:
    report = scenario_report  # the folder's scenarios, run once per session (conftest.py)
    assert report.passed, [str(f) for r in report.results for f in r.failures]
    assert report.coverage is not None
    charts = {c.chart: c for c in report.coverage.charts}
    for name in INIT_CHARTS:
        c = charts[name]
        assert c.missing_states == () and c.missing_transitions == (), report.coverage.to_text()
        assert c.entered and c.taken
