"""Live while writing (``ttt-sm gui --lab DIR``): the student's chart file watched, reloaded on every save.

::

    watcher thread:  stat the file a few times a second  --(it changed)-->  load it (app.chart_file)
        | it does not load, or does not fit the slot: the error (file:line) to every page; the robot runs on
        | it loads: the simulation thread builds the robot again from power-on with it in its slot,
        |           the diagrams draw it anew, every page hears of it ("lab" and "session" messages)
        v
    checks process:  python -m ttt_sm.lab.live DIR  (one JSON line per check, as each is decided)
        | each line to every page as it comes; the next good save ends a run still going

    simulation thread:  the chart raises while the robot runs it (Session.robot_raised)
        | the arm holds where it stands, the session pauses and stays; the error (file:line) to every page
        | the next good save builds the robot again and runs on if it was running

The checks run as a process of their own, at a lower priority: they take
seconds of CPU, and the simulation thread (and the pages) must not wait on
them.  Nothing here knows the lab's exercises: the command line reads the
folder and hands over a :class:`LabTask` (the file, its class, the slot,
the command that runs the checks).

What a page is sent is :meth:`LabWatch.state`, one ``{"type": "lab", ...}``
message, numbered (``version``) so that a page keeps only the newest.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import logging
import subprocess
import threading
import traceback
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..app.chart_file import ChartFileError, load_chart
from ..app.slots import THESIS_SLOTS, ChartSlots, SlotError
from ..debug.debugger import Debugger
from ..debug.replay import GameRecipe, RobotRecipe
from ..params import shown_path
from ..runner import one_line
from ..runtime import TickChart
from .catalogue import describe_session
from .diagrams import Diagrams
from .session import Session

log = logging.getLogger(__name__)

#: How often the file is looked at, s (a few times a second: a save shows within a fraction of one).
POLL_S = 0.2
#: How long a reload may wait for the simulation thread, s.
SWAP_TIMEOUT_S = 60.0


@dataclass(frozen=True)
class LabTask:
    """What the cockpit watches and how it judges it.

    ``chart_file`` holds class ``class_name``, which runs in slot ``slot``;
    ``checks_argv`` is a command that checks the file and prints one JSON
    line per check (:mod:`ttt_sm.lab.live`); ``title`` names the exercise.
    """

    title: str
    slot: str
    chart_file: Path
    class_name: str
    checks_argv: tuple[str, ...]


class ReloadError(RuntimeError):
    """A chart that loaded but could not be put in the robot: one line, ``file:line: ...``."""


def _file_key(path: Path) -> tuple[int, int, int] | None:
    """What changes when the file is saved (its inode for editors that save by renaming), None if absent."""
    try:
        st = path.stat()
    except OSError:
        return None
    return st.st_mtime_ns, st.st_size, st.st_ino


class LabWatch:
    """The student's chart, watched and reloaded into a :class:`Session`; its checks run on every good save."""

    def __init__(self, task: LabTask, poll_s: float = POLL_S) -> None:
        self.task = task
        self.poll_s = poll_s
        self.session: Session | None = None
        self.diagrams: Diagrams | None = None
        self._lock = threading.Lock()
        self._stopping = threading.Event()
        self._thread: threading.Thread | None = None
        self._seen = _file_key(task.chart_file)
        self._version = 0
        #: Saves seen, charts loaded (the diagram's version), the class running now and where it is written.
        self.saves = 0
        self.loads = 0
        self.running: tuple[str, str] | None = None
        self.error: str | None = None
        self._checks: dict[str, Any] = {"status": "none", "results": [], "error": None, "score": None, "of": 0}
        self._proc: subprocess.Popen[str] | None = None

    # -- before the session: the first load ---------------------------------------------------

    def first_slots(self) -> ChartSlots:
        """The slots to build the first robot with: the student's class, or the thesis' if it does not load yet."""
        try:
            cls, where, slots = self._load()
        except (ChartFileError, SlotError) as exc:
            self.error = str(exc)
            return THESIS_SLOTS
        self.loads = 1
        self.running = (cls.__name__, where)
        return slots

    def attach(self, session: Session, diagrams: Diagrams) -> None:
        """Reload into `session`, whose pages draw the charts with `diagrams` (``create_app`` calls it)."""
        self.session, self.diagrams = session, diagrams
        session.fault_listeners.append(self._robot_raised)

    # -- life -------------------------------------------------------------------------------

    def start(self) -> None:
        """Watch the file (a thread) and run the checks on the chart that loaded first, if it did."""
        if self._thread is not None:
            return
        if self.loads:
            self._start_checks()
        self._thread = threading.Thread(target=self._watch, name="ttt-sm-lab-watch", daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Stop watching; end a checks run still going."""
        self._stopping.set()
        if self._thread is not None:
            self._thread.join(10)
        self._end_checks()

    # -- what a page is sent ------------------------------------------------------------------

    def state(self) -> dict[str, Any]:
        """The ``lab`` message: the exercise, what runs, the last save's error, the checks so far."""
        with self._lock:
            checks = {**self._checks, "results": list(self._checks["results"])}
            version = self._version
        t = self.task
        running = (f"{self.running[0]} ({self.running[1]})" if self.running else
                   f"the thesis' {t.slot} (your {t.class_name} has not loaded yet)")
        return {"type": "lab", "version": version, "title": t.title, "slot": t.slot,
                "file": shown_path(t.chart_file), "class": t.class_name, "running": running,
                "saves": self.saves, "loads": self.loads, "error": self.error, "checks": checks}

    def _publish(self) -> None:
        with self._lock:
            self._version += 1
        if self.session is not None:
            self.session.broadcast(self.state())

    # -- the watcher thread ---------------------------------------------------------------------

    def _watch(self) -> None:
        while not self._stopping.wait(self.poll_s):
            key = _file_key(self.task.chart_file)
            if key == self._seen:
                continue
            self._seen = key
            try:
                self.reload()
            except Exception as exc:  # never let a save end the watching
                log.exception("the lab's reload failed")
                self.error = f"{shown_path(self.task.chart_file)}:1: the reload failed: {type(exc).__name__}: {exc}"
                self._publish()

    def reload(self) -> None:
        """Load the file again; if it loads and fits, rebuild the robot with it and run the checks."""
        self.saves += 1
        try:
            cls, where, slots = self._load()
            self._swap(cls, where, slots)
        except (ChartFileError, SlotError, ReloadError) as exc:
            self.error = str(exc)
            self._publish()
            return
        self.error = None
        self.loads += 1
        self.running = (cls.__name__, where)
        self._start_checks()  # publishes

    def _robot_raised(self, exc: BaseException) -> None:
        """The chart raised while the robot ran it (the simulation thread): where in the file, to every page."""
        file = shown_path(self.task.chart_file)
        line = _line_in(self.task.chart_file, exc)
        what = f"{type(exc).__name__}: {' '.join(str(exc).split()) or type(exc).__name__}"
        robot = self.session.debugger.robot if self.session is not None else None
        when = f" at t = {robot.t:.4f} s" if robot is not None else ""
        if line is None:  # not in the student's file: the cockpit's own error, said as such
            self.error = (f"{file}: the robot stopped{when}, not in your file: {what}; the arm holds where it"
                          f" stands: save to start again")
        else:
            self.error = (f"{file}:{line}: {what} (raised while the robot ran your chart{when}); the arm holds"
                          f" where it stands: save a fix to start again")
        self._publish()

    def _load(self) -> tuple[type[TickChart], str, ChartSlots]:
        t = self.task
        cls, where = load_chart(t.chart_file, t.class_name)
        try:
            slots = ChartSlots().with_chart(t.slot, cls, where)
        except SlotError:
            raise
        except Exception as exc:  # the library refused the class while its structure was read
            raise ChartFileError(f"{where}: {one_line(exc)}") from None
        return cls, where, slots

    def _swap(self, cls: type[TickChart], where: str, slots: ChartSlots) -> None:
        """In the simulation thread: a new robot from power-on with `cls` in the slot; the pages told."""
        session, diagrams, slot = self.session, self.diagrams, self.task.slot
        if session is None or diagrams is None:
            return

        def swap(dbg: Debugger) -> None:
            run_on = session.fault is not None and session.fault_while_running  # the fault paused the run
            old = dbg.recipe
            if not isinstance(old, (RobotRecipe, GameRecipe)):
                raise ReloadError(f"{where}: this session's robot cannot be built again (not the twin)")
            try:
                with session.robot_replaced(replaying=False):
                    dbg.start_over(dataclasses.replace(old, slots=slots))
            except Exception as exc:  # the student's class raised while the robot was built
                dbg.recipe = old
                line = _line_in(self.task.chart_file, exc) or 1
                raise ReloadError(f"{shown_path(self.task.chart_file)}:{line}: the robot could not be built with"
                                  f" {cls.__name__}: {one_line(exc)}") from None
            session.last_stop = None
            if run_on:
                session.mode = "running"
            session.chart_classes[slot] = cls
            session.info.update(describe_session(dbg))
            diagrams.replace(slot, cls)
            session.broadcast({"type": "session", "info": session.info})

        try:
            session.call(swap, timeout_s=SWAP_TIMEOUT_S)
        except TimeoutError:
            raise ReloadError(f"{where}: the simulation did not answer: the cockpit's session has stopped"
                              f" ({session.error or 'no reason given'})") from None

    # -- the checks process ------------------------------------------------------------------------

    def _start_checks(self) -> None:
        self._end_checks()
        proc = subprocess.Popen(list(self.task.checks_argv), stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                stdin=subprocess.DEVNULL, text=True, encoding="utf-8")
        with self._lock:
            self._proc = proc
            self._checks = {"status": "running", "results": [], "error": None, "score": None, "of": self.loads}
        self._publish()
        threading.Thread(target=self._read_checks, args=(proc,), name="ttt-sm-lab-checks", daemon=True).start()

    def _end_checks(self) -> None:
        with self._lock:
            proc, self._proc = self._proc, None
        if proc is not None and proc.poll() is None:
            proc.kill()
            with contextlib.suppress(subprocess.TimeoutExpired):
                proc.wait(10)

    def _read_checks(self, proc: subprocess.Popen[str]) -> None:
        assert proc.stdout is not None  # opened with a pipe
        ended = False
        for raw in proc.stdout:
            try:
                line = json.loads(raw)
            except ValueError:
                continue  # not one of ours (a library's print): not a check
            with self._lock:
                if self._proc is not proc:
                    return  # a newer save's run took over
                if line.get("type") == "check":
                    self._checks["results"].append({k: line.get(k) for k in ("name", "kind", "passed", "reason")})
                elif line.get("type") == "done":
                    self._checks.update(status="done", score=line.get("score"))
                    ended = True
                elif line.get("type") == "error":
                    self._checks.update(status="error", error=str(line.get("error")))
                    ended = True
            self._publish()
        status = proc.wait()
        with self._lock:
            if self._proc is not proc or ended:
                return
            self._checks.update(status="error", error=f"the checks ended without a result (exit status {status})")
        self._publish()


def _line_in(path: Path, exc: BaseException) -> int | None:
    """The line of `path` deepest in `exc`'s traceback (None if none of its frames is in that file)."""
    resolved = path.resolve()
    line = None
    for frame in traceback.extract_tb(exc.__traceback__):
        if frame.filename and Path(frame.filename).resolve() == resolved:
            line = frame.lineno or line
    return line

