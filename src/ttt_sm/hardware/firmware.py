"""Find the firmware's C sources and compile them with the system C compiler into a shared object.

The firmware is portable C99 (``firmware/src``, ``firmware/include``); the
PC builds it as a shared object to load with ctypes (:mod:`.native`), with
the warnings a firmware build must pass (:data:`CFLAGS`, warnings are
errors).  A build is cached by a SHA-256 of the sources, the flags and the
compiler's version, so a test session or an emulator compiles once.

Two precisions (``firmware/include/ttt_fw/real.h``): ``"float"``, what the
reference board runs (single-precision FPU), and ``"double"``, the PC's
float64 step operation for operation.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
from pathlib import Path
from typing import Literal

from ..params import user_cache

Precision = Literal["float", "double"]
PRECISIONS: tuple[Precision, ...] = ("float", "double")

#: The flags every firmware build passes: C99 and pedantic, every warning an
#: error, no silent float -> double promotion or narrowing (real.h).
CFLAGS: tuple[str, ...] = ("-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-Wdouble-promotion",
                           "-Wfloat-conversion", "-Wconversion", "-O2")
#: What the PC's shared object adds: position-independent code, a shared library.
SHARED_FLAGS: tuple[str, ...] = ("-fPIC", "-shared")

_ENV_SOURCES = "TTT_SM_FIRMWARE"


class FirmwareError(RuntimeError):
    """The firmware cannot be found or built: names what is missing or what the compiler said."""


#: The firmware's sources beside this module: in a source checkout a link to ``firmware/``, in an
#: installed wheel a copy (package data).
PACKAGED_SOURCES = Path(__file__).resolve().parent / "firmware_src"


def firmware_root() -> Path:
    """The firmware's folder: ``$TTT_SM_FIRMWARE``, else the sources the package carries (:data:`PACKAGED_SOURCES`)."""
    env = os.environ.get(_ENV_SOURCES)
    root = Path(env) if env else PACKAGED_SOURCES
    if not (root / "src").is_dir() or not (root / "include").is_dir():
        raise FirmwareError(f"no firmware sources at {root} (src/ and include/); reinstall ttt_sm, or set"
                            f" {_ENV_SOURCES} to the firmware/ folder of a source checkout")
    return root


def sources(root: Path | None = None) -> list[Path]:
    """The C files of the firmware's portable part (``src/*.c``), sorted."""
    root = firmware_root() if root is None else root
    return sorted((root / "src").glob("*.c"))


def compiler() -> str:
    """The system C compiler: ``$CC`` or ``cc``."""
    cc = os.environ.get("CC", "cc")
    if shutil.which(cc) is None:
        raise FirmwareError(f"no C compiler {cc!r} on PATH (install gcc or set CC)")
    return cc


def _compiler_version(cc: str) -> str:
    done = subprocess.run([cc, "--version"], capture_output=True, text=True, check=False)
    return done.stdout.splitlines()[0] if done.stdout else cc


def compile_command(precision: Precision, out: Path, root: Path | None = None) -> list[str]:
    """The compiler command line that builds the shared object `out` of the given precision."""
    if precision not in PRECISIONS:
        raise FirmwareError(f"precision must be one of {', '.join(PRECISIONS)}, got {precision!r}")
    root = firmware_root() if root is None else root
    define = ["-DTTT_FW_DOUBLE"] if precision == "double" else []
    return [compiler(), *CFLAGS, *SHARED_FLAGS, *define, f"-I{root / 'include'}",
            *(str(s) for s in sources(root)), "-o", str(out)]


def default_cache() -> Path:
    """Where builds are cached: ``$XDG_CACHE_HOME/ttt_sm/firmware`` (``~/.cache`` by default)."""
    return user_cache("firmware")


def build(precision: Precision = "float", cache: Path | None = None) -> Path:
    """Compile the firmware as a shared object (once per sources, flags and compiler) and return its path.

    Raises :class:`FirmwareError` with the compiler's messages when the
    build fails (a warning fails it too).
    """
    root = firmware_root()
    cache = default_cache() if cache is None else cache
    cc = compiler()
    digest = hashlib.sha256()
    for part in (precision, _compiler_version(cc), *CFLAGS, *SHARED_FLAGS):
        digest.update(part.encode() + b"\0")
    for path in sorted([*sources(root), *(root / "include").rglob("*.h")]):
        digest.update(path.relative_to(root).as_posix().encode() + b"\0" + path.read_bytes())
    out = cache / f"ttt_fw_{precision}_{digest.hexdigest()[:16]}.so"
    if out.exists():
        return out
    cache.mkdir(parents=True, exist_ok=True)
    partial = out.with_suffix(f".{os.getpid()}.tmp")
    command = compile_command(precision, partial, root)
    done = subprocess.run(command, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        partial.unlink(missing_ok=True)
        raise FirmwareError(f"the firmware ({precision}) does not build:\n$ {' '.join(command)}\n"
                            f"{done.stderr.strip()}")
    partial.replace(out)  # atomic: a concurrent build of the same sources writes the same file
    return out


def main(argv: list[str] | None = None) -> int:
    """``python -m ttt_sm.hardware.firmware [OUT_DIR]``: build both precisions (``make firmware``)."""
    import sys

    args = sys.argv[1:] if argv is None else argv
    out_dir = Path(args[0]) if args else Path("out/firmware")
    try:
        for precision in PRECISIONS:
            path = build(precision, out_dir)
            print(f"firmware ({precision}): {path}")
    except FirmwareError as e:
        print(f"firmware: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
