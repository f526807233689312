"""Files a full disk cannot corrupt: whole lines or none, whole pictures or none, one writer per record.

Every file ``ttt_sm`` writes goes through this module:

- :class:`LineSink`: a JSON Lines record, appended line by line.  A write
  that fails (``ENOSPC``: the disk is full; ``EFBIG``: past the process's
  file-size limit; ``EIO``) cuts the file back to the end of its last whole
  line, so every line on disk parses, and raises :class:`RecordWriteError`,
  which names the file, why, and what to do.  The sink takes an exclusive
  lock on its file (``flock``): a second process that opens the same record
  is refused at once with :class:`RecordBusyError` instead of interleaving
  its lines with the first one's.
- :func:`write_atomic` (and :func:`write_png`, :func:`save_figure` for
  pictures, :func:`write_text`): the whole file is written under a
  temporary name in the same folder and renamed over the name asked for, so
  the name holds the whole new file or what was there before, never a
  0-byte or half picture.

docs/reliability.md, "Records on a full disk", says what each command does
then, and how it is tested on a real full file system.
"""

from __future__ import annotations

import errno
import fcntl
import io
import itertools
import os
import threading
from pathlib import Path
from typing import Any

#: The one-line advice for a write that failed, by errno (the CLI adds it after the path and the reason).
ADVICE = {
    errno.ENOSPC: "the disk is full: free some space or choose another path",
    errno.EDQUOT: "the disk quota is used up: free some space or choose another path",
    errno.EFBIG: "the file is larger than this process may write (ulimit -f): raise the limit or write less",
}

_counter = itertools.count()
_counter_lock = threading.Lock()


class RecordWriteError(OSError):
    """A record or a picture could not be written; ``filename`` is the file, ``strerror`` says what is on disk."""


class RecordBusyError(Exception):
    """A second writer of a record that a running process is writing now."""


def _shown(path: Path) -> str:
    text = str(path)
    return text if text.isprintable() and len(text) <= 200 else repr(text[:200])


def _busy(path: Path) -> RecordBusyError:
    return RecordBusyError(f"{_shown(path)} is being written by another ttt-sm process now: give this run another"
                           " file (or folder), or stop the other one first")


def refuse_if_busy(path: str | Path) -> None:
    """:class:`RecordBusyError` if a running process writes the record at ``path`` now (nothing is changed):
    a command says so before it builds anything, then :class:`LineSink` takes the lock for good."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_CLOEXEC)
    except OSError:  # not there (or not readable): nobody writes it, or opening it will say why
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        raise _busy(Path(path)) from None
    except OSError:
        pass
    finally:
        os.close(fd)


class LineSink:
    """A file of whole lines, appended one write at a time, locked against a second writer.

    ``append``: go on after the lines the file holds (a line cut short at its
    end is cut off first); else start the file anew.  :meth:`write` takes
    text made of whole lines (ending in a new line) and writes all of it or,
    when the disk refuses part of it, none (:class:`RecordWriteError`).
    """

    def __init__(self, path: str | Path, append: bool = False) -> None:
        self.path = Path(path)
        fd = os.open(self.path, (os.O_RDWR if append else os.O_WRONLY) | os.O_CREAT | os.O_CLOEXEC, 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise _busy(self.path) from None
        except OSError:  # a file system without locks: write on unlocked
            pass
        try:
            self._size = _whole_lines_end(fd) if append else 0
            os.ftruncate(fd, self._size)
        except OSError:
            os.close(fd)
            raise
        self._fd: int | None = fd
        #: Lines written (by this sink).
        self.lines = 0

    @property
    def closed(self) -> bool:
        return self._fd is None

    def write(self, text: str) -> None:
        """Append ``text`` (whole lines) in full, or nothing: :class:`RecordWriteError`, the file cut back."""
        if self._fd is None:
            raise ValueError(f"{self.path} is closed")
        if not text:
            return
        if not text.endswith("\n"):
            raise ValueError("a record is written a whole line at a time (the text must end in a new line)")
        data = memoryview(text.encode("utf-8"))
        done = 0
        try:
            while done < len(data):
                n = os.pwrite(self._fd, data[done:], self._size + done)
                if n <= 0:
                    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
                done += n
        except OSError as exc:
            try:
                os.ftruncate(self._fd, self._size)  # the half line goes: freeing space never fails for lack of it
            except OSError:
                pass
            raise self.error(exc) from None
        self._size += len(data)
        self.lines += text.count("\n")

    def error(self, exc: OSError) -> RecordWriteError:
        """The error naming this file for ``exc``, and what the file holds now."""
        kept = f"{self.lines} whole line{'s' if self.lines != 1 else ''} kept" if self.lines else "nothing kept"
        return RecordWriteError(exc.errno or errno.EIO, f"{exc.strerror or exc} ({kept}, no half line)",
                                str(self.path))

    def close(self) -> None:
        if self._fd is not None:
            fd, self._fd = self._fd, None
            os.close(fd)


def _whole_lines_end(fd: int) -> int:
    """Where the file's last whole line ends (a line cut short after it, by a kill, is left out)."""
    size = os.lseek(fd, 0, os.SEEK_END)
    pos = size
    while pos > 0:
        start = max(0, pos - 65536)
        chunk = os.pread(fd, pos - start, start)
        cut = chunk.rfind(b"\n")
        if cut >= 0:
            return start + cut + 1
        pos = start
    return 0


def write_atomic(path: str | Path, data: bytes | str) -> Path:
    """Write ``data`` to ``path`` whole, or leave ``path`` as it was (:class:`RecordWriteError`).

    The bytes go to a hidden temporary file in the same folder (``.NAME.PID-N.tmp``), which is
    renamed over ``path`` once all of them are written; a failed write removes it.
    """
    path = Path(path)
    blob = data.encode("utf-8") if isinstance(data, str) else bytes(data)
    with _counter_lock:
        n = next(_counter)
    tmp = path.with_name(f".{path.name}.{os.getpid()}-{n}.tmp")
    try:
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o666)
        except FileExistsError:  # left by a process killed at that moment, whose pid came round again
            tmp.unlink()
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o666)
        try:
            view = memoryview(blob)
            while view:
                n = os.write(fd, view)
                if n <= 0:
                    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
                view = view[n:]
        finally:
            os.close(fd)
        os.replace(tmp, path)
    except OSError as exc:
        try:
            tmp.unlink()
        except OSError:
            pass
        reason = f"{exc.strerror or exc}" + (" (not written)" if exc.errno in ADVICE else "")  # the disk's refusal
        raise RecordWriteError(exc.errno or errno.EIO, reason, str(path)) from None
    return path


def write_text(path: str | Path, text: str) -> Path:
    """:func:`write_atomic` of UTF-8 text."""
    return write_atomic(path, text)


def write_png(path: str | Path, image: Any, params: tuple[int, ...] | list[int] = ()) -> Path:
    """Encode an image (OpenCV's BGR array) in the format of ``path``'s extension, then :func:`write_atomic`.

    ``ValueError`` if OpenCV cannot encode it in that format.
    """
    import cv2

    path = Path(path)
    suffix = path.suffix.lower() or ".png"
    ok, encoded = cv2.imencode(suffix, image, list(params))
    if not ok:
        raise ValueError(f"{_shown(path)}: OpenCV could not encode the picture as {suffix}")
    return write_atomic(path, encoded.tobytes())


def save_figure(fig: Any, path: str | Path, **kwargs: Any) -> Path:
    """A matplotlib figure saved whole (in the format of ``path``'s extension), then :func:`write_atomic`."""
    path = Path(path)
    buf = io.BytesIO()
    fig.savefig(buf, format=kwargs.pop("format", None) or (path.suffix[1:].lower() or "png"), **kwargs)
    return write_atomic(path, buf.getvalue())


__all__ = ["ADVICE", "LineSink", "RecordBusyError", "RecordWriteError", "refuse_if_busy", "save_figure",
           "write_atomic", "write_png", "write_text"]
