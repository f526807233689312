"""``ttt-sm ik --method dls|dls-fixed|closed [--elbow up|down] [--trace]``: the thesis' fixed-lambda loop reachable."""

from __future__ import annotations

import json

import numpy as np
import pytest

from ttt_sm.cli import main


def run_json(capsys, *argv):
    code = main(["ik", *argv, "--json"])
    return code, json.loads(capsys.readouterr().out)


def test_the_thesis_fixed_lambda_loop_converges_and_its_trace_is_its_path(capsys):
    code, fixed = run_json(capsys, "0", "250", "0", "--method", "dls-fixed", "--trace")
    assert code == 0 and fixed["method"] == "dls-fixed" and fixed["damping"] == 0.001
    trace = fixed["trace"]
    assert [t["iteration"] for t in trace] == list(range(1, fixed["iterations"] + 1))
    residuals = [t["residual"] for t in trace]
    assert residuals == sorted(residuals, reverse=True)  # every fixed step brings it closer
    assert residuals[-1] == fixed["residual"] <= fixed["tolerance"]
    assert trace[-1]["q_deg"] == fixed["q_deg"]
    _, closed = run_json(capsys, "0", "250", "0", "--method", "closed")
    assert closed["iterations"] == 0 and closed["within_limits"]
    assert np.allclose(fixed["q_deg"], closed["q_deg"], atol=1e-3)


def test_the_closed_form_gives_the_elbow_down_branch_and_says_it_is_out_of_limits(capsys):
    code, down = run_json(capsys, "0", "250", "0", "--method", "closed", "--elbow", "down")
    assert code == 0 and down["q_deg"][2] > 0 and not down["within_limits"]
    assert down["residual"] < 1e-12


@pytest.mark.parametrize("argv, named", [(["--method", "dls", "--elbow", "down"], "--elbow"),
                                         (["--method", "closed", "--trace"], "--trace")])
def test_options_that_do_not_go_together_are_refused_in_one_line(capsys, argv, named):
    assert main(["ik", "0", "250", "0", *argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and named in err[0]
