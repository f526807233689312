"""The cockpit's diagrams read at a laptop's size (1280x720) in a real browser (Chromium via Playwright).

Every label of every picture of every chart (overview, each sub-chart on its own,
the whole chart) is measured as drawn: its font size times the scale from the
SVG's units to the screen (``getScreenCTM``), and its box's height
(``getBoundingClientRect``).  A click on a state shows what its actions do,
whole; a taken transition shows how often, beside its label.
"""

from __future__ import annotations

from typing import Any

from .conftest import Cockpit, open_page

TIMEOUT_MS = 60_000
#: The smallest label a student reads without zooming (issue 27: the Control overview's were about 7 px).
MIN_LABEL_PX = 11.0

_SIZES_JS = """() => {
  const svg = document.querySelector('[data-role=diagram] svg');
  const out = [];
  for (const t of svg.querySelectorAll('text')) {
    if (!t.textContent.trim()) continue;
    const m = t.getScreenCTM();
    const px = parseFloat(getComputedStyle(t).fontSize) * Math.hypot(m.a, m.b);
    out.push([px, t.getBoundingClientRect().height, t.textContent.trim().slice(0, 40)]);
  }
  return out;
}"""


def _wait_view(page: Any, chart: str, view: str) -> None:
    page.wait_for_function(
        "([c, v]) => { const d = document.querySelector('[data-role=diagram]');"
        " return d.dataset.chart === c && d.dataset.view === v && !d.dataset.loading"
        " && d.querySelector('svg'); }", arg=[chart, view])


def _show_driveinit1(page: Any, cockpit: Cockpit) -> None:
    """Open the cockpit on DriveInit1's whole chart."""
    open_page(page, cockpit, "/charts", timeout_ms=TIMEOUT_MS)
    page.set_default_timeout(TIMEOUT_MS)
    page.wait_for_selector("[data-state]")
    page.locator('[data-role="chart-tabs"]').get_by_role("button", name="DriveInit1", exact=True).click()
    page.locator('[data-role="view-bar"]').get_by_role("button", name="Whole chart").click()
    _wait_view(page, "DriveInit1", "whole")


def _charts(page: Any) -> list[str]:
    """The charts of the session, at a laptop's size."""
    page.set_viewport_size({"width": 1280, "height": 720})
    page.set_default_timeout(TIMEOUT_MS)
    charts = page.eval_on_selector_all('[data-role="chart-tabs"] button', "bs => bs.map(b => b.dataset.chart)")
    assert len(charts) >= 5
    return charts


def _sizes_of_every_picture(page: Any) -> dict[str, list[tuple[float, float, str]]]:
    found: dict[str, list[tuple[float, float, str]]] = {}
    for chart in _charts(page):
        page.locator('[data-role="chart-tabs"]').get_by_role("button", name=chart, exact=True).click()
        bar = page.locator('[data-role="view-bar"]')
        subs = bar.locator("button.alone")
        views = [("overview", bar.get_by_role("button", name="Overview"))] if subs.count() else []
        views += [(subs.nth(i).get_attribute("title").split()[2], subs.nth(i)) for i in range(subs.count())]
        views += [("whole", bar.get_by_role("button", name="Whole chart"))] if subs.count() else [("whole", None)]
        for view, button in views:
            if button is not None:
                button.click()
            _wait_view(page, chart, view)
            found[f"{chart}.{view}"] = page.evaluate(_SIZES_JS)
    return found


def test_every_label_of_every_picture_is_at_least_11_px_at_1280x720(page: Any, cockpit: Cockpit) -> None:
    open_page(page, cockpit, "/charts", timeout_ms=TIMEOUT_MS)
    page.wait_for_selector("[data-state]")
    sizes = _sizes_of_every_picture(page)
    assert {"Control.overview", "Control.Drawing_O", "Control.whole", "Safety.overview", "Safety.whole",
            "DriveInit2.whole"} <= set(sizes)
    print({name: round(min(s)[0], 1) for name, s in sizes.items()})  # the numbers a report quotes
    small = {name: min(s) for name, s in sizes.items() if min(s)[0] < MIN_LABEL_PX}
    assert not small, f"labels under {MIN_LABEL_PX} px: {small}"
    # the box Chromium draws agrees: a label's box is at least its font size high
    assert all(height >= MIN_LABEL_PX for s in sizes.values() for _, height, _ in s)


def test_a_click_shows_the_whole_text_of_a_summarised_action_and_the_legend_is_once_on_the_page(
        page: Any, cockpit: Cockpit) -> None:
    _show_driveinit1(page, cockpit)
    state = page.locator('[data-role="diagram"] [data-state-id="turn_fwd"]')
    drawn = state.locator("text").all_text_contents()
    assert any(t.startswith("en: pos_out = enc_prev = pos_Encoder") for t in drawn)
    assert any(t.endswith("…") for t in drawn)  # the entry action is summarised on the picture ...
    state.click()
    page.keyboard.press("Escape")
    detail = page.locator('[data-role="diagram-detail"]')
    assert detail.is_visible()
    # ... and whole in the panel (and in the SVG's <title>, a browser's tooltip)
    whole = "en: pos_out = enc_prev = pos_Encoder; inc = search_speed*dt; index_start = index; direction = 1"
    assert whole in detail.text_content()
    assert whole in state.locator("title").text_content()
    # the pictures carry no legend; the page has it once, collapsible
    assert "Legend" not in " ".join(page.locator('[data-role="diagram"] text').all_text_contents())
    legend = page.locator("details.diagram-legend")
    assert legend.count() == 1 and legend.get_attribute("open") is None
    legend.locator("summary").click()
    page.wait_for_function("document.querySelector('[data-role=diagram-legend] svg') !== null")
    assert "entry action" in page.locator('[data-role="diagram-legend"]').text_content()


def test_a_taken_transition_shows_its_count_beside_its_label(page: Any, cockpit: Cockpit) -> None:
    _show_driveinit1(page, cockpit)
    # power_on -> turn_fwd is taken on the first chart ticks: step until a count is drawn
    for _ in range(20):
        if page.locator('[data-role="diagram"] text.taken-count').count():
            break
        tick = page.locator('[data-role="tick"]').text_content()
        page.get_by_role("button", name="Tick", exact=True).click()
        page.wait_for_function("t => document.querySelector('[data-role=tick]').textContent !== t", arg=tick)
    edges = page.eval_on_selector_all(
        '[data-role="diagram"] [data-taken-count]:not([data-taken-count="0"])',
        "els => els.map(e => [e.dataset.takenCount, (e.querySelector('text.taken-count') || {}).textContent])")
    assert edges, "no transition taken after 20 chart ticks"
    assert all(mark == f"×{count}" for count, mark in edges)
