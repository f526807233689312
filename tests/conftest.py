"""Test configuration: scenario files in tests/scenarios/ are collected as tests.

``pytester`` runs pytest on made-up scenario folders (tests/scenario_runner).
``browser_fixtures`` gives the browser tests Debian's Chromium through Playwright
(``browser``, ``page``, ``js_file``).
"""

pytest_plugins = ["ttt_sm.scenario.pytest_plugin", "pytester", "browser_fixtures"]
