"""One view of the kinematics lab as a command: options -> query -> the view's document -> JSON, text or PNG.

``ttt-sm kinematics workspace|dh|race`` (:mod:`.kinematics`) and ``ttt-sm kinematics
trajectory|forces`` (:mod:`.kinematics_motion`) all run through :func:`view_command`.
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable
from typing import Any

from .common import CliError, print_json


def view_command(view: str, views: Callable[[], dict[str, Any]], query: Callable[[str, argparse.Namespace], dict],
                 text: Callable[[str, dict[str, Any]], str], draw: Callable[[str, dict[str, Any], str], None],
                 option_names: Callable[[str], str]) -> Callable[[argparse.Namespace], int]:
    """The command of one view: its document from ``views()[view]`` on the query the options make, printed as
    JSON (``--json``) or text, drawn into ``--png``; a bad value is a one-line :class:`CliError` naming the option.

    ``views`` is called when the command runs, so the web package loads only then.
    """
    def run(args: argparse.Namespace) -> int:
        from ..twin.workspace import load_arm
        from ..web.kinematics import KinematicsQueryError

        if args.png is not None and (not args.png.lower().endswith(".png") or os.path.isdir(args.png)):
            raise CliError(f"{view}: --png must name a .png file, got {args.png!r}")
        params = load_arm(args.params)
        try:
            data = views()[view](params, query(view, args))
        except (KinematicsQueryError, ValueError) as exc:
            raise CliError(f"{view}: {option_names(str(exc))}") from None
        if args.png:
            draw(view, data, args.png)
            print(f"kinematics {view}: wrote {args.png}", file=sys.stderr)
        if args.json:
            print_json(data)
        else:
            print(text(view, data))
        return 0

    return run
