"""``ttt-sm kinematics trajectory|forces``: the /kinematics/motion page's views with --json and --png."""

from __future__ import annotations

import json

import pytest

from ttt_sm.cli import main


def test_trajectory_json_text_and_png(capsys: pytest.CaptureFixture[str], tmp_path) -> None:
    png = tmp_path / "traj.png"
    argv = ["kinematics", "trajectory", "--from", "-0.02", "0.24", "--to", "0.02", "0.24", "--hold", "0.5",
            "--methods", "increment,quintic"]
    assert main([*argv, "--json", "--png", str(png)]) == 0
    d = json.loads(capsys.readouterr().out)
    assert [m["method"] for m in d["methods"]] == ["increment", "quintic"]
    assert d["methods"][0]["move_s"] == pytest.approx(0.04 / 0.02)
    assert all(m["ink_length_m"] == pytest.approx(0.04, abs=2e-3) for m in d["methods"])
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert out.startswith("line (-0.0200, 0.2400) -> (0.0200, 0.2400) m at 0.02 m/s") and "quintic" in out


def test_forces_text_names_the_estimate_s_error(capsys: pytest.CaptureFixture[str], tmp_path) -> None:
    png = tmp_path / "forces.png"
    assert main(["kinematics", "forces", "--at", "0.05", "0.3", "--png", str(png)]) == 0
    out = capsys.readouterr().out
    assert out.startswith("pen at (0.0500, 0.3000) m: manipulability |det J| = ")
    assert "contact force while drawing: true 2.0" in out and "relative error: mean " in out
    assert png.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.parametrize("argv, named", [(["trajectory", "--from", "0.5", "0"], "--from"),
                                         (["trajectory", "--methods", "spline"], "--methods"),
                                         (["trajectory", "--speed", "5"], "--speed"),
                                         (["forces", "--at", "0.0", "2.0"], "--at"),
                                         (["forces", "--png", "x.txt"], "--png")])
def test_bad_values_are_one_line_naming_the_option(capsys: pytest.CaptureFixture[str], argv: list[str],
                                                   named: str) -> None:
    assert main(["kinematics", *argv]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("ttt-sm kinematics") and named in err and "\n" not in err
