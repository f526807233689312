"""Together, the scenario files of this folder enter every state and take every transition
of the Safety chart (docs/safety.md): each way into the safe state (the pen servo's too), the lift and its
time-out, a fault while lifting, holding or re-initialising, and reset."""

from __future__ import annotations

from ttt_sm.charts import Safety
from ttt_sm.scenario import RunReport


def test_scenarios_cover_every_state_and_transition_of_the_safety_chart(scenario_report: RunReport) -> None:
    report = scenario_report  # the folder's scenarios, run once per session (conftest.py)
    assert report.passed, [str(f) for r in report.results for f in r.failures]
    assert report.coverage is not None
    (c,) = [c for c in report.coverage.charts if c.chart == "Safety"]
    assert c.missing_states == () and c.missing_transitions == (), report.coverage.to_text()
    structure = Safety.structure()
    assert set(c.entered) == {s.id for s in structure.states if not s.history}
    assert set(c.taken) == {t.label for t in structure.transitions}
    # every way into the safe state: from monitoring (5: a drive or the link, the camera or the pen servo
    # each lifting or holding), lifting (2), holding and re-initialising
    into_safe = {t.label for t in structure.transitions if t.target in ("lift", "hold", "stopped")}
    assert len(into_safe) == 10 and into_safe <= set(c.taken)
