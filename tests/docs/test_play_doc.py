"""docs/play.md stays true: its Python example plays a whole game as written, its key table is complete."""

import re
from pathlib import Path

import pytest

PLAY = (Path(__file__).resolve().parents[2] / "docs" / "play.md").read_text()


@pytest.fixture(scope="module")
def example():
    blocks = re.findall(r"```python\n(.*?)```", PLAY, re.S)
    assert len(blocks) == 1, "docs/play.md should hold one Python example"
    namespace: dict = {}
    exec(compile(blocks[0], "docs/play.md", "exec"), namespace)  # noqa: S102 - our own docs
    return namespace


def test_the_python_example_plays_a_whole_game(example):
    report = example["report"]
    assert report["moves"] and report["camera"] == "serial"


def test_the_report_table_names_every_key_a_game_reports(example):
    table = re.search(r"## What it reports\n(.*?)\n## ", PLAY, re.S).group(1)
    documented = set(re.findall(r"`([a-z_0-9]+)`", table.split("The files")[0]))
    reported = set(example["report"]) | {"record", "board_png", "opponent"}  # the CLI adds these three
    assert reported <= documented, sorted(reported - documented)
