"""Together, the scenario files of this folder enter every state and take every transition
of the AlgorithmActivator (thesis fig. 3.30) and of the Game chart (the Tic-tac-toe GUI's
game flow, section 3.7).  These charts are not part of the robot: their scenarios run them
bare (``chart: Game``)."""

from __future__ import annotations

from ttt_sm.charts import AlgorithmActivator, Game
from ttt_sm.scenario import RunReport


def test_scenarios_cover_every_state_and_transition_of_the_game_charts(scenario_report: RunReport) -> None:
    report = scenario_report  # the folder's scenarios, run once per session (conftest.py)
    assert report.passed, [str(f) for r in report.results for f in r.failures]
    assert report.coverage is not None
    charts = {c.chart: c for c in report.coverage.charts}
    for cls in (AlgorithmActivator, Game):
        c = charts[cls.__name__]
        assert c.missing_states == () and c.missing_transitions == (), report.coverage.to_text()
        structure = cls.structure()
        assert set(c.entered) == {s.id for s in structure.states if not s.history}
        assert set(c.taken) == {t.label for t in structure.transitions}
    # a click ignored both while the pulse lasts and after it (targetless: nothing left or entered)
    ignored = {t.label for t in AlgorithmActivator.structure().transitions if t.target is None}
    assert ignored == {"enabled -> (none): trigger", "spent -> (none): trigger"}
    # and stop from every phase before turning_off
    stops = {t.source for t in Game.structure().transitions if t.trigger == "stop"}
    assert stops == {"compiling", "initialising", "playing", "game_over", "erasing"}
