"""Every page of docs/ runs: its commands, sessions and examples, and what they print is what it says.

The runner and its markers are described in tests/docs/mdrun.py; `-s` shows each
page's report (what ran, what was compared, what was left to other tests and why).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from mdrun import DocError, PageRunner, Tolerance, first_mismatch, line_matches, pages, read_blocks


@pytest.mark.parametrize("doc", pages(), ids=lambda p: p.name)
def test_the_page_runs_and_prints_what_it_says(doc: Path, tmp_path: Path) -> None:
    report = PageRunner(doc, tmp_path).run()  # a block that does not do what the page says raises DocError
    print(report.line())
    verified = (report.commands + report.debugger_commands + report.python_blocks + report.doctest_examples
                + report.scenarios_checked + report.json_checked + report.checks + report.paths)
    assert verified > 0, f"{doc.name}: nothing on the page was run or checked ({report.line()})"


# -- the runner itself: it finds what is false ---------------------------------------------------


def _page(tmp_path: Path, text: str) -> PageRunner:
    tmp_path.mkdir(exist_ok=True)
    page = tmp_path / "page.md"
    page.write_text(text, encoding="utf-8")
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    return PageRunner(page, scratch)


def test_a_number_the_command_does_not_print_is_found_with_its_line(tmp_path: Path) -> None:
    runner = _page(tmp_path, "Intro.\n\n```\n$ ttt-sm ai move --board ............X............ --symbol O\n"
                             "2 3\n```\n")
    with pytest.raises(DocError) as caught:
        runner.run()
    message = str(caught.value)
    assert message.startswith("page.md:5: `ttt-sm ai move --board ............X............ --symbol O`:"
                              " the page says '2 3', it printed ")


def test_elisions_exit_status_and_tolerance(tmp_path: Path) -> None:
    runner = _page(tmp_path, """\
<!-- doc-test: numbers within 5% -->
```
$ ttt-sm ai move --board XXX...................... --symbol O
ttt-sm ai: error: --board: impossible move counts: X has 3 marks and O 0; ...
(exit status 2)
$ ttt-sm ai move --board ............X............ --symbol O --json
...
  "row": 2,
...
```
""")
    report = runner.run()
    assert report.commands == 2 and report.outputs_compared == 2
    assert line_matches("t = 3.0150 s", "t = 3.015 s", Tolerance())
    assert not line_matches("t = 3.0150 s", "t = 3.0151 s", Tolerance())
    assert line_matches("current 5.7 A", "current 5.723 A", Tolerance(rel=0.01))
    assert not line_matches("DriveInit1 moved", "DriveInit2 moved", Tolerance(abs=5))  # names are text
    assert first_mismatch(["a", "...", "d"], ["a", "b", "c", "d"], Tolerance()) is None
    assert first_mismatch(["a", "...", "e"], ["a", "b", "c", "d"], Tolerance()) == (2, 4)


def test_a_false_claim_about_a_debugger_session_is_found(tmp_path: Path) -> None:
    runner = _page(tmp_path, """\
```
$ ttt-sm debug
(ttt-sm) break enter DriveInit1.turn_back
(ttt-sm) run
```

Drive 1 stops against its hard stop at 170 deg, turning back:
<!-- check: abs(q_true[1] - 170deg) < 0.5deg and DriveInit1.direction == -1 -->
and it has already found its index:
<!-- check: DriveInit1.offset != 0 -->
""")
    with pytest.raises(DocError) as caught:
        runner.run()
    assert str(caught.value).startswith("page.md:10: the page claims 'DriveInit1.offset != 0', which is false"
                                        " where the session above ended (t = 3.0150 s): DriveInit1.offset = 0")
    assert runner.report.checks == 1 and runner.report.debugger_commands == 2


def test_markers_are_read_and_need_what_they_promise(tmp_path: Path) -> None:
    blocks = read_blocks("<!-- doc-test: skip: a server -->\n```\n$ ttt-sm camera serve\n```\n"
                         "```python\nx = 1\n```\n<!-- check: t > 0 -->\n", "p.md")
    assert blocks[0].markers == ["skip: a server"] and blocks[1].checks == [(8, "t > 0")]
    with pytest.raises(DocError, match="p.md:1: a doc-test marker with no code block after it"):
        read_blocks("<!-- doc-test: skip: x -->\ntext\n", "p.md")
    for k, (marker, message) in enumerate((("skip:", "needs a reason"),
                                           ("run by tests/nothing.py", "no such test file naming"),
                                           ("numbers roughly", "unknown doc-test marker"))):
        runner = _page(tmp_path / str(k), f"<!-- doc-test: {marker} -->\n```\n$ ttt-sm ai move\n```\n")
        with pytest.raises(DocError, match=message):
            runner.run()


def test_a_python_block_that_fails_names_its_page(tmp_path: Path) -> None:
    runner = _page(tmp_path, "```python\nx = 1\n```\n\n```python\nassert x == 2, 'x is 1'\n```\n")
    with pytest.raises(AssertionError, match="x is 1"):
        runner.run()


def test_a_file_the_reader_saves_is_there_for_the_commands_below(tmp_path: Path) -> None:
    runner = _page(tmp_path, """\
<!-- doc-test: file scenarios/mine.yaml -->
```yaml
name: mine
steps:
  - run: {chart_steps: 1}
  - expect: "DriveInit1.turn_back"
```

```
$ ttt-sm scenario check scenarios/mine.yaml
ok mine  (scenarios/mine.yaml; 3 steps)
```
""")
    with pytest.raises(DocError) as caught:
        runner.run()
    assert str(caught.value) == ("page.md:11: `ttt-sm scenario check scenarios/mine.yaml`: the page says"
                                 " 'ok mine  (scenarios/mine.yaml; 3 steps)', it printed"
                                 " 'ok mine  (scenarios/mine.yaml; 2 steps)' (printed line 1)")
    assert runner.report.files_written == 1
    with pytest.raises(DocError, match="a file name inside the folder the commands run in"):
        _page(tmp_path / "up", "<!-- doc-test: file ../x.yaml -->\n```\nx\n```\n").run()


def test_a_block_that_does_not_run_may_not_hold_what_would(tmp_path: Path) -> None:
    runner = _page(tmp_path, "```\nexpr := or\n```\n\n```\n>>> 1 + 1\n3\n```\n")
    with pytest.raises(DocError, match=r"page.md:6: a '>>>' example in a block that does not run"):
        runner.run()
    assert runner.report.text_blocks == 1
    with pytest.raises(DocError, match=r"page.md:2: a '\$ ' command in a ```text block"):
        _page(tmp_path / "b", "```text\n$ ttt-sm ai move\n```\n").run()
    # what the prose says a block prints is compared with it, or refused
    printed = "```python\nprint(6 * 7)\n```\n\nprints\n\n```\n{}\n```\n"
    with pytest.raises(DocError, match="page.md:7: the page says this is what is printed, but nothing compares"):
        _page(tmp_path / "c", printed.format(42)).run()
    marked = printed.replace("prints\n", "prints\n<!-- doc-test: printed by the block above -->\n")
    assert _page(tmp_path / "d", marked.format(42)).run().outputs_compared == 1
    with pytest.raises(DocError, match="the page says '41', it printed '42'"):
        _page(tmp_path / "e", marked.format(41)).run()
