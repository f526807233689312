"""Scenario files that are not scenarios: bombs, binary files, deep nesting, endless steps.

Each is refused at load with one line naming the file and the line, in
bounded time and memory (docs/reliability.md).
"""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from ttt_sm.runtime.conditions import MAX_CONDITION_CHARS, MAX_DEPTH, ExprError, parse
from ttt_sm.scenario import ScenarioError, load_scenario, load_scenario_text
from ttt_sm.scenario.model import DEFAULT_MAX_STEP_S
from ttt_sm.scenario.source import MAX_FILE_BYTES, MAX_NESTING

MEMORY_LIMIT_MB = 500


def error_of(text: str, file: str = "s.yaml") -> ScenarioError:
    with pytest.raises(ScenarioError) as info:
        load_scenario_text(textwrap.dedent(text), file)
    return info.value


def billion_laughs(levels: int = 12, fan: int = 10) -> str:
    """A sequence of state names whose first item expands, through aliases, to fan**levels names."""
    nested = [f"&l0 [{', '.join(['lol'] * fan)}]"]
    nested += [f"&l{k} [{', '.join(['*l' + str(k - 1)] * fan)}]" for k in range(1, levels)]
    return textwrap.dedent(f"""\
        name: laughs
        steps:
          - expect_states:
              chart: DriveInit1
              sequence: [[{', '.join(nested)}]]
    """)


def run_isolated(code: str) -> tuple[subprocess.CompletedProcess[str], float]:
    """Run `code` in a fresh interpreter whose address space is capped; return it and its peak RSS (MB)."""
    wrapper = textwrap.dedent(f"""
        import resource, sys
        cap = {2 * MEMORY_LIMIT_MB} * 2**20  # a safety net: the old loader would take the machine down
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
        exec(compile({code!r}, "<isolated>", "exec"))
        # VmHWM: this process's peak RSS (ru_maxrss would count the forking parent's pages too)
        hwm = next(line for line in open("/proc/self/status") if line.startswith("VmHWM:"))
        print("peak_rss_mb", int(hwm.split()[1]) / 1024, file=sys.stderr)
    """)
    proc = subprocess.run([sys.executable, "-c", wrapper], capture_output=True, text=True, timeout=300)
    peak = [float(line.split()[1]) for line in proc.stderr.splitlines() if line.startswith("peak_rss_mb")]
    return proc, peak[0] if peak else float("inf")


def test_a_yaml_bomb_is_refused_at_its_first_alias_in_bounded_memory(tmp_path):
    bomb = tmp_path / "bomb.yaml"
    bomb.write_text(billion_laughs())
    proc, peak_mb = run_isolated(textwrap.dedent(f"""
        from ttt_sm.scenario import ScenarioError, load_scenario
        try:
            load_scenario({str(bomb)!r})
        except ScenarioError as exc:
            print(exc)
    """))
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.strip().startswith(f"{bomb}:5: YAML aliases (*l0) are not allowed"), proc.stdout
    assert peak_mb < MEMORY_LIMIT_MB


def test_an_alias_anywhere_names_its_line():
    e = error_of("""\
        name: n
        steps:
          - run: &r {seconds: 1}
          - run: *r
    """)
    assert (e.file, e.line) == ("s.yaml", 4)
    assert "YAML aliases (*r) are not allowed" in e.message


@pytest.mark.parametrize("content, line, message", [
    (b"name: n\nsteps:\n  - mark: caf\xe9\n", 3, "not UTF-8 text (byte 0xe9 at column 14)"),
    (b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR", 1, "not UTF-8 text (byte 0x89 at column 1)"),
    (b"name: n\nsteps:\n  - mark: a\x00b\n", 3, "not valid YAML: character #x0000 at column 12: special"),
    (b"name: n\nsteps:\n  - mark: " + b"[" * 5000 + b"]" * 5000 + b"\n", 3,
     f"nested deeper than {MAX_NESTING} levels"),
])
def test_files_that_are_not_text_or_nest_too_deep_get_one_line(tmp_path, content, line, message):
    f = tmp_path / "bad.yaml"
    f.write_bytes(content)
    with pytest.raises(ScenarioError) as info:
        load_scenario(f)
    assert str(info.value).startswith(f"{f}:{line}: "), str(info.value)
    assert message in str(info.value)
    assert "\n" not in str(info.value)


def test_a_file_too_big_is_refused_before_it_is_read(tmp_path):
    f = tmp_path / "big.yaml"
    f.write_bytes(b"name: n\nsteps:\n" + b"  - mark: x\n" * (MAX_FILE_BYTES // 12 + 10))
    with pytest.raises(ScenarioError, match=rf"^{f}: more than {MAX_FILE_BYTES} bytes"):
        load_scenario(f)


def test_a_device_that_never_ends_is_not_read_to_its_end():
    with pytest.raises(ScenarioError, match=r"^/dev/zero: (more than|not)"):
        load_scenario("/dev/zero")


def test_a_huge_value_is_not_formatted_whole_into_a_message():
    e = error_of("name: n\nsteps:\n  - run: {seconds: '" + "x" * 200_000 + "'}\n")
    assert e.line == 3 and len(str(e)) < 300


def test_a_deeply_nested_condition_is_refused_with_its_column():
    text = "(" * 10_000 + "1" + ")" * 10_000
    with pytest.raises(ExprError, match=r"nested deeper than \d+ levels at column \d+"):
        parse(text[:MAX_CONDITION_CHARS])
    for deep in ("not " * 400 + "true", "-" * 1000 + "1", "abs(" * 300 + "1" + ")" * 300, "+".join("1" * 900)):
        with pytest.raises(ExprError, match=r"nested deeper than \d+ levels"):
            parse(deep)
    parse("(" * MAX_DEPTH + "1" + ")" * MAX_DEPTH)  # as deep as allowed


def test_a_condition_too_long_is_refused_before_it_is_parsed():
    with pytest.raises(ExprError, match=rf"a condition is at most {MAX_CONDITION_CHARS} characters, got 1000001"):
        parse("1" + " " * 1_000_000)


def test_in_a_scenario_a_deep_condition_names_the_file_and_line():
    e = error_of("name: n\nsteps:\n  - expect: \"" + "not " * 3000 + "true\"\n")
    assert e.line == 3 and "expect: " in e.message and len(str(e)) < 400


@pytest.mark.parametrize("step", [
    "run_until: {condition: \"t > 1\", timeout_s: 1.0e+12}",
    "run: {seconds: 1.0e+12}",
    "expect: {condition: \"t > 1\", within_s: 1.0e+12}",
    "expect: {condition: \"t > 1\", for_s: 1.0e+12}",
])
def test_a_step_beyond_the_time_bound_is_refused_naming_the_bound_and_how_to_raise_it(step):
    e = error_of(f"name: n\nsteps:\n  - {step}\n")
    assert e.line == 3
    assert f"beyond {DEFAULT_MAX_STEP_S:g} s of simulated time, the longest a step may run" in e.message
    assert "max_step_s:" in e.message


def test_the_start_settle_time_is_bounded_too():
    e = error_of("name: n\nstart: {settle_s: 1.0e+9}\nsteps:\n  - run: {seconds: 1}\n")
    assert e.line == 2 and "settle_s" in e.message and "max_step_s" in e.message


def test_max_step_s_raises_the_bound_and_is_itself_checked():
    s = load_scenario_text("name: n\nmax_step_s: 5000\nsteps:\n  - run: {seconds: 4000}\n", "s.yaml")
    assert s.max_step_s == 5000 and s.steps[0].seconds == 4000
    e = error_of("name: n\nmax_step_s: -1\nsteps:\n  - run: {seconds: 4}\n")
    assert e.line == 2 and "max_step_s" in e.message
    assert load_scenario_text("name: n\nsteps:\n  - run: {seconds: 1}\n", "s.yaml").max_step_s == \
        DEFAULT_MAX_STEP_S


def test_the_packaged_scenarios_all_keep_the_default_bound():
    folder = Path(__file__).resolve().parents[1] / "scenarios"
    for f in sorted(folder.glob("*.yaml")):
        assert load_scenario(f).max_step_s == DEFAULT_MAX_STEP_S
