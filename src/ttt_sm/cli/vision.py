"""``ttt-sm vision``: read a photo of the board, make simulated photos, measure the detector.

``ttt-sm vision detect IMAGE [--view far_edge] [--robot-marks TEXT] [--overlay OUT.png] [--json]``
locates the field in a photo and prints the cells (as the image shows them
and in board order) with their ink percentages.  A photo turned against the
view (its perspective shows it) or mirrored (the robot's marks, when given,
show it) is refused: read, it would put every symbol in the wrong cell.  So is
a photo whose handedness nothing establishes (no robot marks, or marks that a
mirror leaves in place) when a mirror would read another board.

``ttt-sm vision render OUT.png [--seed N] [--board TEXT] [--robot X|O]
[--shadow] [--dim D] [--json]`` saves a simulated camera photo of a random
board (or of the given one) and prints what is on it.

``ttt-sm vision bench [--photos N] [--seed N] [--json]`` runs the accuracy
and speed targets.

Errors (not an image, no field found, bad arguments) are one line on
standard error and exit status 2.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import cv2

from ..vision.errors import VisionError
from ..vision.orientation import VIEW_NAMES, board_text, board_values, establish_orientation
from .common import add_group, board_cells, print_json, seed


def register(sub: Any) -> argparse.ArgumentParser:
    """Add the ``vision`` command to the subcommands of ``ttt-sm`` (``build_parser``'s ``sub``)."""
    help_ = "read the board from a photo, make simulated camera photos (thesis 3.6.3; see docs/vision.md)"
    sp, actions = add_group(sub, "vision", help_)

    d = actions.add_parser("detect", help="locate the field in a photo and read its cells",
                           description="Locate the drawn field in a photo and read its 25 cells.")
    d.add_argument("image", metavar="IMAGE", help="photo of the board (PNG, JPEG, ...)")
    d.add_argument("--view", choices=VIEW_NAMES, default="far_edge",
                   help="where the camera stands, for the board order (default far_edge: beyond the far edge)")
    d.add_argument("--robot-marks", metavar="TEXT", type=board_cells, default=None,
                   help="the robot's marks, 25 characters in board order (X or O where it drew, . elsewhere;"
                        " rows may be split by /):"
                        " checks that the photo is neither turned nor mirrored")
    d.add_argument("--overlay", metavar="PNG", default=None, help="also save the photo with the located field")
    d.add_argument("--json", action="store_true", help="print one JSON document")
    d.set_defaults(func=cmd_vision_detect)

    r = actions.add_parser("render", help="save a simulated camera photo of a board",
                           description="Save a simulated camera photo: perspective, uneven light, blur, noise.")
    r.add_argument("out", metavar="OUT.png", help="where to save the photo")
    r.add_argument("--seed", type=seed, default=0, help="seed of the board, the camera and the light (default 0)")
    r.add_argument("--board", metavar="TEXT", default=None,
                   help="25 characters . X O in board order (row 1 first, rows may be split by /; default: a"
                        " random board)")
    r.add_argument("--robot", choices=["X", "O"], default="X", help="the robot's symbol for --board (default X)")
    r.add_argument("--shadow", action="store_true", help="cast the arm's shadow over the board")
    r.add_argument("--dim", type=float, default=None,
                   help="light on the dim side, 0.1..1 of the bright side (default: random)")
    r.add_argument("--json", action="store_true", help="print one JSON document")
    r.set_defaults(func=cmd_vision_render)

    b = actions.add_parser("bench", help="accuracy and time per frame on simulated photos",
                           description="Detect the cells of simulated photos: accuracy and time per frame.")
    b.add_argument("--photos", type=int, default=200, help=f"number of photos, 1..{MAX_PHOTOS} (default 200)")
    b.add_argument("--seed", type=seed, default=0, help="seed of the photo series (default 0)")
    b.add_argument("--json", action="store_true", help="print one JSON document")
    b.set_defaults(func=cmd_vision_bench)
    return sp


#: Most photos one ``vision bench`` takes (about 50 ms each).
MAX_PHOTOS = 10_000


def _picture_path(path: str, what: str) -> Path:
    """`path` if OpenCV can write a picture there (by its extension), else a VisionError naming `what`."""
    if not cv2.haveImageWriter(path):
        suffix = Path(path).suffix or "(none)"
        raise VisionError(f"{what} {path!r}: cannot write a picture with the extension {suffix!r}; use .png or .jpg")
    return Path(path)


def _write_picture(path: Path, image: Any, what: str) -> None:
    import errno

    from ..files import RecordWriteError, write_png

    try:
        write_png(path, image)  # whole, or not there (a full disk: the error names the file)
    except (ValueError, cv2.error):
        raise VisionError(f"{what} {str(path)!r}: could not encode the picture") from None
    except RecordWriteError as exc:
        if exc.errno != errno.ENOENT:
            raise  # a full disk, say: its one line names the file and what to do
        raise VisionError(f"{what} {str(path)!r}: could not write the picture (does the folder exist?)") from None


def _robot_marks(text: str) -> str:
    """``--robot-marks``: 25 marks X, O or . in board order (rows may be split by /), or a VisionError naming it."""
    marks = text.upper().replace("/", "")
    if len(marks) != 25 or set(marks) - {"X", "O", "."}:
        raise VisionError(f"--robot-marks {text[:80]!r}: expected 25 marks, X or O where the robot drew and ."
                          " elsewhere, in board order (row 1 first; rows may be split by /)")
    return marks


def _fail(exc: Exception) -> int:
    print(f"ttt-sm vision: error: {exc}", file=sys.stderr)
    return 2


def cmd_vision_detect(args: argparse.Namespace) -> int:
    """Detect the cells of one photo; exit 0, or 2 if it is not an image or shows no field."""
    from ..vision.camera import read_image
    from ..vision.detection import detect
    from ..vision.pictures import overlay

    try:
        out = _picture_path(args.overlay, "--overlay") if args.overlay else None
        marks = None if args.robot_marks is None else _robot_marks(args.robot_marks)
        image = read_image(args.image)
        det = detect(image)
        if out is not None:  # where the field was found, also when the board cannot be read from it
            _write_picture(out, overlay(image, det), "--overlay")
        note = establish_orientation(det.grid, det.cells, args.view, marks, str(args.image))
    except VisionError as exc:
        return _fail(exc)
    data = det.to_dict()
    data["image"] = str(args.image)
    data["view"] = args.view
    data["orientation"] = note
    data["board"] = board_text(det.cells, args.view)
    data["board_percentages"] = [round(v, 2) for v in board_values(det.percentages, args.view)]
    if out is not None:
        data["overlay"] = str(out)
    if args.json:
        print_json(data)
        return 0
    board = data["board"]
    print(f"{args.image}: field found in {det.time_ms:.1f} ms (fit {det.grid.rms_cells:.3f} cells RMS); {note}")
    print("as the image shows it      board (row 1 first, view " + args.view + ")")
    for k in range(5):
        row = det.cells[5 * k:5 * k + 5]
        pct = " ".join(f"{p:5.1f}" for p in det.percentages[5 * k:5 * k + 5])
        print(f"  {row}   {pct}      {board[5 * k:5 * k + 5]}")
    return 0


def cmd_vision_render(args: argparse.Namespace) -> int:
    """Save a simulated photo; exit 0, or 2 on a bad argument."""
    import numpy as np

    from ..twin.workspace import load_arm
    from ..vision.bench import random_shadow
    from ..vision.scenes import random_scene, scene_from_text
    from ..vision.simulated import Lighting, SimulatedCamera

    params = load_arm(args.params)
    try:
        out = _picture_path(args.out, "OUT")
        try:
            scene = (scene_from_text(params, args.board, args.robot, args.seed) if args.board is not None
                     else random_scene(params, args.seed))
        except ValueError as exc:
            raise VisionError(f"--board: {exc}") from None
        rng = np.random.default_rng(args.seed + 1)
        lighting = None
        if args.dim is not None:
            if not 0.1 <= args.dim <= 1.0:
                raise VisionError(f"--dim must lie in [0.1, 1], got {args.dim}")
            lighting = Lighting.random(rng, dim=(args.dim, args.dim))
        cam = SimulatedCamera(scene.board, params, seed=args.seed, lighting=lighting,
                              shadow=random_shadow(params, rng) if args.shadow else None)
        image = cam.frame()
        _write_picture(out, image, "OUT")
    except ValueError as exc:
        return _fail(exc)
    data = {"out": str(out), "board": scene.text, "robot_symbol": scene.robot_symbol, "view": cam.view(),
            "dim": round(cam.lighting.dim, 3), "roll_deg": round(cam.pose.roll_deg, 2),
            "position_m": [round(v, 4) for v in cam.pose.position_m]}
    if args.json:
        print_json(data)
    else:
        rows = "\n".join(f"  {scene.text[5 * k:5 * k + 5]}" for k in range(5))
        print(f"wrote {out} (view {data['view']}, dim side at {data['dim']:.2f}); the board:\n{rows}")
    return 0


def cmd_vision_bench(args: argparse.Namespace) -> int:
    """Run the vision benchmark; exit 0 if every cell was read right, 1 if not."""
    from ..twin.workspace import load_arm
    from ..vision.bench import bench_vision

    if not 1 <= args.photos <= MAX_PHOTOS:
        return _fail(VisionError(f"--photos must lie in 1..{MAX_PHOTOS}, got {args.photos}"))
    params = load_arm(args.params)

    def say(msg: str) -> None:
        print(msg, file=sys.stderr, flush=True)

    result = bench_vision(args.seed, args.photos, params, progress=say)
    if args.json:
        print_json(result)
    else:
        for k, v in result.items():
            print(f"  {k}: {v}")
    return 0 if result["vision_accuracy"] == 1.0 else 1
