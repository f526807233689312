"""Strict JSON everywhere: a NaN or an infinity is ``null``, never the bare ``NaN`` JSON readers refuse."""

from __future__ import annotations

import ast
import dataclasses
import json
import math
from pathlib import Path

import numpy as np

from ttt_sm.cli import main
from ttt_sm.cli.common import emit
from ttt_sm.runtime.jsonable import dumps, jsonable
from ttt_sm.runtime.listeners import TraceRecord

SRC = Path(__file__).resolve().parents[1] / "src" / "ttt_sm"


def strict_loads(text: str):
    """``json.loads`` that refuses NaN, Infinity and -Infinity, as a strict reader does."""
    def refuse(word: str):
        raise ValueError(f"not JSON: {word}")
    return json.loads(text, parse_constant=refuse)


@dataclasses.dataclass
class Result:
    settle_s: float
    margins_db: np.ndarray
    path: Path


def test_non_finite_numbers_become_null_wherever_they_are():
    value = {"nan": math.nan, "inf": math.inf, "np": np.float64("-inf"), "ok": np.float32(0.5),
             "array": np.array([1.0, np.nan]), "result": Result(math.nan, np.array([np.inf, 6.0]), Path("a/b")),
             "nested": [(math.nan, 1), {"n": np.int64(3), "b": np.bool_(True)}]}
    assert jsonable(value) == {"nan": None, "inf": None, "np": None, "ok": 0.5, "array": [1.0, None],
                               "result": {"settle_s": None, "margins_db": [None, 6.0], "path": "a/b"},
                               "nested": [[None, 1], {"n": 3, "b": True}]}
    assert strict_loads(dumps(value))["array"] == [1.0, None]
    assert dumps([math.nan, -math.inf]) == "[null, null]"


def test_the_cli_prints_a_result_with_nan_as_strict_json(capsys):
    emit({"settle_s": math.nan, "steps": np.array([0.1, np.inf])}, as_json=True)
    out = capsys.readouterr().out
    assert "NaN" not in out and "Infinity" not in out
    assert strict_loads(out) == {"settle_s": None, "steps": [0.1, None]}


def test_a_trace_record_with_nan_data_is_strict_json():
    line = TraceRecord(tick=3, time_s=0.03, chart="Control", source="a", target="b", trigger="tick",
                       data=jsonable({"X_out": math.nan})).to_json()
    assert strict_loads(line)["data"] == {"X_out": None}


def test_the_debugger_snapshot_shows_a_chart_output_not_yet_set_as_null(tmp_path, capsys):
    # before initialisation the Control chart has no tool pose: X_out is NaN inside the chart
    commands = tmp_path / "commands.txt"
    commands.write_text("show snapshot\n")
    assert main(["debug", "--commands", str(commands)]) == 0
    line = next(ln for ln in capsys.readouterr().out.splitlines() if ln.startswith('{"charts"'))
    snapshot = strict_loads(line)
    assert snapshot["charts"]["Control"]["data"]["X_out"] is None


def _json_writes_without_allow_nan(root: Path) -> list[str]:
    """``file:line`` of every ``json.dump``/``json.dumps`` call under ``root`` without ``allow_nan=False``."""
    found = []
    for path in sorted(root.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                    and isinstance(node.func.value, ast.Name) and node.func.value.id == "json"
                    and node.func.attr in ("dump", "dumps")):
                if not any(k.arg == "allow_nan" and isinstance(k.value, ast.Constant) and k.value.value is False
                           for k in node.keywords):
                    found.append(f"{path.relative_to(root.parent)}:{node.lineno}")
    return found


def test_no_json_is_written_past_the_strict_writer():
    """Every ``json.dump(s)`` in the package passes ``allow_nan=False`` (use ``runtime.jsonable.dumps``)."""
    offenders = _json_writes_without_allow_nan(SRC)
    assert offenders == [], (f"json.dumps without allow_nan=False (a NaN would print as bare NaN): {offenders}; "
                             "use ttt_sm.runtime.jsonable.dumps")


def test_the_checker_finds_a_lax_json_write(tmp_path):
    pkg = tmp_path / "ttt_sm"
    pkg.mkdir()
    (pkg / "strict.py").write_text("import json\nprint(json.dumps({'x': 1}, allow_nan=False))\n")
    (pkg / "lax.py").write_text("import json\nprint(json.dumps({'x': float('nan')}))\n")
    assert _json_writes_without_allow_nan(pkg) == ["ttt_sm/lax.py:2"]
