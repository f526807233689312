"""The designed gains, kept: a parameter file's cascades are designed once per machine, not once per process.

Designing the three cascades (:func:`ttt_sm.twin.tuning.design_gains`, thesis
section 3.2) imports python-control and takes one to three seconds of CPU, and
every process that builds a robot needs them: each ``ttt-sm play``, each graded
submission, each test worker.  The design is a pure function of the parameters
and of the code and library versions that compute it, so its result is kept in
``$XDG_CACHE_HOME/ttt_sm/gains/<key>.json`` (``~/.cache`` by default) under a key
made of all of them: a changed parameter, a changed ``tuning.py`` or ``gains.py``,
another python-control, SciPy or NumPy gives another key, and the gains are
designed again.  The numbers are the design's to the last bit (each float is
kept as its hexadecimal text, ``float.hex``).  A cache that cannot be read or written
is passed by, never an error: the gains are then designed in the process.

``ttt-sm tune`` designs afresh (it is the design's own view).
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
import tempfile
from dataclasses import asdict
from functools import lru_cache
from importlib import metadata
from pathlib import Path

from ..params import ArmParams, user_cache
from .gains import DriveGains, Gains

#: The modules whose text is part of the key: the design and the data it fills in.
_DESIGN_SOURCES = ("tuning.py", "gains.py")
#: The libraries whose versions are part of the key.
_DESIGN_LIBRARIES = ("control", "scipy", "numpy")


def _version(library: str) -> str:
    try:
        return metadata.version(library)
    except metadata.PackageNotFoundError:
        return "absent"


def cache_key(params: ArmParams) -> str:
    """The key of `params`' gains: a SHA-256 over the parameters, the design's sources and library versions."""
    digest = hashlib.sha256(repr(params).encode())
    here = Path(__file__).parent
    for name in _DESIGN_SOURCES:
        digest.update(name.encode() + b"\0" + (here / name).read_bytes())
    for library in _DESIGN_LIBRARIES:
        digest.update(f"{library}={_version(library)}\0".encode())
    digest.update(sys.version.encode())
    return digest.hexdigest()


def _read(path: Path) -> Gains | None:
    try:
        drives = json.loads(path.read_text(encoding="utf-8"))["drives"]
        kept = tuple(DriveGains(**{k: float.fromhex(v) for k, v in d.items()}) for d in drives)
    except (OSError, ValueError, KeyError, TypeError):
        return None  # missing, half written by a killed process, or of another layout: design again
    return Gains(drives=kept) if len(kept) == 3 else None  # type: ignore[arg-type]


def _write(path: Path, gains: Gains) -> None:
    """Write `gains` whole or not at all (a temporary file renamed over the name)."""
    # each float as its hexadecimal text: exact, and a margin that is not there (NaN) stays one
    text = json.dumps({"drives": [{k: float(v).hex() for k, v in asdict(d).items()} for d in gains.drives]},
                      allow_nan=False)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".tmp-", suffix=".json")
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as f:
                f.write(text)
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
    except OSError:
        pass  # a read-only or full cache: the next process designs again


def kept_gains(params: ArmParams, preset: str = "ours", cache: Path | None = None) -> Gains:
    """The gains of a tuning preset for `params` (:func:`ttt_sm.twin.tuning.gains_for`): from the cache when kept.

    ``"ours"`` (the default, what the drives initialise with) is designed by
    :func:`ttt_sm.twin.tuning.design_gains`; ``"thesis"`` holds the thesis'
    hand-set gains with their margins measured.  Raises what the design raises
    (:class:`ttt_sm.twin.tuning.TuningError`) for parameters it cannot design
    for, or an unknown preset; nothing is kept then.
    """
    if cache is None:
        return _kept_default(params, preset)
    return _kept(params, preset, cache)


@lru_cache(maxsize=8)
def _kept_default(params: ArmParams, preset: str) -> Gains:
    return _kept(params, preset, user_cache("gains"))


def _kept(params: ArmParams, preset: str, cache: Path) -> Gains:
    path = cache / f"{preset}-{cache_key(params)}.json"
    gains = _read(path)
    if gains is None:
        from .tuning import gains_for  # python-control is imported only when a design is needed

        gains = gains_for(params, preset)
        _write(path, gains)
    return gains

