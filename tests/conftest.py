"""Test configuration: scenario files in tests/scenarios/ are collected as tests."""

pytest_plugins = ["ttt_sm.scenario.pytest_plugin"]
