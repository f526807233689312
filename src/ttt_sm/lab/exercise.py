"""The lab's exercises: what each asks a student to write, and the folder a student works in.

An exercise is a folder of the package (``ttt_sm/lab/exercises/<name>/``)::

    exercise.toml   what it is: the slot, the student's file and class, the checks' settings
    task.md         the task page: what to build, the thesis section, hints, what is checked
    <file>.py       the skeleton: a chart that loads, fits the slot, and fails the checks
    checks/*.yaml   scenario files the student's chart must pass (docs/scenarios.md)

``ttt-sm lab start EXERCISE DIR`` copies the folder to DIR; ``ttt-sm lab check
DIR`` reads DIR's ``exercise.toml`` and judges DIR's file (:mod:`.checks`).
"""

from __future__ import annotations

import shutil
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..app.slots import slot
from ..params import shown_path

#: Where the packaged exercises are.
EXERCISES = Path(__file__).parent / "exercises"
#: The file that makes a folder an exercise (and a student's folder one to check).
MANIFEST = "exercise.toml"


class LabError(ValueError):
    """An exercise or a student's folder that cannot be used: one line saying why and what to do."""


@dataclass(frozen=True)
class Exercise:
    """One exercise, read from its ``exercise.toml``.

    ``twin`` is the whole-robot check (``"init"``: initialise the drives;
    ``"draw_x"``: draw an X and measure it; ``""``: none); ``within_s`` its
    time bound; ``max_rms_mm`` the drawing's precision bound;
    ``coverage`` the share of the chart's transitions the checks must take,
    counting only those leaving ``coverage_states`` when that is given.
    """

    name: str
    folder: Path
    title: str
    slot: str
    section: str
    file: str
    class_name: str
    twin: str = ""
    within_s: float = 20.0
    max_rms_mm: float = 1.0
    coverage: float = 0.0
    coverage_states: tuple[str, ...] = ()
    seed: int = 0

    @property
    def chart_file(self) -> Path:
        return self.folder / self.file

    def scenario_files(self) -> list[Path]:
        return sorted((self.folder / "checks").glob("*.yaml"))


def _get(doc: dict[str, Any], key: str, kind: type, where: Path) -> Any:
    value = doc.get(key)
    if not isinstance(value, kind) or isinstance(value, bool) and kind is not bool:
        raise LabError(f"{shown_path(where)}: {key} must be a {kind.__name__}, got {value!r}")
    return value


def read_exercise(folder: Path) -> Exercise:
    """The exercise described by ``folder/exercise.toml``; a :class:`LabError` if it is missing or wrong."""
    manifest = folder / MANIFEST
    if not manifest.is_file():
        raise LabError(f"{shown_path(folder)}: no {MANIFEST} there: check a folder made by ttt-sm lab start")
    try:
        doc = tomllib.loads(manifest.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise LabError(f"{shown_path(manifest)}: {exc}") from None
    twin = doc.get("twin", {})
    cov = doc.get("coverage", {})
    exercise = Exercise(
        name=_get(doc, "name", str, manifest), folder=folder, title=_get(doc, "title", str, manifest),
        slot=_get(doc, "slot", str, manifest), section=_get(doc, "section", str, manifest),
        file=_get(doc, "file", str, manifest), class_name=_get(doc, "class", str, manifest),
        twin=str(twin.get("task", "")), within_s=float(twin.get("within_s", 20.0)),
        max_rms_mm=float(twin.get("max_rms_mm", 1.0)), coverage=float(cov.get("min_fraction", 0.0)),
        coverage_states=tuple(cov.get("states", ())), seed=int(doc.get("seed", 0)),
    )
    slot(exercise.slot)  # a slot that does not exist is the exercise's mistake: say so now
    if exercise.twin not in ("", "init", "draw_x"):
        raise LabError(f"{shown_path(manifest)}: twin.task must be 'init', 'draw_x' or absent, got {exercise.twin!r}")
    return exercise


def exercises() -> list[Exercise]:
    """Every packaged exercise, by name."""
    return [read_exercise(p) for p in sorted(EXERCISES.iterdir()) if (p / MANIFEST).is_file()]


def exercise(name: str) -> Exercise:
    """A packaged exercise by name; a :class:`LabError` lists the names there are."""
    found = {e.name: e for e in exercises()}
    if name not in found:
        raise LabError(f"no exercise {name!r}; exercises: {', '.join(found)} (ttt-sm lab list)")
    return found[name]


def start(name: str, folder: Path) -> Exercise:
    """Copy exercise `name` (task page, skeleton, checks) into `folder`, which must be empty or new."""
    ex = exercise(name)
    if folder.exists() and (not folder.is_dir() or any(folder.iterdir())):
        raise LabError(f"{shown_path(folder)} is not empty: start an exercise in a new or empty folder")
    shutil.copytree(ex.folder, folder, dirs_exist_ok=True, ignore=shutil.ignore_patterns("__pycache__"))
    return read_exercise(folder)
