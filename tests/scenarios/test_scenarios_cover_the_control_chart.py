"""Together, the scenario files of this folder enter every state and take every transition
of the Control chart (thesis section 3.6.1, figs. 3.24-3.27): the field, X, O, the sine
wave, erasing, finishing from every sub-chart, and the ignored button of each busy one."""

from __future__ import annotations

from ttt_sm.charts import Control
from ttt_sm.scenario import RunReport


def test_scenarios_cover_every_state_and_transition_of_the_control_chart(scenario_report: RunReport) -> None:
    report = scenario_report  # the folder's scenarios, run once per session (conftest.py)
    assert report.passed, [str(f) for r in report.results for f in r.failures]
    assert report.coverage is not None
    (c,) = [c for c in report.coverage.charts if c.chart == "Control"]
    assert c.missing_states == () and c.missing_transitions == (), report.coverage.to_text()
    structure = Control.structure()
    assert set(c.entered) == {s.id for s in structure.states if not s.history}
    assert set(c.taken) == {t.label for t in structure.transitions}
    # among them, a button ignored by every sub-chart and by each state of start_stop
    # (their `on button` actions: nothing left or entered)
    ignored = {t.label for t in structure.transitions if t.target is None}
    assert len(ignored) == 11 and ignored <= set(c.taken)
    # and finish from every sub-chart that moves the arm
    to_finishing = {t.label for t in structure.transitions if t.target == "finishing"}
    assert len(to_finishing) == 6 and to_finishing <= set(c.taken)
