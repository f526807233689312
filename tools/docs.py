"""``python -m tools.docs export|check`` (``make docs``): every generated file of the repository.

``export`` writes the chart diagrams in ``charts/`` (as ``ttt-sm charts
export`` does), ``docs/architecture.md`` with its pictures, and the firmware's
generated headers (``layout.h``, ``structs.h``, ``protocol.h``, ``arm_board.h``); ``check`` lists the
files that are stale and exits with status 1 if there are any.  Run it from the repository's root with the
repository's Python (``.venv/bin/python -m tools.docs check``) or pass
``--root``.  A development tool: the installed package does not carry it (the
wheel has no repository to write into).
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any, cast

from ttt_sm.cli.common import CliError, emit

from .architecture.layers import SOURCE_ROOT


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m tools.docs",
        description="regenerate every generated file (charts/, docs/architecture.md, the firmware's headers),"
                    " or check they are up to date")
    parser.add_argument("action", choices=["export", "check"])
    parser.add_argument("--root", default=".", help="the repository's root folder (default: the current folder)")
    parser.add_argument("--json", action="store_true", help="print one JSON document")
    return parser


def run(args: argparse.Namespace) -> int:
    """Export or check ``charts/``, ``docs/architecture.md`` and the firmware's generated sources under ``--root``."""
    from ttt_sm.charts import ALL_CHARTS
    from ttt_sm.cli.commands import REPO_CHART_FORMATS, repo_chart_extras
    from ttt_sm.hardware import generate
    from ttt_sm.runtime.export import export_command

    from .architecture import document

    root = Path(args.root)
    if not (root / "src" / "ttt_sm").is_dir():
        raise CliError(f"{root.resolve()} is not the root of the ttt_sm repository (no src/ttt_sm there); "
                       "run from it or pass --root")
    if (root / "src" / "ttt_sm").resolve() != SOURCE_ROOT:
        raise CliError(f"the ttt_sm in use is {SOURCE_ROOT}, not the one in {root.resolve()}: the pages would "
                       "show other code; run the Python of that repository (its .venv/bin/python)")
    charts = export_command(ALL_CHARTS, root / "charts", check=args.action == "check", formats=REPO_CHART_FORMATS,
                            extras=repo_chart_extras())
    if args.action == "check":
        stale = [*cast(list[str], charts["stale"]), *document.stale(root),
                 *(str(p) for p in generate.stale(root / "firmware"))]
        result: dict[str, Any] = {"root": str(root), "stale": stale, "ok": not stale}
        text = "every generated file is up to date" if not stale else \
            "stale (run `make docs`):\n" + "\n".join(f"  {f}" for f in stale)
        emit(result, args.json, text)
        return 0 if not stale else 1
    written = [*cast(list[str], charts["written"]), *(str(p) for p in document.export(root)),
               *(str(p) for p in generate.write(root / "firmware"))]
    emit({"root": str(root), "written": written}, args.json, "wrote:\n" + "\n".join(f"  {f}" for f in written))
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Run the tool; a problem is one line and status 2."""
    args = build_parser().parse_args(argv)
    try:
        return run(args)
    except CliError as exc:
        print(f"tools.docs: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
