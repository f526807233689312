"""The layers hold: who may import whom (tools.architecture.layers.CONTRACT), and no import circles.

The checker reads the source with ``ast``; the second half of this file
points it at a copy of the package with one wrong import put in, to show
that it fails, and how it names the import.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from tools.architecture.layers import CONTRACT, SOURCE_ROOT, allowed, check, component_of, scan


@pytest.fixture(scope="module")
def graph():
    return scan()


def test_the_layers_hold(graph):
    problems = check(graph)
    assert problems == [], "the layering contract is broken:\n" + "\n".join(problems)


def test_the_issue_rules_are_in_the_contract():
    """The rules issue 9 asks for, read off the contract itself."""
    by_name = {c.name: c for c in CONTRACT}
    assert allowed(by_name["runtime"]) == ["files"]  # the disk writer (ttt_sm.files): no robot code
    assert not {"charts", "sched", "app"} & set(allowed(by_name["twin"]))
    assert allowed(by_name["charts"]) == ["runtime"]
    assert "twin" not in allowed(by_name["vision"])
    for tool in ("debug", "scenario", "bench", "app", "sched", "twin", "vision", "game"):
        assert "cli" not in allowed(by_name[tool]) and "cli common" not in allowed(by_name[tool])


def test_every_module_belongs_to_one_component(graph):
    assert [m for m in graph.modules if component_of(m) is None] == []
    assert component_of("ttt_sm.vision.scenes").name == "vision staging"  # the longest prefix wins
    assert component_of("ttt_sm.vision.simulated").name == "vision"
    assert component_of("ttt_sm.cli.common").name == "cli common"


# --- the checker, checked: a copy of the package with one wrong import ---------------------------

@pytest.fixture
def package(tmp_path: Path) -> Path:
    copy = tmp_path / "src" / "ttt_sm"
    shutil.copytree(SOURCE_ROOT, copy, ignore=shutil.ignore_patterns("__pycache__", "*.bin", "*.toml"))
    return copy


def add_line(package: Path, module: str, line: str) -> int:
    """Append ``line`` to the module's file; return its line number."""
    path = package / module
    text = path.read_text(encoding="utf-8")
    path.write_text(text + line + "\n", encoding="utf-8")
    return text.count("\n") + 1


def test_the_copy_holds_before_anything_is_added(package):
    assert check(scan(package)) == []


def test_an_import_upwards_fails_naming_the_file_line_and_rule(package):
    n = add_line(package, "twin/kinematics/__init__.py", "from ...app.robot import Robot")
    problems = check(scan(package))
    assert problems[0] == (f"src/ttt_sm/twin/kinematics/__init__.py:{n}: ttt_sm.twin.kinematics imports "
                           "ttt_sm.app.robot, "
                           "but app (application) stands above twin (parts); twin may import: params, arm, files")
    # the app imports the twin, so the wrong import closes a circle too, named by the same line
    assert len(problems) == 2 and problems[1].startswith("import circle among ttt_sm.app.")
    assert f"ttt_sm.twin.kinematics -> ttt_sm.app.robot (src/ttt_sm/twin/kinematics/__init__.py:{n})" in problems[1]


def test_an_import_sideways_fails(package):
    n = add_line(package, "vision/simulated.py", "from ttt_sm.twin.whiteboard import Whiteboard")
    [problem] = check(scan(package))
    assert problem.startswith(f"src/ttt_sm/vision/simulated.py:{n}: ttt_sm.vision.simulated imports "
                              "ttt_sm.twin.whiteboard, but twin stands beside vision (both parts)")


def test_an_import_outside_an_only_list_fails(package):
    add_line(package, "charts/game.py", "from ..params import ArmParams")
    [problem] = check(scan(package))
    assert "params is not among what charts may import; charts may import: runtime" in problem


def test_a_circle_of_type_checking_imports_fails(package):
    n = add_line(package, "runtime/temporal.py", "if TYPE_CHECKING:\n    from .chart import TickChart")
    [problem] = check(scan(package))
    # every module on a way from temporal back to itself is in the circle (chart imports its class's builder,
    # its clock, guards, its plans, the engine and its callbacks and the program, all of which import temporal)
    assert problem.startswith("import circle among ttt_sm.runtime.callbacks, ttt_sm.runtime.chart, "
                              "ttt_sm.runtime.chart_class, ttt_sm.runtime.chart_clock, "
                              "ttt_sm.runtime.engine, ttt_sm.runtime.guards, ttt_sm.runtime.plan, "
                              "ttt_sm.runtime.program, "
                              "ttt_sm.runtime.temporal:")
    assert f"ttt_sm.runtime.temporal -> ttt_sm.runtime.chart (src/ttt_sm/runtime/temporal.py:{n + 1})" in problem


def test_a_subcommand_importing_back_from_the_cli_fails(package):
    n = add_line(package, "cli/ai.py", "def _late():\n    from . import main")
    [problem] = check(scan(package))
    assert problem.startswith("import circle among ttt_sm.cli, ttt_sm.cli.ai")
    assert f"ttt_sm.cli.ai -> ttt_sm.cli (src/ttt_sm/cli/ai.py:{n + 1})" in problem


def test_a_tool_importing_the_cli_fails(package):
    add_line(package, "debug/shell.py", "from ..cli.common import CliError")
    [problem] = check(scan(package))
    assert "imports ttt_sm.cli.common, but cli common stands beside debug (both tools)" in problem


def test_a_module_outside_the_contract_fails(package):
    (package / "extras").mkdir()
    (package / "extras" / "__init__.py").write_text('"""Something new."""\n', encoding="utf-8")
    assert check(scan(package)) == [
        "ttt_sm.extras: in no component of the layering contract; add it to CONTRACT"]
