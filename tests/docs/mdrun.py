"""Run the code of a docs/ page and check what it prints: the documentation's own test runner.

A page is read top to bottom; each fenced code block is one of:

- a **transcript**: a block whose lines start with ``$ `` (``$ ttt-sm ...``,
  ``$ .venv/bin/ttt-sm ...``, ``$ .venv/bin/python ...``).  Each command runs;
  the lines under it, up to the next ``$``, are what it prints, and are
  compared with what it does print (see *Matching*).  A command without
  lines under it must only succeed.  ``$ ttt-sm debug`` followed by
  ``(ttt-sm) COMMAND`` lines is a debugger session: the commands are its
  script, and the block is compared with the session's transcript (if it
  shows any output at all; a block of commands alone must run without an
  ``error:`` line);
- ``sh``: every line is a command (``# comments`` dropped), run as above;
- ``python``: run in the page's namespace (blocks of a page share it, in
  order), or as a doctest when it holds ``>>>`` lines;
- ``yaml`` with ``steps:``: a scenario, loaded and checked (names, units,
  conditions) against the charts; ``json``: parsed;
- anything else (formulas, grammars, a command's synopsis, file formats):
  text, not run, and counted in the report.  A text block may not hold what
  would run elsewhere (``>>>`` examples belong in a ``python`` block, a
  ``$ `` command in a transcript), nor follow prose that ends in "prints"
  without the marker that compares it (below).

Matching: line by line after collapsing runs of spaces; ``...`` alone on a
line stands for any number of lines, ``...`` inside a line for any text
(doctest's ELLIPSIS); every number must equal the printed one, unless the
block allows a tolerance.  A last line ``(exit status N)`` states the
command's exit status (default 0).  Standard error follows standard output.

Markers are HTML comments outside the code blocks (GitHub does not show them):

- ``<!-- doc-test: skip: REASON -->`` before a block: not run, and the reason
  is reported (a command that takes minutes, a server that runs until Ctrl-C);
- ``<!-- doc-test: run by tests/PATH.py -->`` before a block: another test runs
  it (that file must exist and name the page);
- ``<!-- doc-test: numbers within 2% -->`` or ``within 0.05`` before a block:
  printed numbers may differ by that much (relative or absolute);
- ``<!-- doc-test: printed by the block above -->`` before a text block: it is
  what the ``python`` block before it prints, compared as a transcript is;
- ``<!-- doc-test: file NAME -->`` before a block: the block is a file the
  reader saves as NAME (a scenario of their own, one with mistakes in it);
  it is written to the scratch folder for the commands below it, and not
  checked itself (they show what the program says of it);
- ``<!-- check: CONDITION -->`` after a debugger session: a claim the prose
  makes, written in the condition language of scenarios and ``break when``
  (``abs(q_true[1] - 170deg) < 0.5deg``, ``DriveInit1.direction == -1``),
  must hold where the session ended.

Every path the prose names (``docs/x.md``, ``tests/...yaml``, a relative
link) must exist.

Commands run in the test's process (``ttt_sm.cli.main``) in a scratch folder
that links the repository's ``tests``, ``charts`` and ``src``; what they write
(``out/...``) stays there.
"""

from __future__ import annotations

import contextlib
import doctest
import io
import json
import math
import os
import re
import shlex
import subprocess
import sys
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
PROMPT = "(ttt-sm) "
LINKED = ("tests", "charts", "src")

_FENCE = re.compile(r"^( *)```(\S*)\s*$")  # a fence may be indented (a block in a list item)
_BLOCKS = re.compile(r"^ *```.*?^ *```", re.S | re.M)
_MARKER = re.compile(r"<!--\s*(doc-test|check):\s*(.*?)\s*-->", re.S)
_NUMBER = re.compile(r"(?<![A-Za-z_\d.])[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")
_EXIT = re.compile(r"^\(exit status (\d+)\)$")
_LINK = re.compile(r"\]\(([^)#\s]+)(?:#[^)\s]*)?\)")
_PATH = re.compile(r"(?<![\w/.-])(?:docs|src|tests|charts|scripts)/[\w./-]+"
                   r"\.(?:md|py|yaml|yml|toml|svg|png|json|txt|sh)\b")
_INLINE_COMMAND = re.compile(r"`((?:\.venv/bin/)?ttt-sm [^`]+)`")


class DocError(AssertionError):
    """Something a page says that is not so (or a marker that cannot be read): ``page:line: what``."""


@dataclass
class Block:
    """A fenced code block: its info string, first line number (1-based, of the code) and lines."""

    info: str
    line: int
    lines: list[str]
    markers: list[str] = field(default_factory=list)  # doc-test markers just before it
    checks: list[tuple[int, str]] = field(default_factory=list)  # check markers after it, with lines
    lead: str = ""  # the last line of prose before it ("prints", "Run it:")


@dataclass
class Report:
    """What a page's run did, for the summary."""

    page: str
    commands: int = 0
    debugger_commands: int = 0
    python_blocks: int = 0
    doctest_examples: int = 0
    scenarios_checked: int = 0
    json_checked: int = 0
    outputs_compared: int = 0
    checks: int = 0
    paths: int = 0
    parsed_only: int = 0
    files_written: int = 0
    text_blocks: int = 0
    run_elsewhere: list[str] = field(default_factory=list)
    skipped: list[str] = field(default_factory=list)

    def line(self) -> str:
        parts = [f"{self.commands} commands", f"{self.debugger_commands} debugger commands",
                 f"{self.python_blocks} python blocks", f"{self.doctest_examples} doctest examples",
                 f"{self.scenarios_checked} scenarios loaded", f"{self.json_checked} JSON parsed",
                 f"{self.outputs_compared} outputs compared", f"{self.checks} checks",
                 f"{self.paths} paths found", f"{self.parsed_only} commands parsed, not run",
                 f"{self.files_written} files written", f"{self.text_blocks} text blocks (not code)"]
        text = f"{self.page}: " + ", ".join(parts)
        if self.run_elsewhere:
            text += f"; run by other tests: {', '.join(self.run_elsewhere)}"
        if self.skipped:
            text += f"; not run: {'; '.join(self.skipped)}"
        return text


def read_blocks(text: str, page: str) -> list[Block]:
    """The fenced blocks of a page with the markers that belong to them."""
    blocks: list[Block] = []
    outside: list[tuple[int, str]] = []  # (line, text) outside the fences
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if m is None:
            outside.append((i + 1, lines[i]))
            i += 1
            continue
        indent = len(m.group(1))
        j = i + 1
        while j < len(lines) and not lines[j].lstrip(" ").startswith("```"):
            j += 1
        if j == len(lines):
            raise DocError(f"{page}:{i + 1}: a code block that is never closed")
        code = [line[indent:] if not line[:indent].strip() else line.lstrip(" ") for line in lines[i + 1:j]]
        prose = [t.strip() for _, t in outside if t.strip() and not _MARKER.fullmatch(t.strip())]
        blocks.append(Block(m.group(2), i + 2, code, lead=prose[-1] if prose else ""))
        outside.append((i + 1, "\0BLOCK"))
        i = j + 1
    # Markers: a doc-test marker belongs to the next block, a check to the previous one.
    text_out = "\n".join(t for _, t in outside)
    line_of = [n for n, _ in outside]
    index = 0
    for m in _MARKER.finditer(text_out):
        at = text_out.count("\n", 0, m.start())
        before = text_out.count("\0BLOCK", 0, m.start())
        kind, body = m.group(1), " ".join(m.group(2).split())
        if kind == "doc-test":
            if before >= len(blocks):
                raise DocError(f"{page}:{line_of[at]}: a doc-test marker with no code block after it")
            blocks[before].markers.append(body)
        else:
            if before == 0:
                raise DocError(f"{page}:{line_of[at]}: a check with no code block before it")
            blocks[before - 1].checks.append((line_of[at], body))
        index += 1
    return blocks


# -- matching ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class Tolerance:
    """How far a printed number may be from the page's: relative or absolute (0: equal)."""

    rel: float = 0.0
    abs: float = 0.0

    @classmethod
    def parse(cls, text: str, where: str) -> Tolerance:
        m = re.fullmatch(r"numbers within ([\d.]+)(%?)", text)
        if m is None:
            raise DocError(f"{where}: unknown doc-test marker {text!r}; markers: 'skip: REASON',"
                           " 'run by tests/PATH.py', 'numbers within 2%' or 'numbers within 0.05'")
        value = float(m.group(1))
        return cls(rel=value / 100) if m.group(2) else cls(abs=value)

    def same(self, expected: str, actual: str) -> bool:
        a, b = float(expected), float(actual)
        if a == b:
            return True
        return math.isfinite(a) and math.isfinite(b) and abs(a - b) <= max(self.abs, self.rel * abs(a))


def _normal(line: str) -> str:
    return " ".join(line.split())


def _line_pattern(expected: str) -> tuple[re.Pattern[str], list[str]]:
    """A regular expression for a page's line (its numbers captured), and those numbers."""
    parts: list[str] = []
    numbers: list[str] = []
    pos = 0
    for m in re.finditer(r"\.\.\.|" + _NUMBER.pattern, expected):
        parts.append(re.escape(expected[pos:m.start()]))
        if m.group() == "...":
            parts.append(".*?")
        else:
            parts.append(f"({_NUMBER.pattern})")
            numbers.append(m.group())
        pos = m.end()
    parts.append(re.escape(expected[pos:]))
    return re.compile("".join(parts)), numbers


def line_matches(expected: str, actual: str, tol: Tolerance) -> bool:
    """One line of a page against one printed line: ``...`` for any text, numbers within ``tol``."""
    exp, act = _normal(expected), _normal(actual)
    if exp == act:
        return True
    pattern, wanted = _line_pattern(exp)
    m = pattern.fullmatch(act)
    if m is None:
        return False
    return all(tol.same(w, g) for w, g in zip(wanted, m.groups(), strict=True))


def first_mismatch(expected: Sequence[str], actual: Sequence[str], tol: Tolerance) -> tuple[int, int] | None:
    """None when the printed lines match the page's, else (page line index, printed line index) where
    matching failed furthest in."""
    best = (0, 0)
    seen: set[tuple[int, int]] = set()

    def go(i: int, j: int) -> bool:
        nonlocal best
        if (i, j) in seen:
            return False
        seen.add((i, j))
        if (i, j) > best:
            best = (i, j)
        if i == len(expected):
            return j == len(actual)
        if expected[i].strip() == "...":
            return any(go(i + 1, k) for k in range(j, len(actual) + 1))
        return j < len(actual) and line_matches(expected[i], actual[j], tol) and go(i + 1, j + 1)

    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10_000))
    return None if go(0, 0) else best


# -- running -----------------------------------------------------------------------------------


@dataclass
class Printed:
    out: str
    status: int


class PageRunner:
    """Runs one page's blocks in order, in a scratch folder; raises :class:`DocError` at a false claim."""

    def __init__(self, page: Path, scratch: Path) -> None:
        self.page = page
        self.name = f"docs/{page.name}" if page.parent == DOCS else page.name
        self.scratch = scratch
        self.namespace: dict[str, Any] = {"__name__": f"doc_{page.stem}"}
        self.report = Report(self.name)
        self.debugger: Any = None  # the last debugger session's Debugger
        self.printed: tuple[int, str] | None = None  # the last python block: its line, what it printed

    def where(self, line: int) -> str:
        return f"{self.name}:{line}"

    def run(self) -> Report:
        for name in LINKED:
            link = self.scratch / name
            if not link.exists():
                link.symlink_to(ROOT / name)
        text = self.page.read_text(encoding="utf-8")
        self.paths(text)
        self.inline_commands(text)
        with _chdir(self.scratch):
            for block in read_blocks(text, self.name):
                self.block(block)
        return self.report

    def inline_commands(self, text: str) -> None:
        """Commands written in the prose (`ttt-sm ...`) are not run, but must parse: known options and
    values of the right kind (a command named without its required arguments is a mention)."""
        prose = _BLOCKS.sub("", text)
        for m in _INLINE_COMMAND.finditer(" ".join(prose.split("\n"))):
            command = m.group(1)
            if any(c in command for c in "[]|<>") or "..." in command \
                    or any(re.fullmatch(r"[A-Z][A-Z0-9_,]*", w) for w in command.split()):
                continue  # a synopsis (ttt-sm ik X Y Z, --commands FILE), not a command
            line = text.count("\n", 0, text.find(command.split()[-1])) + 1
            self.parse_only(command, line)

    def parse_only(self, command: str, line: int) -> None:
        words = shlex.split(command)
        error = _parse(words[1:])
        if error and ("the following arguments are required" in error
                      or (words[-1].startswith("-") and "expected one argument" in error)):
            error = None  # `ttt-sm draw`, `ttt-sm ai move --board` name a command or an option
        if error:
            raise DocError(f"{self.where(line)}: `{command}` is not a command ttt-sm takes: {error}")
        self.report.parsed_only += 1

    def paths(self, text: str) -> None:
        """Every repository path and relative link in the prose names something that exists (a marker's
        path is the marker's to check)."""
        prose = _MARKER.sub("", _BLOCKS.sub("", text))
        for m in _LINK.finditer(prose):
            target = m.group(1)
            if "://" in target or target.startswith(("mailto:", "#")):
                continue
            if not (self.page.parent / target).exists():
                line = text.count("\n", 0, text.find(m.group(0))) + 1
                raise DocError(f"{self.where(line)}: the link {target!r} leads nowhere")
            self.report.paths += 1
        for m in _PATH.finditer(prose):
            path = m.group(0).rstrip(".,;:)")
            if any(c in path for c in "<>*{}") or "..." in path:
                continue
            if not (ROOT / path).exists():
                line = text.count("\n", 0, text.find(m.group(0))) + 1
                raise DocError(f"{self.where(line)}: {path} does not exist")
            self.report.paths += 1

    def block(self, block: Block) -> None:
        where = self.where(block.line - 1)
        tol = Tolerance()
        action = None
        for marker in block.markers:
            if marker.startswith("numbers within"):
                tol = Tolerance.parse(marker, where)
            elif marker.startswith(("skip:", "run by ", "file ")) or marker == "printed by the block above":
                if action is not None:
                    raise DocError(f"{where}: {action!r} and {marker!r}: one of them")
                action = marker
            else:
                Tolerance.parse(marker, where)  # names the markers there are
        if action is not None and action.startswith("skip:"):
            reason = action[len("skip:"):].strip()
            if not reason:
                raise DocError(f"{where}: 'doc-test: skip:' needs a reason")
            self.report.skipped.append(f"line {block.line}: {reason}")
            for k, command in _commands(block):  # not run, but they must parse
                if re.match(r"(\.venv/bin/)?ttt-sm ", command):
                    self.parse_only(command, block.line + k)
            return
        if action is not None and action.startswith("run by "):
            test = action[len("run by "):].strip()
            path = ROOT / test
            if not path.is_file() or self.page.name not in path.read_text(encoding="utf-8"):
                raise DocError(f"{where}: 'run by {test}': no such test file naming {self.page.name}")
            self.report.run_elsewhere.append(f"line {block.line} by {test}")
            return
        if action is not None and action.startswith("file "):
            self.save(block, action[len("file "):].strip(), where)
            return
        if action == "printed by the block above":
            if self.printed is None:
                raise DocError(f"{where}: 'printed by the block above', but no python block ran before it")
            line, out = self.printed
            self.compare(block.lines, out.splitlines(), block.line - 1, f"the python block on line {line}", tol)
            return
        kind = classify(block)
        if kind == "transcript":
            self.transcript(block, tol)
        elif kind == "sh":
            for k, command in _commands(block):
                self.command(command, [], block.line + k, tol)
        elif kind == "python":
            self.python(block)
        elif kind == "scenario":
            self.scenario(block)
        elif kind == "json":
            try:
                json.loads("\n".join(block.lines))
            except ValueError as exc:
                raise DocError(f"{self.where(block.line)}: this JSON does not parse: {exc}") from None
            self.report.json_checked += 1
        else:
            self.text(block)
        if block.checks:
            self.check(block)

    def save(self, block: Block, name: str, where: str) -> None:
        """A file the reader saves: written to the scratch folder, where the commands below read it."""
        path = Path(name)
        if not name or path.is_absolute() or ".." in path.parts:
            raise DocError(f"{where}: 'file {name}': a file name inside the folder the commands run in")
        target = self.scratch / path
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text("\n".join(block.lines) + "\n", encoding="utf-8")
        self.report.files_written += 1

    def text(self, block: Block) -> None:
        """A block that is not run: it may not hold what would run in another block, nor be what the prose
        says a block above prints (``... prints``) without being compared with it."""
        if re.search(r"\bprints:?$", block.lead):
            raise DocError(f"{self.where(block.line - 1)}: the page says this is what is printed, but nothing"
                           " compares it: put '<!-- doc-test: printed by the block above -->' before it (after a"
                           " python block), or show the command as a transcript ('$ ...')")
        for k, line in enumerate(block.lines):
            if line.lstrip().startswith(">>> "):
                raise DocError(f"{self.where(block.line + k)}: a '>>>' example in a block that does not run:"
                               " write it in a ```python block (a doctest)")
            if line.startswith("$ "):
                raise DocError(f"{self.where(block.line + k)}: a '$ ' command in a ```{block.info} block:"
                               " a transcript is a ``` or ```sh block")
        self.report.text_blocks += 1

    # -- transcripts ------------------------------------------------------------------------

    def transcript(self, block: Block, tol: Tolerance) -> None:
        starts = [k for k, line in enumerate(block.lines) if line.startswith("$ ")]
        if starts[0] != 0:
            raise DocError(f"{self.where(block.line)}: a transcript starts with its '$ ' command")
        for a, b in zip(starts, [*starts[1:], len(block.lines)], strict=True):
            command = block.lines[a][2:]
            shown = block.lines[a + 1:b]
            while shown and not shown[-1].strip():
                shown.pop()
            self.command(command, shown, block.line + a, tol)

    def command(self, command: str, shown: list[str], line: int, tol: Tolerance) -> None:
        words = shlex.split(command)
        status_line = shown and _EXIT.match(shown[-1].strip())
        status = int(status_line.group(1)) if status_line else 0
        if status_line:
            shown = shown[:-1]
        session = [s[len(PROMPT):] for s in shown if s.startswith(PROMPT)]
        if words[0] in ("ttt-sm", ".venv/bin/ttt-sm"):
            if words[1:2] == ["debug"] and session:
                printed = self.debug_session(words[1:], session)
                self.report.debugger_commands += len(session)
                if all(s.startswith(PROMPT) for s in shown):  # commands alone: they must run
                    errors = [s for s in printed.out.splitlines() if s.startswith("error: ")]
                    if errors:
                        raise DocError(f"{self.where(line)}: the session printed {errors[0]!r}")
                    shown = []
            else:
                printed = _in_process(words[1:])
        elif words[0] in (".venv/bin/python", "python"):
            done = subprocess.run([sys.executable, *words[1:]], capture_output=True, text=True, timeout=600,
                                  check=False)
            printed = Printed(done.stdout + done.stderr, done.returncode)
        else:
            raise DocError(f"{self.where(line)}: cannot run {words[0]!r} here; mark the block"
                           " '<!-- doc-test: skip: REASON -->'")
        self.report.commands += 1
        if printed.status != status:
            raise DocError(f"{self.where(line)}: `{command}` exited with status {printed.status}, the page"
                           f" says {status}; it printed:\n{_tail(printed.out)}")
        if shown:
            self.compare(shown, printed.out.splitlines(), line, command, tol)

    def debug_session(self, argv: list[str], commands: list[str]) -> Printed:
        from ttt_sm.debug.shell import DebugShell

        script = self.scratch / "session.txt"
        script.write_text("\n".join(commands) + "\n", encoding="utf-8")
        shells: list[Any] = []
        original = DebugShell.run_script

        def keep(shell: Any, lines: Any) -> None:
            shells.append(shell)
            original(shell, lines)

        DebugShell.run_script = keep  # type: ignore[method-assign]
        try:
            printed = _in_process([*argv, "--commands", str(script)])
        finally:
            DebugShell.run_script = original  # type: ignore[method-assign]
        self.debugger = shells[-1].dbg if shells else None
        lines = printed.out.splitlines()
        if lines and lines[-1] == "(end of commands)":  # a script's end; a person types quit or Ctrl-D
            lines.pop()
        return Printed("\n".join(lines) + "\n", printed.status)

    def compare(self, shown: list[str], printed: list[str], line: int, command: str, tol: Tolerance) -> None:
        self.report.outputs_compared += 1
        printed = list(printed)
        while printed and not printed[-1].strip():  # a closing blank line is not worth a line of the page
            printed.pop()
        miss = first_mismatch(shown, printed, tol)
        if miss is None:
            return
        i, j = miss
        if i < len(shown):
            said = f"the page says {shown[i].strip()!r}"
            got = f"it printed {printed[j].strip()!r}" if j < len(printed) else "it printed nothing more"
            raise DocError(f"{self.where(line + 1 + i)}: `{command}`: {said}, {got}"
                           f" (printed line {j + 1})")
        raise DocError(f"{self.where(line + len(shown))}: `{command}` printed more than the page shows:"
                       f" {printed[j].strip()!r} (end with a '...' line to leave the rest out)")

    # -- python, scenarios, checks ----------------------------------------------------------

    def python(self, block: Block) -> None:
        source = "\n".join(block.lines) + "\n"
        if any(line.lstrip().startswith(">>> ") for line in block.lines):
            test = doctest.DocTestParser().get_doctest(source, self.namespace, self.name, self.name, block.line - 1)
            out = io.StringIO()
            runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
            result = runner.run(test, out=out.write, clear_globs=False)
            if result.failed:
                raise DocError(f"{self.where(block.line)}: a doctest example fails:\n{out.getvalue()}")
            self.report.doctest_examples += result.attempted
        else:
            code = compile(source, f"{self.name}:{block.line}", "exec")
            out = io.StringIO()
            with contextlib.redirect_stdout(out):
                exec(code, self.namespace)  # noqa: S102 - the repository's own docs
            self.printed = (block.line, out.getvalue())
        self.report.python_blocks += 1

    def scenario(self, block: Block) -> None:
        from ttt_sm.scenario import ScenarioError, load_scenario_text

        try:
            load_scenario_text("\n".join(block.lines) + "\n", f"{self.name}:{block.line}")
        except ScenarioError as exc:
            raise DocError(f"{self.where(block.line)}: this scenario does not load: {exc}") from None
        self.report.scenarios_checked += 1

    def check(self, block: Block) -> None:
        from ttt_sm.debug.errors import DebugError
        from ttt_sm.debug.expr import parse_condition
        from ttt_sm.debug.names import RobotNames

        if self.debugger is None:
            raise DocError(f"{self.where(block.checks[0][0])}: a check after a block that is no debugger session")
        dbg = self.debugger
        names = RobotNames(lambda: dbg.robot)
        for line, text in block.checks:
            try:
                holds = parse_condition(text, names).evaluate(names)
            except DebugError as exc:
                raise DocError(f"{self.where(line)}: check {text!r}: {exc}") from None
            if not holds:
                values = "; ".join(f"{ref} = {_value(names, ref)}" for ref in _refs(text))
                raise DocError(f"{self.where(line)}: the page claims {text!r}, which is false where the"
                               f" session above ended (t = {dbg.robot.t:.4f} s): {values}")
            self.report.checks += 1


def _commands(block: Block) -> list[tuple[int, str]]:
    """The commands of a transcript or ``sh`` block, with their line offsets."""
    kind = classify(block)
    if kind == "transcript":
        return [(k, line[2:]) for k, line in enumerate(block.lines) if line.startswith("$ ")]
    if kind == "sh":
        return [(k, line.split(" #", 1)[0].strip()) for k, line in enumerate(block.lines)
                if line.split(" #", 1)[0].strip() and not line.lstrip().startswith("#")]
    return []


def _parse(argv: list[str]) -> str | None:
    """None if ``ttt-sm`` parses the arguments, else argparse's complaint."""
    from ttt_sm.cli import build_parser
    from ttt_sm.cli.common import join_negative_values

    parser = build_parser()
    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            parser.parse_args(join_negative_values(parser, argv))
    except SystemExit as exc:
        if exc.code:
            return err.getvalue().strip().splitlines()[-1] if err.getvalue().strip() else f"exit {exc.code}"
    return None


def classify(block: Block) -> str:
    """transcript, sh, python, scenario, json, or text."""
    if block.lines and block.lines[0].startswith("$ ") and block.info in ("", "console", "shell", "sh"):
        return "transcript"
    if block.info == "sh":
        return "sh"
    if block.info == "python":
        return "python"
    if block.info == "yaml" and any(line.startswith("steps:") for line in block.lines):
        return "scenario"
    if block.info == "json":
        return "json"
    return "text"


def _in_process(argv: list[str]) -> Printed:
    from ttt_sm.cli import main

    out = io.StringIO()
    err = io.StringIO()
    stdin = sys.stdin
    sys.stdin = io.StringIO("")  # no terminal: a command that reads commands reads none
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                status = main(argv)
            except SystemExit as exc:  # argparse
                status = int(exc.code or 0)
    finally:
        sys.stdin = stdin
    return Printed(out.getvalue() + err.getvalue(), status)


def _refs(text: str) -> list[Any]:
    from ttt_sm.runtime.conditions import parse

    return list(dict.fromkeys(parse(text).refs))


def _value(names: Any, ref: Any) -> Any:
    return names.datum(ref.chart, ref.name) if ref.chart else names.signal(ref.name, ref.index)


def _tail(text: str, lines: int = 8) -> str:
    return "\n".join(text.splitlines()[-lines:])


@contextlib.contextmanager
def _chdir(path: Path) -> Iterator[None]:
    before = Path.cwd()
    os.chdir(path)
    try:
        yield
    finally:
        os.chdir(before)


def pages() -> list[Path]:
    """Every page of docs/."""
    return sorted(DOCS.glob("*.md"))
