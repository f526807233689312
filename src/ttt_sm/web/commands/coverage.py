"""Coverage on the chart cockpit's diagrams (:mod:`..coverage`): scenarios run, a report loaded, cleared;
a scenario suggested for a transition never taken."""

from __future__ import annotations

from typing import Any

from ..coverage import colouring, load_scenarios, run_for_coverage, scenario_from_text
from ..fields import MAX_SCENARIO_BYTES, identifier, integer, names_list, report, text
from .spec import Cockpit, Reply, command


@command("coverage_run", files=names_list(200))
def run(session: Cockpit, cid: int, files: list[str]) -> Reply:
    """Run the session's scenario files ``files`` (names) and colour what they covered."""
    cov = session.coverage
    scenarios = load_scenarios(files, cov.scenarios)
    return cov.start(cid, "coverage_run", lambda check: run_for_coverage(scenarios, cov.params, cov.charts,
                                                                          check=check))


@command("coverage_scenario", name=text(200), text=text(MAX_SCENARIO_BYTES))
def run_text(session: Cockpit, cid: int, name: str, text: str) -> Reply:
    """Run a scenario file's ``text`` (sent from the page, file ``name``) and colour what it covered."""
    cov = session.coverage
    scenario = scenario_from_text(name, text)
    return cov.start(cid, "coverage_scenario", lambda check: run_for_coverage([scenario], cov.params, cov.charts,
                                                                               check=check))


@command("coverage_load", report=report)
def load(session: Cockpit, cid: int, report: dict[str, Any]) -> Reply:
    """Colour a ``report``: the JSON of ``ttt-sm scenario run --coverage --json``."""
    cov = session.coverage
    cov.show({**colouring(report, cov.charts), "source": "report"})
    return {"text": "coverage report loaded"}


@command("coverage_clear")
def clear(session: Cockpit, cid: int) -> Reply:
    """Colour no coverage."""
    session.coverage.clear()
    return {"text": "coverage cleared"}


@command("coverage_suggest", chart=identifier, transition=integer(0, 10_000))
def suggest(session: Cockpit, cid: int, chart: str, transition: int) -> Reply:
    """The shortest generated scenario that takes transition ``transition`` (its index) of ``chart``, sent to
    the page as a ``coverage_suggestion`` message when the search (on the coverage's worker) is done."""
    return session.coverage.suggest(cid, chart, transition)
