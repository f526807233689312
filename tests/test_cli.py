"""The command line: every result-producing command prints JSON with the promised keys."""

import json

import pytest

from ttt_sm.cli import main


def run_json(capsys, *argv):
    code = main([*argv, "--json"] if "--" not in argv else list(argv))
    out = capsys.readouterr().out
    return code, json.loads(out)


def test_params_json_is_si(capsys):
    code, data = run_json(capsys, "params")
    assert code == 0
    assert data["geometry"]["L2"] == pytest.approx(0.22)
    assert data["control"]["rate_hz"] == 1000.0


def test_ik_json_reaches_the_target(capsys):
    code, data = run_json(capsys, "ik", "10", "250", "5", "--phi", "0")
    assert code == 0
    assert data["reached_mm_deg"] == pytest.approx([10.0, 250.0, 5.0, 0.0], abs=1e-2)
    assert data["iterations"] >= 1


def test_unreachable_ik_target_is_one_line_and_exit_2(capsys):
    code = main(["ik", "2000", "0", "0"])
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith("ttt-sm ik: error:") and err.count("\n") == 1


def test_a_bad_parameter_file_is_named(capsys, tmp_path):
    bad = tmp_path / "arm.toml"
    bad.write_text("[geometry]\nL1 = 'tall'\n")
    code = main(["--params", str(bad), "params"])
    err = capsys.readouterr().err
    assert code == 2
    assert str(bad) in err and "not valid" not in err  # valid TOML, wrong content
    assert "[geometry] is missing L2" in err


def test_init_json_keys(capsys):
    code, data = run_json(capsys, "init", "--starts", "2", "--seed", "5")
    assert code == 0
    for key in ("runs", "successes", "limit_violations", "board_zone_entries", "max_time_s",
                "mean_time_s", "max_offset_error_rad"):
        assert key in data
    assert data["runs"] == 2 and data["successes"] == 2


def test_charts_check_passes_on_the_repository(capsys):
    code, data = run_json(capsys, "charts", "check")
    assert code == 0 and data["ok"] is True


def test_charts_export_writes_the_asked_formats(capsys, tmp_path):
    code, data = run_json(capsys, "charts", "export", "--format", "dot,mermaid", "--out", str(tmp_path))
    assert code == 0
    names = {p.split("/")[-1] for p in data["written"]}
    assert {"DriveInit1.dot", "DriveInit1.md", "DriveInit3.dot"} <= names
    code = main(["charts", "export", "--format", "gif", "--out", str(tmp_path)])
    assert code == 2


def test_bench_quick_json_keys(capsys):
    code, data = run_json(capsys, "bench", "--quick", "--only", "ik,loop,pacing,charts")
    assert code == 0
    for key in ("ik_warm_median_us", "ik_warm_median_iterations", "ik_offset_median_us",
                "ik_cold_success_rate", "loop_realtime_factor", "pacing_deadline_misses",
                "pacing_lateness_p99_us", "chart_quiet_tick_us", "chart_send_tick_us"):
        assert key in data
    assert data["ik_cold_success_rate"] == 1.0


def test_bench_rejects_an_unknown_section(capsys):
    assert main(["bench", "--only", "nonsense"]) == 2
    assert "unknown bench section" in capsys.readouterr().err


def test_tune_json_keys(capsys, tmp_path):
    code, rows = run_json(capsys, "tune", "--out", str(tmp_path))
    assert code == 0
    assert [r["drive"] for r in rows] == [1, 2, 3]
    for r in rows:
        for key in ("step_rad", "rise_time_s", "settling_time_s", "overshoot_pct", "error_at_0_5s_rad",
                    "static_error_rad", "inner_phase_margin_deg", "outer_phase_margin_deg",
                    "outer_gain_margin_db"):
            assert key in r
    assert (tmp_path / rows[0]["plot"].split("/")[-1]).exists()


def test_draw_rejects_a_cell_off_the_field(capsys):
    code = main(["draw", "X", "--row", "6", "--column", "1"])
    assert code == 2
    assert "cell (6, 1) is off the 5x5 field" in capsys.readouterr().err
