"""The runtime is generic: it imports no robot code (STYLE.md, one-way dependencies)."""

import ast
from pathlib import Path

RUNTIME = Path(__file__).resolve().parents[2] / "src" / "ttt_sm" / "runtime"
ROBOT = ("ttt_sm.twin", "ttt_sm.sched", "ttt_sm.params", "ttt_sm.app", "ttt_sm.cli", "ttt_sm.bench")


def test_runtime_imports_no_robot_code():
    offenders = []
    for path in sorted(RUNTIME.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom):
                if node.level >= 2:  # from .. import x: outside the runtime package
                    offenders.append(f"{path.name}: from {'.' * node.level}{node.module or ''}")
                elif node.level == 0 and node.module and node.module.startswith(ROBOT):
                    offenders.append(f"{path.name}: from {node.module}")
            elif isinstance(node, ast.Import):
                offenders += [f"{path.name}: import {a.name}" for a in node.names if a.name.startswith(ROBOT)]
    assert offenders == []
