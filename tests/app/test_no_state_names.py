"""The application observes charts only through their declared outputs, never their state names.

A renamed state must fail where it is declared (the chart, its scenarios,
its diagrams), not after a 600 s simulated timeout somewhere in `ttt_sm.app`.
So no module of `src/ttt_sm/app` may hold a string that is a state's name
(unless it is also a declared datum's, as Control's output `erasing` is
beside the Game chart's state), nor test membership in a chart's
configuration.
"""

from __future__ import annotations

import ast
from pathlib import Path

import ttt_sm.app
from ttt_sm.charts import ALL_CHARTS

APP = Path(ttt_sm.app.__file__).parent
DATA_NAMES = {d.name for chart in ALL_CHARTS for d in chart.declarations()}
STATE_NAMES = {s.id for chart in ALL_CHARTS for s in chart.structure().states} - DATA_NAMES
CONFIGURATION = {"active_ids", "configuration_values", "configuration", "active"}


def _reads_configuration(node: ast.expr) -> bool:
    """`x.active_ids`, `x.configuration_values`, `robot.active("Control")` and the like."""
    if isinstance(node, ast.Call):
        node = node.func
    return isinstance(node, ast.Attribute) and node.attr in CONFIGURATION


def offences(source: str, name: str) -> list[str]:
    found = []
    for node in ast.walk(ast.parse(source, name)):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value in STATE_NAMES:
            found.append(f"{name}:{node.lineno}: state name {node.value!r}")
        if isinstance(node, ast.Compare) and any(isinstance(op, (ast.In, ast.NotIn)) for op in node.ops):
            if any(_reads_configuration(c) for c in node.comparators):
                found.append(f"{name}:{node.lineno}: tests a chart's configuration")
    return found


def test_the_scan_finds_what_it_looks_for():
    assert STATE_NAMES >= {"wait_1", "Erase", "go_wait", "pass_pos", "failed", "off", "turn_pen"}
    bad = 'waiting = "wait_1" in c.active_ids\nif x not in robot.active("Game"): pass\n'
    assert sorted(offences(bad, "bad.py")) == ["bad.py:1: state name 'wait_1'",
                                               "bad.py:1: tests a chart's configuration",
                                               "bad.py:2: tests a chart's configuration"]


def test_no_module_of_the_application_reads_a_state_name():
    modules = sorted(APP.glob("*.py"))
    assert len(modules) > 5
    found = [o for path in modules for o in offences(path.read_text(encoding="utf-8"), path.name)]
    assert found == []
