"""The tick benchmark runs and reports its numbers (no timing asserts)."""

from ttt_sm.runtime.bench import BenchMove, bench_quiet_tick


def test_bench_reports_quiet_and_send_costs():
    result = bench_quiet_tick(repeat=3, number=50)
    assert set(result) == {"chart_quiet_tick_us", "chart_send_tick_us", "chart_transition_tick_us", "speedup"}
    assert all(value > 0 for value in result.values())


def test_bench_chart_guards_all_run_on_the_fast_path():
    assert set(BenchMove().guard_paths().values()) == {"fast"}
