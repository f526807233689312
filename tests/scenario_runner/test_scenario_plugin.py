"""The pytest plugin: scenario files in a `scenarios` folder are test items."""

from __future__ import annotations

from ttt_sm.app.robot import Robot
from ttt_sm.params import load_params

PASSING = """\
name: drive 1 starts turning forward
steps:
  - run_until: {entered: DriveInit1.turn_fwd, timeout_s: 0.1}
"""
FAILING = """\
name: drive 1 turns back at once
steps:
  - run: {chart_steps: 2}
  - expect: "DriveInit1.turn_back"
  - expect: "DriveInit1.stopped"
"""
MALFORMED = """\
name: two typos
steps:
  - run_until: {entered: DriveInit1.turn_back}
  - expect: "q_tru[1] > 0"
"""


def test_scenario_files_are_collected_and_fail_with_file_line(pytester) -> None:
    # pytester runs pytest in this process and afterwards forgets the modules imported
    # meanwhile; build a robot first so that its lazy imports (numpy.fft via python-control)
    # happen out here and are not imported twice later.
    Robot(load_params(None))
    pytester.makeconftest('pytest_plugins = ["ttt_sm.scenario.pytest_plugin"]')
    folder = pytester.mkdir("scenarios")
    (folder / "drive_1_starts_turning_forward.yaml").write_text(PASSING)
    (folder / "drive_1_turns_back_at_once.yaml").write_text(FAILING)
    (folder / "a_typo.yaml").write_text(MALFORMED)
    (pytester.path / "not_a_scenario.yaml").write_text("just: data\n")  # outside scenarios/: ignored
    result = pytester.runpytest("-p", "no:cacheprovider", "-v", "--scenario-coverage")
    result.assert_outcomes(passed=1, failed=2)
    result.stdout.fnmatch_lines([
        "scenarios/a_typo.yaml::a_typo FAILED*",
        "scenarios/drive_1_starts_turning_forward.yaml::drive_1_starts_turning_forward PASSED*",
        "scenarios/drive_1_turns_back_at_once.yaml::drive_1_turns_back_at_once FAILED*",
        "scenario file is not valid:",
        "  scenarios/a_typo.yaml:3: run_until: missing timeout_s:*",
        "  scenarios/a_typo.yaml:4: expect: unknown name 'q_tru'*",  # every mistake of the file
        "scenario 'drive 1 turns back at once' failed (3 of 3 steps run, t = 0.004 s):",
        "  scenarios/drive_1_turns_back_at_once.yaml:4: expect: 'DriveInit1.turn_back' is false*",
        "  scenarios/drive_1_turns_back_at_once.yaml:5: expect: 'DriveInit1.stopped' is false*",
        "*scenario coverage*",
        "DriveInit1: states 4/*",
    ])
    assert "Traceback" not in result.stdout.str()
