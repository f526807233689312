"""charts/ in the repository is generated: a test fails when it is stale."""

from pathlib import Path

from ttt_sm.charts import ALL_CHARTS
from ttt_sm.cli.commands import REPO_CHART_FORMATS
from ttt_sm.runtime.export import stale_files

REPO = Path(__file__).resolve().parents[2]


def test_charts_folder_is_up_to_date():
    stale = stale_files(ALL_CHARTS, REPO / "charts", REPO_CHART_FORMATS)
    assert not stale, f"regenerate with `ttt-sm charts export`: {stale}"


def test_every_chart_has_its_page_and_svg():
    for chart in ALL_CHARTS:
        name = chart.__name__
        page = (REPO / "charts" / f"{name}.md").read_text()
        assert "```mermaid" in page and "| input |" in page
        assert (REPO / "charts" / f"{name}.svg").read_text().lstrip().startswith("<?xml")
