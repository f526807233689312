"""``ttt-sm docs export|check``: every generated file of the repository, in one command.

``export`` writes the chart diagrams in ``charts/`` (as ``ttt-sm charts
export`` does), ``docs/architecture.md`` with its pictures and the
firmware's generated sources (``firmware/include/ttt_fw/layout.h``, as
``python -m ttt_sm.hardware.generate`` does); ``check``
lists the files that are stale and exits with status 1 if there are any.
Run it from the repository's root (or pass ``--root``).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any, cast

from ..architecture.layers import SOURCE_ROOT
from .common import CliError, add_command, emit


def register(sub: Any) -> None:
    """Add ``docs`` to the subcommands of ``ttt-sm``."""
    sp = add_command(sub, "docs", cmd_docs,
                     "regenerate every generated file (charts/, docs/architecture.md, the firmware's layout.h), or"
                     " check they are up to date")
    sp.add_argument("action", choices=["export", "check"])
    sp.add_argument("--root", default=".", help="the repository's root folder (default: the current folder)")


def cmd_docs(args: argparse.Namespace) -> int:
    """Export or check ``charts/``, ``docs/architecture.md`` and the firmware's generated sources under ``--root``."""
    from ..architecture import document
    from ..charts import ALL_CHARTS
    from ..hardware import generate
    from ..runtime.export import export_command
    from .commands import REPO_CHART_FORMATS, repo_chart_extras

    root = Path(args.root)
    if not (root / "src" / "ttt_sm").is_dir():
        raise CliError(f"{root.resolve()} is not the root of the ttt_sm repository (no src/ttt_sm there); "
                       "run from it or pass --root")
    if (root / "src" / "ttt_sm").resolve() != SOURCE_ROOT:
        raise CliError(f"the ttt_sm in use is {SOURCE_ROOT}, not the one in {root.resolve()}: the pages would "
                       "show other code; run the ttt-sm of that repository (its .venv/bin/ttt-sm)")
    charts = export_command(ALL_CHARTS, root / "charts", check=args.action == "check", formats=REPO_CHART_FORMATS,
                            extras=repo_chart_extras())
    if args.action == "check":
        stale = [*cast(list[str], charts["stale"]), *document.stale(root),
                 *(str(p) for p in generate.stale(root / "firmware"))]
        result: dict[str, Any] = {"root": str(root), "stale": stale, "ok": not stale}
        text = "every generated file is up to date" if not stale else \
            "stale (run `ttt-sm docs export`):\n" + "\n".join(f"  {f}" for f in stale)
        emit(result, args.json, text)
        return 0 if not stale else 1
    written = [*cast(list[str], charts["written"]), *(str(p) for p in document.export(root)),
               *(str(p) for p in generate.write(root / "firmware"))]
    emit({"root": str(root), "written": written}, args.json, "wrote:\n" + "\n".join(f"  {f}" for f in written))
    return 0
