"""Pictures of what the detector saw: the located field over the photo, the rectified cells."""

from __future__ import annotations

import cv2
import numpy as np

from .detection import CELL_MARGIN, CELL_PX, INK_LEVEL, Detection, ink_image, rectify, working_image

N = 5
GRID_BGR = (0, 170, 255)      # the located (drawn) lines, orange
BORDER_BGR = (255, 140, 0)    # the extrapolated outer edge, blue
CROSSING_BGR = (0, 0, 230)
OCCUPIED_BGR = (0, 150, 0)
EMPTY_BGR = (120, 120, 120)


def overlay(image: np.ndarray, detection: Detection) -> np.ndarray:
    """The photo with the located field drawn on it: lines, crossings, outer edge, each cell's reading.

    Orange: the 4 + 4 drawn lines as located; blue: the field's outer edge,
    extrapolated one cell beyond them; red dots: the 16 crossings; in each
    cell its character and ink percentage.
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
        label = f"{ch} {pct:.0f}"
        (w, h), _ = cv2.getTextSize(label, cv2.FONT_HERSHEY_SIMPLEX, 0.35, 1)
        org = (int(u - w / 2), int(v + h / 2))
        cv2.putText(out, label, org, cv2.FONT_HERSHEY_SIMPLEX, 0.35, (255, 255, 255), 3, cv2.LINE_AA)
        cv2.putText(out, label, org, cv2.FONT_HERSHEY_SIMPLEX, 0.35, colour, 1, cv2.LINE_AA)
    return out


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
        cv2.putText(out, label, (x0 + 2, y1 - 3), cv2.FONT_HERSHEY_SIMPLEX, 0.32, (0, 0, 200), 1, cv2.LINE_AA)
    return out
