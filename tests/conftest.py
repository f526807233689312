"""Test configuration: scenario files in tests/scenarios/ are collected as tests.

``pytester`` runs pytest on made-up scenario folders (tests/scenario_runner).
"""

pytest_plugins = ["ttt_sm.scenario.pytest_plugin", "pytester"]
