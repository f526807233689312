"""pytest plugin: scenario files are tests.

Register it in a ``conftest.py``::

    pytest_plugins = ["ttt_sm.scenario.pytest_plugin"]

Every ``*.yaml`` / ``*.yml`` file in a folder named ``scenarios`` becomes one
test item named after the file.  A failing scenario shows each failure as
``FILE:LINE: message`` (no Python traceback: the scenario file is the test);
a file that does not follow the format fails the same way, at its line.

``pytest --scenario-coverage`` prints, at the end, the states entered and the
transitions taken by the scenarios that ran, and those missing.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from ..runtime.listeners import Coverage
from .errors import ScenarioError
from .loader import load_scenario
from .runner import ScenarioResult, run_scenario

SCENARIO_DIR = "scenarios"
_COVERAGE = pytest.StashKey[Coverage]()
_PARAMS = pytest.StashKey[Any]()


class ScenarioFailed(Exception):
    """A scenario ran and something did not happen as written."""

    def __init__(self, result: ScenarioResult) -> None:
        self.result = result
        super().__init__("\n".join(str(f) for f in result.failures))


def pytest_addoption(parser: pytest.Parser) -> None:
    group = parser.getgroup("ttt_sm scenarios")
    group.addoption("--scenario-coverage", action="store_true", default=False,
                    help="report the chart states and transitions the scenario files covered")


def pytest_configure(config: pytest.Config) -> None:
    config.stash[_COVERAGE] = Coverage()


def pytest_collect_file(file_path: Path, parent: pytest.Collector) -> pytest.Collector | None:
    if file_path.suffix in (".yaml", ".yml") and file_path.parent.name == SCENARIO_DIR:
        return ScenarioFile.from_parent(parent, path=file_path)
    return None


class ScenarioFile(pytest.File):
    """A scenario file: one item (loaded when it runs, so a format error is that test's failure)."""

    def collect(self) -> Iterator[pytest.Item]:
        yield ScenarioItem.from_parent(self, name=self.path.stem)


def _shown(path: Path) -> Path:
    """The path relative to the working folder when it is under it: short, and an editor finds it."""
    try:
        return path.relative_to(Path.cwd())
    except ValueError:
        return path


class ScenarioItem(pytest.Item):
    """One scenario run on a new simulated robot."""

    def _params(self) -> Any:
        stash = self.config.stash
        if _PARAMS not in stash:
            from ..params import load_params

            stash[_PARAMS] = load_params(None)
        return stash[_PARAMS]

    def runtest(self) -> None:
        scenario = load_scenario(_shown(self.path))
        result = run_scenario(scenario, self._params(), coverage=self.config.stash[_COVERAGE])
        self.user_properties.append(("sim_time_s", round(result.sim_time_s, 3)))
        if not result.passed:
            raise ScenarioFailed(result)

    def repr_failure(self, excinfo: pytest.ExceptionInfo[BaseException],
                     style: Any = None) -> str:
        exc = excinfo.value
        if isinstance(exc, ScenarioFailed):
            r = exc.result
            head = f"scenario {r.name!r} failed ({r.steps_run} of {r.steps_total} steps run," \
                   f" t = {r.sim_time_s:.3f} s):"
            return "\n".join([head, *(f"  {f}" for f in r.failures)])
        if isinstance(exc, ScenarioError):
            return "scenario file is not valid:\n" + "\n".join(f"  {e}" for e in exc.errors)
        return str(super().repr_failure(excinfo))

    def reportinfo(self) -> tuple[Path, int, str]:
        return self.path, 0, f"scenario {self.name}"


def pytest_terminal_summary(terminalreporter: Any, config: pytest.Config) -> None:
    if not config.getoption("scenario_coverage", default=False):
        return
    report = config.stash[_COVERAGE].report()
    terminalreporter.section("scenario coverage")
    terminalreporter.write(report.to_text() if report.charts else "no scenario ran\n")
