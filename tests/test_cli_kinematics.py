"""``ttt-sm kinematics workspace|dh|race``: the /kinematics page's views with --json and --png."""

from __future__ import annotations

import json

import pytest

from ttt_sm.cli import main


def run_json(capsys: pytest.CaptureFixture[str], *argv: str) -> dict:
    assert main(["kinematics", *argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_workspace_json_answers_exercise_a(capsys: pytest.CaptureFixture[str]) -> None:
    d = run_json(capsys, "workspace", "--q2-max-deg", "86", "--q3-max-deg", "100")
    assert d["cells"][3] == ["elbow down"] * 3 + ["elbow up"] * 2
    assert d["fits"] is True


def test_workspace_text_shows_the_6x6_field_missing_its_far_corner(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["kinematics", "workspace", "--cells", "6", "--cell-m", "0.03", "--L2", "0.215"]) == 0
    out = capsys.readouterr().out
    assert "field fits: no" in out and "  UUUUU-\n" in out


def test_race_json_and_png(capsys: pytest.CaptureFixture[str], tmp_path) -> None:
    png = tmp_path / "race.png"
    assert main(["kinematics", "race", "--target", "0.075", "0.325", "--json", "--png", str(png)]) == 0
    d = json.loads(capsys.readouterr().out)
    assert [m["method"] for m in d["methods"]] == ["lm_fixed", "dls_adaptive", "analytic_up", "analytic_down", "twist"]
    assert all(m["converged"] for m in d["methods"])
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000


def test_dh_png(capsys: pytest.CaptureFixture[str], tmp_path) -> None:
    png = tmp_path / "dh.png"
    assert main(["kinematics", "dh", "--q-deg", "0", "90", "-90", "0", "--png", str(png)]) == 0
    assert "link  theta offset" in capsys.readouterr().out
    assert png.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("argv, named", [(["workspace", "--q3-max-deg", "-170"], "q3"),
                                         (["workspace", "--L2", "5"], "--L2"),
                                         (["race", "--target", "0.1", "0.2", "--max-iterations", "0"],
                                          "--max-iterations")])
def test_bad_values_are_one_line_naming_the_option(capsys: pytest.CaptureFixture[str], argv: list[str],
                                                   named: str) -> None:
    assert main(["kinematics", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("ttt-sm kinematics") and named in err and "\n" not in err
