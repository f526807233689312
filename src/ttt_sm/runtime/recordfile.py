"""A record written as it happens: JSON Lines, each line flushed, ended by a line that says how the run ended.

Every record ``ttt_sm`` writes while something runs (the debugger's and the
cockpit's trace, a scenario run's report and traces, the bench's results)
goes through :class:`RecordFile`:

- the file is opened before the run starts, so a folder that cannot take it
  is an ``OSError`` then, not after the work;
- each line is one JSON object (strict JSON, :mod:`.jsonable`), written and
  flushed when it happens, so whatever ends the process next (Ctrl-C,
  SIGTERM, a bug, the power) leaves every line written before it whole;
- the last line is an *ending*: ``{"event": "finished"}``, ``{"event":
  "interrupted", "signal": "SIGTERM", ...}`` or ``{"event": "error",
  "message": ...}``, with where the run stood (docs/reliability.md, "Records
  that survive").  A record whose last line is not an ending was cut short
  by something no program can answer (``kill -9``, the power): every line it
  has still parses;
- a line is written whole or not at all (:class:`~.files.LineSink`): when
  the disk is full the file is cut back to its last whole line, an ending
  ``{"event": "error", "message": "...No space left on device..."}`` is
  written if the space it freed takes it, and the write raises
  :class:`~.files.RecordWriteError` naming the file (:attr:`RecordFile.failed`
  keeps it); later writes do nothing;
- one process writes a record at a time: a second one is refused at once
  (:class:`~.files.RecordBusyError`).

:func:`read_lines` reads any such record back, and names the line that does
not parse, if one does not.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..files import LineSink, RecordWriteError
from .jsonable import dumps

#: The events that end a record.
ENDINGS = ("finished", "interrupted", "error")


class RecordFile:
    """A JSON Lines file written line by line, each line flushed; :meth:`end` writes its last line.

    Also a text sink (``write(text)``, ``flush()``) for a
    :class:`~.listeners.Trace`, which writes its records to it as they happen.
    """

    def __init__(self, path: str | Path, append: bool = False) -> None:
        """Start the file anew, or with ``append`` go on after the lines it holds."""
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._file: LineSink | None = LineSink(self.path, append=append)
        self.lines = 0
        #: The ending written (``"finished"``, ``"interrupted"``, ``"error"``), once :meth:`end` ran.
        self.ended: str | None = None
        #: Why the record stopped before its end (the disk full, say), or None.
        self.failed: RecordWriteError | None = None

    @property
    def closed(self) -> bool:
        return self._file is None

    def add(self, line: Mapping[str, Any]) -> None:
        """Append one JSON object as a line, and flush it (nothing once the record is closed)."""
        self.write(dumps(line) + "\n")

    def write(self, text: str) -> None:
        """Append text made of whole JSON lines, on disk when this returns (a :class:`~.listeners.Trace` sink).

        All of it or none: a write the disk refuses leaves the record at its
        last whole line, ended by an ``error`` line if that still fits, the
        record closed, and raises :class:`~.files.RecordWriteError` (also
        kept as :attr:`failed`).
        """
        if self._file is None:
            return
        try:
            self._file.write(text)
        except RecordWriteError as exc:
            self.failed = exc
            self._end_after_failure(exc)
            raise
        self.lines += text.count("\n")

    def _end_after_failure(self, exc: RecordWriteError) -> None:
        """The record's last line says the disk refused it, if the space freed by the cut takes that line."""
        assert self._file is not None
        try:
            self._file.write(dumps({"event": "error", "message": f"the record could not be written on: "
                                    f"{exc.strerror}", "errno": exc.errno}) + "\n")
            self.ended = "error"
            self.lines += 1
        except RecordWriteError:
            pass
        self.close()

    def flush(self) -> None:
        """Nothing to do: each :meth:`write` is on disk when it returns (a text sink's method)."""

    def end(self, how: str, **data: Any) -> None:
        """Write the ending line ``{"event": how, ...data}`` and close the file; only the first call writes."""
        if how not in ENDINGS:
            raise ValueError(f"a record ends with one of {', '.join(ENDINGS)}, not {how!r}")
        if self._file is None or self.ended is not None:
            return
        self.add({"event": how, **data})
        self.ended = how
        self.close()

    def close(self) -> None:
        """Close the file (without an ending: :meth:`end` writes one)."""
        if self._file is not None:
            self._file.close()
            self._file = None

    def __enter__(self) -> RecordFile:
        return self

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None, _tb: Any) -> None:
        """Leaving a ``with`` block ends the record: ``finished``, else how the run was stopped."""
        if exc is None:
            self.end("finished")
        else:
            how, data = ending_of(exc)
            self.end(how, **data)


def interruption(exc: BaseException) -> KeyboardInterrupt | None:
    """The Ctrl-C or SIGTERM behind `exc`: `exc` itself, or one it was raised while handling; else None.

    A signal that lands while a C extension initialises (numpy, OpenCV and
    matplotlib are imported when first needed) comes out of the import as
    ``ImportError: initialization failed``, the interruption only its context:
    the run was still interrupted, not broken.
    """
    seen: set[int] = set()
    link: BaseException | None = exc
    while link is not None and id(link) not in seen:
        if isinstance(link, KeyboardInterrupt):
            return link
        seen.add(id(link))
        link = link.__cause__ or link.__context__
    return None


def ending_of(exc: BaseException) -> tuple[str, dict[str, Any]]:
    """How an exception ends a record: ``("interrupted", {"signal": ...})`` or ``("error", {"message": ...})``.

    A :class:`KeyboardInterrupt` is an interruption (also as the context of
    another exception: :func:`interruption`); its ``signal``
    attribute (``"SIGTERM"``, set by the command line's handler) names the
    signal, else it was Ctrl-C (``"SIGINT"``).
    """
    interrupt = interruption(exc)
    if interrupt is not None:
        return "interrupted", {"signal": str(getattr(interrupt, "signal", "SIGINT"))}
    text = " ".join(str(exc).split())[:300]
    return "error", {"message": f"{type(exc).__name__}: {text}" if text else type(exc).__name__}


def read_lines(path: str | Path) -> list[dict[str, Any]]:
    """Every line of a record, parsed; a line that does not parse raises ValueError naming it."""
    lines = []
    with Path(path).open(encoding="utf-8") as f:
        for n, line in enumerate(f, 1):
            try:
                lines.append(json.loads(line))
            except json.JSONDecodeError as exc:
                raise ValueError(f"{path}:{n}: not a JSON line ({exc.msg})") from None
    return lines
