"""The scenario files of this folder, run once per test session with their joint coverage.

The coverage tests of the init charts and of the Control chart share one run:
the Control scenarios simulate several minutes of robot time each time they run.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from ttt_sm.params import load_params
from ttt_sm.scenario import RunReport, load_scenario, run_scenarios, scenario_files

HERE = Path(__file__).parent


@pytest.fixture(scope="session")
def scenario_report() -> RunReport:
    """Every scenario file of tests/scenarios, run one after another, with coverage."""
    scenarios = [load_scenario(p) for p in scenario_files([HERE])]
    return run_scenarios(scenarios, load_params(None), coverage=True)
