"""Scenario tests of event sequences: YAML files that drive the robot and check its charts.

A scenario file says, step by step, what happens to the robot (inputs set or
forced, events posted, time passing) and what the charts must do (states
entered in order, conditions on chart data and signals).  It is a test and a
piece of documentation: ``tests/scenarios/drive_1_turns_back_at_a_hard_stop.yaml``.

- :mod:`.source`: YAML with line numbers (a ``SafeLoader`` subclass);
- :mod:`ttt_sm.runtime.conditions`: the condition language (parsed, never ``eval``-ed),
  shared with the debugger's ``break when``;
- :mod:`.model`, :mod:`.loader`: the steps, checked against the charts;
- :mod:`.runner`: runs a scenario on the simulated robot; :mod:`.suite`: several, with coverage;
- :mod:`.pytest_plugin`: YAML files as tests; ``ttt-sm scenario run`` is :mod:`ttt_sm.cli.scenario`.

See ``docs/scenarios.md``.
"""

from ..runtime.conditions import ExprError, Expression, Ref, parse
from .errors import ScenarioError, ScenarioErrors
from .loader import load_scenario, load_scenario_text, scenario_files
from .model import SIGNALS, Catalog, Scenario
from .runner import Failure, ScenarioResult, run_scenario
from .suite import RunReport, coverage_dict, run_scenarios

__all__ = [
    "SIGNALS",
    "Catalog",
    "ExprError",
    "Expression",
    "Failure",
    "Ref",
    "RunReport",
    "Scenario",
    "ScenarioError",
    "ScenarioErrors",
    "ScenarioResult",
    "coverage_dict",
    "load_scenario",
    "load_scenario_text",
    "parse",
    "run_scenario",
    "run_scenarios",
    "scenario_files",
]
