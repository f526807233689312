"""Pictures of what the detector saw: the located field over the photo, the rectified cells."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from ttt_sm.files import write_png
from ttt_sm.params import ArmParams

from .detection import CELL_MARGIN, CELL_PX, INK_LEVEL, Detection, ink_image, rectify, working_image

N = 5
GRID_BGR = (0, 170, 255)      # the located (drawn) lines, orange
BORDER_BGR = (255, 140, 0)    # the extrapolated outer edge, blue
CROSSING_BGR = (0, 0, 230)
OCCUPIED_BGR = (0, 150, 0)
EMPTY_BGR = (120, 120, 120)


def overlay(image: np.ndarray, detection: Detection, legend: bool = True) -> np.ndarray:
    """The photo with the located field drawn on it: lines, crossings, outer edge, each cell's reading.

    Orange: the 4 + 4 drawn lines as located; blue: the field's outer edge,
    extrapolated one cell beyond them; red dots: the 16 crossings; in each
    cell its character and ink percentage.  With `legend`, a box in the
    photo's corner farthest from the field says so (:data:`OVERLAY_LEGEND`).
    """
    out = image.copy() if image.ndim == 3 else cv2.cvtColor(image, cv2.COLOR_GRAY2BGR)
    g = detection.grid
    t = np.linspace(0.0, 5.0, 2)
    for k in range(N + 1):
        colour = BORDER_BGR if k in (0, N) else GRID_BGR
        for pts in (np.column_stack((np.full(2, k), t)), np.column_stack((t, np.full(2, k)))):
            p = np.round(g.field_to_image(pts) * 16).astype(np.int32)
            cv2.line(out, tuple(p[0]), tuple(p[1]), colour, 1, cv2.LINE_AA, shift=4)
    for u, v in g.crossings.reshape(-1, 2):
        cv2.circle(out, (int(round(u * 16)), int(round(v * 16))), 2 * 16, CROSSING_BGR, -1, cv2.LINE_AA, shift=4)
    centres = g.field_to_image(np.array([(c + 0.5, r + 0.82) for r in range(N) for c in range(N)]))
    for k, (u, v) in enumerate(centres):
        ch, pct = detection.cells[k], detection.percentages[k]
        colour = EMPTY_BGR if ch == "." else OCCUPIED_BGR
        label = f"{ch} {pct:.0f}%"
        (w, h), _ = cv2.getTextSize(label, cv2.FONT_HERSHEY_SIMPLEX, 0.42, 1)
        org = (int(u - w / 2), int(v + h / 2))
        cv2.putText(out, label, org, cv2.FONT_HERSHEY_SIMPLEX, 0.42, (255, 255, 255), 3, cv2.LINE_AA)
        cv2.putText(out, label, org, cv2.FONT_HERSHEY_SIMPLEX, 0.42, colour, 1, cv2.LINE_AA)
    if legend:
        _legend(out, g.corners)
    return out


#: What :func:`overlay`'s colours mean: (BGR, how it is drawn, what it is).
OVERLAY_LEGEND = (
    (GRID_BGR, "line", "the 4 + 4 drawn lines, as located"),
    (BORDER_BGR, "line", "the field's outer edge, one cell beyond"),
    (CROSSING_BGR, "dot", "the 16 crossings of the lines"),
    (OCCUPIED_BGR, "text", "in each cell: what was read, ink %"),
)


def legend_box(shape: tuple[int, ...], field_corners: np.ndarray) -> tuple[int, int, int, int]:
    """(x0, y0, x1, y1) of the overlay's legend: the image corner that hides the least of the field."""
    font, scale = cv2.FONT_HERSHEY_SIMPLEX, 0.42
    w = max(cv2.getTextSize(text, font, scale, 1)[0][0] for _, _, text in OVERLAY_LEGEND) + 40
    h = 17 * len(OVERLAY_LEGEND) + 8
    height, width = shape[:2]
    fx0, fy0 = np.min(field_corners, axis=0)
    fx1, fy1 = np.max(field_corners, axis=0)
    boxes = [(4, 4), (width - 4 - w, 4), (4, height - 4 - h), (width - 4 - w, height - 4 - h)]

    def hidden(x: int, y: int) -> float:
        return max(0.0, min(x + w, fx1) - max(x, fx0)) * max(0.0, min(y + h, fy1) - max(y, fy0))

    x, y = min(boxes, key=lambda b: hidden(*b))
    return x, y, x + w, y + h


def _legend(out: np.ndarray, field_corners: np.ndarray) -> None:
    x0, y0, x1, y1 = legend_box(out.shape, field_corners)
    cv2.rectangle(out, (x0, y0), (x1, y1), (255, 255, 255), -1)
    cv2.rectangle(out, (x0, y0), (x1, y1), (150, 150, 150), 1)
    for k, (colour, kind, text) in enumerate(OVERLAY_LEGEND):
        y = y0 + 13 + 17 * k
        if kind == "line":
            cv2.line(out, (x0 + 6, y - 4), (x0 + 26, y - 4), colour, 2, cv2.LINE_AA)
        elif kind == "dot":
            cv2.circle(out, (x0 + 16, y - 4), 3, colour, -1, cv2.LINE_AA)
        else:
            cv2.putText(out, "X", (x0 + 10, y), cv2.FONT_HERSHEY_SIMPLEX, 0.42, colour, 1, cv2.LINE_AA)
        cv2.putText(out, text, (x0 + 34, y), cv2.FONT_HERSHEY_SIMPLEX, 0.42, (40, 40, 40), 1, cv2.LINE_AA)


def cells_picture(image: np.ndarray, detection: Detection, cell_px: int = CELL_PX) -> np.ndarray:
    """The field rectified to a square, ink in black, each cell's measured area framed, with its percentage.

    What :func:`~ttt_sm.vision.detection.detect` counts: pixels darker than
    :data:`~ttt_sm.vision.detection.INK_LEVEL` of their local background,
    inside each cell minus the margin along the grid lines.  Scaled 2x to read.
    """
    work, scale = working_image(image)
    field = rectify(ink_image(work), detection.grid.scaled(1.0 / scale), cell_px)
    ink = np.where(field < INK_LEVEL, 0, 255).astype(np.uint8)
    out = cv2.cvtColor(ink, cv2.COLOR_GRAY2BGR)
    out = cv2.resize(out, None, fx=2, fy=2, interpolation=cv2.INTER_NEAREST)
    m = int(round(CELL_MARGIN * cell_px))
    for k in range(N * N):
        r, c = divmod(k, N)
        x0, y0 = 2 * (c * cell_px + m), 2 * (r * cell_px + m)
        x1, y1 = 2 * ((c + 1) * cell_px - m) - 1, 2 * ((r + 1) * cell_px - m) - 1
        occupied = detection.cells[k] != "."
        colour = OCCUPIED_BGR if occupied else (200, 200, 200)
        cv2.rectangle(out, (x0, y0), (x1, y1), colour, 1)
        label = f"{detection.cells[k]} {detection.percentages[k]:.1f}%"
        (tw, th), _ = cv2.getTextSize(label, cv2.FONT_HERSHEY_SIMPLEX, 0.4, 1)
        cv2.rectangle(out, (x0 + 1, y0 + 1), (x0 + tw + 4, y0 + th + 5), (255, 255, 255), -1)
        cv2.putText(out, label, (x0 + 3, y0 + th + 3), cv2.FONT_HERSHEY_SIMPLEX, 0.4, (0, 0, 200), 1,
                    cv2.LINE_AA)
    return out


def fixed_level_picture(image: np.ndarray, detection: Detection, level: int = 80) -> np.ndarray:
    """Side by side: what a fixed grey level calls ink (left) and what the relative level does (right).

    Both are the rectified field, ink black; under a lighting gradient the
    fixed level blackens the dim cells.
    """
    grey = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY) if image.ndim == 3 else image
    fixed = np.where(rectify(grey, detection.grid) < level, 0, 255).astype(np.uint8)
    work, scale = working_image(image)
    rel = np.where(rectify(ink_image(work), detection.grid.scaled(1.0 / scale)) < INK_LEVEL, 0, 255)
    gap = np.full((fixed.shape[0], 8), 255, np.uint8)
    both = np.hstack((fixed, gap, rel.astype(np.uint8)))
    out = cv2.cvtColor(both, cv2.COLOR_GRAY2BGR)
    cv2.rectangle(out, (0, 0), (fixed.shape[1] - 1, fixed.shape[0] - 1), (0, 0, 200), 1)
    cv2.rectangle(out, (fixed.shape[1] + 8, 0), (out.shape[1] - 1, fixed.shape[0] - 1), OCCUPIED_BGR, 1)
    return out


def doc_pictures(out_dir: str | Path, params: ArmParams | None = None) -> list[Path]:
    """Write the pictures of docs/vision.md to `out_dir`; returns their paths.

    A simulated photo (robot X in blue, the person's O in black, the lamp
    on the right, the arm's shadow), the located field over it, the
    rectified cells with their percentages, and the fixed grey level 80 next
    to the relative level on a photo lit at 25 % on its left.
    """
    from ttt_sm.params import load_params
    from ttt_sm.twin.kinematics import ik_closed_form

    from .bench import shadow_of
    from .detection import detect
    from .scenes import scene_from_text
    from .simulated import Lighting, SimulatedCamera

    params = params if params is not None else load_params()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    scene = scene_from_text(params, DOC_BOARD, "X", seed=12)
    light = Lighting(dim=0.45, direction_deg=20.0, spread=0.8, exposure=0.9, vignette=0.12, noise_sigma=1.2,
                     blur_sigma_px=0.7)
    hover = ik_closed_form([0.04, 0.21, 0.06, 0.0], params.geometry)  # the arm waiting over the field
    cam = SimulatedCamera(scene.board, params, seed=12, lighting=light, shadow=shadow_of(list(hover), params.geometry))
    photo = cam.frame()
    det = detect(photo)
    dim_cam = SimulatedCamera(scene_from_text(params, DIM_BOARD, "X", seed=4).board, params, seed=4, jitter=None,
                              lighting=Lighting(dim=0.25, direction_deg=0.0, spread=0.5, exposure=0.85,
                                                vignette=0.05, noise_sigma=2.0, blur_sigma_px=0.7))
    dim_photo = dim_cam.frame()
    # the photos at half size (sensor noise does not compress), the overlay cropped to the field
    x0, y0 = np.floor(det.grid.corners.min(axis=0)).astype(int) - 12
    x1, y1 = np.ceil(det.grid.corners.max(axis=0)).astype(int) + 12
    h, w = photo.shape[:2]

    def small(img: np.ndarray) -> np.ndarray:
        return cv2.resize(img, None, fx=0.5, fy=0.5, interpolation=cv2.INTER_AREA)

    pictures = {
        "vision_photo.png": small(photo),
        # cropped to the field, without the legend (the page's caption says what the colours are)
        "vision_overlay.png": overlay(photo, det, legend=False)[max(0, y0):min(h, y1), max(0, x0):min(w, x1)],
        "vision_cells.png": cells_picture(photo, det),
        "vision_dim_photo.png": small(dim_photo),
        "vision_fixed_level.png": fixed_level_picture(dim_photo, detect(dim_photo)),
    }
    paths = []
    for name, img in pictures.items():
        paths.append(write_png(out / name, img, [cv2.IMWRITE_PNG_COMPRESSION, 9]))
    return paths


#: The boards of the docs' pictures (board order): the robot plays X.
DOC_BOARD = "X...O" ".O.X." "..XO." ".X..O" "O...X"
DIM_BOARD = "..XO." "...XO" "..O.X" "..X.O" "...OX"
