"""Test configuration: scenario files in tests/scenarios/ are collected as tests.

``params`` (the parameter file in force) and ``gains`` (the cascade designed
from it) are shared by every test that asks for them: both are immutable.

``pytester`` runs pytest on made-up scenario folders (tests/scenario_runner).
``browser_fixtures`` gives the browser tests Debian's Chromium through Playwright
(``browser``, ``page``, ``js_file``).

Ctrl-C is answered as in a terminal even when the suite runs as a background job
(``make test &`` or ``nohup``: the shell starts it with SIGINT ignored, and every
process it starts inherits that): the tests stop ``ttt-sm arm serve`` and others
with SIGINT, and a process that ignores it would never stop.
"""

import signal
import sys
from pathlib import Path

import pytest

from ttt_sm.params import ArmParams, load_params
from ttt_sm.twin.gains import Gains
from ttt_sm.twin.tuning import design_gains

# The repository's development tools (tools/: the layering checker, docs/architecture.md's generator)
# are not installed with the package: the tests import them from the checkout.
_ROOT = str(Path(__file__).resolve().parents[1])
if _ROOT not in sys.path:
    sys.path.insert(0, _ROOT)

if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

pytest_plugins = ["ttt_sm.scenario.pytest_plugin", "pytester", "browser_fixtures"]


@pytest.fixture(scope="session")
def params() -> ArmParams:
    """The parameters in force (frozen dataclasses)."""
    return load_params()


@pytest.fixture(scope="session")
def gains(params: ArmParams) -> Gains:
    """The cascade's gains designed from ``params`` (design_gains is a pure, memoised function)."""
    return design_gains(params)
