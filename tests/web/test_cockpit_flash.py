"""Each transition flashes on the Charts page as it is taken (Stateflow's chart animation), in Chromium.

The session is paused and moved by Next, so which transitions a frame
carries is known from a debugger of this test's own (same seed); the page is
watched through the DOM only: a MutationObserver records every transition
element that gets the ``flash`` class, and the class must be gone again once
its animation has run (no wall-clock time is asserted).
"""

from __future__ import annotations

from typing import Any

from ttt_sm.debug.debugger import Debugger
from ttt_sm.params import load_params

from .conftest import Cockpit
from .test_cockpit_browser import go_to_tick, open_cockpit, show

#: Records, in the page, each transition element the flash class is put on.
WATCH_FLASHES = """() => {
  window.flashed = [];
  const box = document.querySelector('[data-role=diagram]');
  new MutationObserver((changes) => {
    for (const c of changes) {
      if (c.attributeName === 'class' && c.target.classList.contains('flash') && c.target.dataset.transition) {
        window.flashed.push(c.target.dataset.transition);
      }
    }
  }).observe(box, { attributes: true, attributeFilter: ['class'], subtree: true });
}"""


def test_each_transition_taken_flashes_on_the_diagram_then_the_flash_clears(page: Any, cockpit: Cockpit) -> None:
    ref = Debugger.build(load_params(), seed=0)
    open_cockpit(page, cockpit)
    go_to_tick(page, 0)
    show(page, "DriveInit1")
    page.wait_for_function("document.querySelectorAll('[data-role=diagram] .flash').length === 0")
    page.evaluate(WATCH_FLASHES)
    for _ in range(2):  # power_on -> turn_fwd at tick 1, then turn_fwd -> turn_back at the stall
        expected = ref.next(10.0)
        assert expected.kind == "transition"
        taken = {f"{r.chart}.{r.source}->{r.target}" for r in expected.transitions if r.chart == "DriveInit1"}
        assert taken
        page.evaluate("window.flashed = []")
        page.get_by_role("button", name="Next", exact=True).click()
        page.wait_for_function(f"document.querySelector('[data-role=tick]').textContent === "
                               f"'{expected.chart_ticks}'")
        page.wait_for_function("window.flashed.length > 0")
        flashed = page.evaluate("window.flashed")
        # each element that flashed is one of the transitions taken (an element may stand for several)
        assert all(set(name.split()) & taken for name in flashed), (flashed, taken)
        for name in taken:
            assert any(name in f.split() for f in flashed), (name, flashed)
        # no other transition of the chart flashed, and the flash is cleared once its animation has run
        page.wait_for_function("document.querySelectorAll('[data-role=diagram] .flash').length === 0")
        edge = page.locator(f'[data-role="diagram"] [data-transition~="{sorted(taken)[0]}"]').first
        assert "flash" not in (edge.get_attribute("class") or "").split()
        assert int(edge.get_attribute("data-taken-count")) >= 1
