"""charts/ in the repository is generated: a test fails when it is stale."""

import html
import re
from pathlib import Path

from ttt_sm.charts import ALL_CHARTS, Control
from ttt_sm.cli.commands import REPO_CHART_FORMATS, repo_chart_extras
from ttt_sm.runtime.dot import to_dot
from ttt_sm.runtime.dot_views import subcharts, views
from ttt_sm.runtime.export import stale_files

REPO = Path(__file__).resolve().parents[2]


def test_charts_folder_is_up_to_date():
    stale = stale_files(ALL_CHARTS, REPO / "charts", REPO_CHART_FORMATS, repo_chart_extras())
    assert not stale, f"regenerate with `ttt-sm charts export`: {stale}"


def test_every_chart_has_its_page_and_svg():
    for chart in ALL_CHARTS:
        name = chart.__name__
        page = (REPO / "charts" / f"{name}.md").read_text()
        assert "```mermaid" in page and "| input |" in page
        assert (REPO / "charts" / f"{name}.svg").read_text().lstrip().startswith("<?xml")


def _size_pt(svg: str) -> tuple[float, float]:
    match = re.search(r'<svg width="([\d.]+)pt" height="([\d.]+)pt"', svg)
    assert match, "no size in the SVG"
    return float(match.group(1)), float(match.group(2))


def test_charts_with_sub_charts_have_an_overview_first_a_picture_per_sub_chart_and_one_legend():
    index = (REPO / "charts" / "index.md").read_text()
    for chart in ALL_CHARTS:
        name = chart.__name__
        subs = subcharts(chart)
        svgs = [f"{name}.overview.svg", *(f"{name}.{s}.svg" for s in subs), f"{name}.svg"] if subs else [f"{name}.svg"]
        positions = [index.index(f"({svg})") for svg in svgs]
        assert positions == sorted(positions), f"{name}: index.md lists its overview first, the whole chart last"
        for svg in svgs:  # the legend is on the chart's page, once, not in every picture
            assert "Legend" not in to_dot(chart, view=next(v for v in views(chart)
                                                           if v.file_stem(name) + ".svg" == svg))
            assert ">Legend</text>" not in (REPO / "charts" / svg).read_text()
        page = (REPO / "charts" / f"{name}.md").read_text()
        assert page.count("How to read the pictures:") == 1 and "| en: f | entry action" in page
        if subs:
            assert f"![{name}: overview, sub-charts closed]({name}.overview.svg)" in page
            assert all(f"({name}.{s}.svg)" in page for s in subs)


def test_the_control_overview_shows_the_sub_charts_of_thesis_fig_3_24_closed_and_small():
    # fig. 3.24: start_stop, Drawing_playing_field, Drawing_X, Drawing_O, Erase; the sine
    # wave and finishing are this project's
    assert subcharts(Control) == ("start_stop", "Drawing_playing_field", "Drawing_X", "Drawing_O",
                                  "Drawing_sine", "Erase", "finishing")
    overview = html.unescape((REPO / "charts" / "Control.overview.svg").read_text())
    for sub in subcharts(Control):
        assert f'<g id="state-{sub}" class="node">' in overview
    assert 'class="cluster"' not in overview
    width, height = _size_pt(overview)
    whole_width, whole_height = _size_pt((REPO / "charts" / "Control.svg").read_text())
    assert width <= 1200 and height <= 900
    assert width * height < 0.5 * whole_width * whole_height
