"""A red transition's suggestion through the cockpit's protocol: ``coverage_suggest`` (no browser, no socket).

The session answers with the shortest scenario the generator of ``ttt-sm
scenario generate`` makes for that transition (searched on the coverage's
worker, not the simulation's thread): YAML that the scenario loader reads and
the runner passes, taking that transition; or, for a transition no path
takes, the generator's reason.  A chart or an index the session does not have
is refused in one line that names it.
"""

from __future__ import annotations

import queue
from collections.abc import Iterator
from typing import Any

import pytest
from starlette.testclient import TestClient
from statemachine import State

from ttt_sm.debug.debugger import Debugger
from ttt_sm.params import load_params
from ttt_sm.runtime import Data, TickChart
from ttt_sm.scenario.loader import load_scenario_text
from ttt_sm.scenario.suite import run_scenarios
from ttt_sm.web.coverage import CoverageRuns
from ttt_sm.web.server import create_app
from ttt_sm.web.session import Session

from .test_protocol import Page

WAIT_S = 300  # the search of the largest chart takes seconds; a busy machine, more


@pytest.fixture(scope="module")
def client() -> Iterator[TestClient]:
    session = Session(Debugger.build(load_params(), seed=0), speed=None, running=False)
    session.start()
    try:
        with TestClient(create_app(session, manage_session=False)) as c:
            yield c
    finally:
        session.stop()


def suggestion(page: Page) -> dict[str, Any]:
    """The next ``coverage_suggestion`` message (frames and the reply in between skipped)."""
    while True:
        m = page.ws.receive_json()
        if m["type"] in ("coverage_suggestion", "error"):
            return m


def test_the_suggested_scenario_loads_passes_and_takes_the_transition(client: TestClient) -> None:
    structure = Debugger.build(load_params(), seed=0).robot.charts["DriveInit2"].structure()
    t = structure.transitions[-1]
    with client.websocket_connect("/ws") as ws:
        page = Page(ws)
        page.join()
        reply = page.answer(page.send(type="coverage_suggest", chart="DriveInit2", transition=t.index))
        assert reply["ok"] and t.label in reply["text"]
        m = suggestion(page)
    assert m["type"] == "coverage_suggestion", m
    assert (m["chart"], m["index"], m["transition"], m["reason"]) == ("DriveInit2", t.index, t.label, None)
    assert m["file"].startswith(f"DriveInit2_{t.index}_") and m["file"].endswith(".yaml")
    scenario = load_scenario_text(m["yaml"], file=m["file"])
    report = run_scenarios([scenario], load_params(), coverage=True)
    assert report.passed, [str(f) for r in report.results for f in r.failures]
    assert report.coverage is not None
    assert t.label in report.coverage.charts[0].taken


def test_a_chart_or_transition_the_session_has_not_is_refused_in_one_line(client: TestClient) -> None:
    with client.websocket_connect("/ws") as ws:
        page = Page(ws)
        page.join()
        bad_chart = page.answer(page.send(type="coverage_suggest", chart="DriveInit9", transition=0))
        bad_index = page.answer(page.send(type="coverage_suggest", chart="DriveInit1", transition=99))
        page.send(type="coverage_suggest", chart="DriveInit1", transition="3")
        not_a_number = page.answer()  # refused before it is queued: an error without the command's id
    assert bad_chart["type"] == "error" and bad_chart["error"].startswith(
        "coverage_suggest: no chart 'DriveInit9' in this session; charts: DriveInit1, ")
    assert bad_index["type"] == "error" and bad_index["error"] == \
        "coverage_suggest: DriveInit1 has no transition 99: its transitions are 0 to 8"
    assert not_a_number["type"] == "error" and "'transition' must be a whole number" in not_a_number["error"]
    for m in (bad_chart, bad_index, not_a_number):
        assert "\n" not in m["error"]


class Stuck(TickChart):
    """A chart with transitions no input can take: a guard never true, and a state it alone enters."""

    inputs = (Data("x", "1", 0, "an input"),)

    idle = State(initial=True)
    busy = State()
    never = State()
    idle.to(busy, cond="x > 3")
    idle.to(never, cond="x > 3 and not (x > 3)")
    never.to(idle)


def test_a_transition_no_path_takes_is_answered_with_the_generators_reason() -> None:
    sent: queue.Queue[tuple[int, dict[str, Any]]] = queue.Queue()
    runs = CoverageRuns(load_params(), {"Stuck": Stuck}, {}, lambda cid, m: sent.put((cid, m)), lambda m: None)
    try:
        index = next(t.index for t in Stuck.structure().transitions if t.source == "never")
        assert "searching Stuck" in runs.suggest(7, "Stuck", index)["text"]
        cid, m = sent.get(timeout=WAIT_S)
        # asked again: the search is kept, the answer the same
        runs.suggest(7, "Stuck", index)
        assert sent.get(timeout=WAIT_S) == (cid, m)
    finally:
        runs.close()
    assert cid == 7 and m["type"] == "coverage_suggestion" and m["yaml"] is None
    assert m["reason"].startswith("its source state never is never active on any explored path")
