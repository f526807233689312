"""Finding the drawn field in a photo: its 4 + 4 lines, their 16 crossings, the field's homography.

The robot draws only the 4 inner lines each way (section 3.6.1); the
field's outer border is not drawn.  So the field is located from the lines
themselves, with no fixed region of interest:

1. the ink mask (pixels clearly darker than their local background, see
   :func:`ttt_sm.vision.detect.ink_image`) is split into connected pieces;
   the drawn grid is one piece (every line crosses the four of the other
   direction), the biggest;
2. a Hough transform over that piece's bounding box finds straight lines;
   they fall into a near-vertical and a near-horizontal family;
3. in each family, four lines are chosen whose crossings with any
   transversal have the cross-ratio of four evenly spaced lines, 4/3
   (a perspective view keeps cross-ratios, not spacings);
4. each line is refitted to its ink pixels (least squares, Huber weights);
5. the 16 crossings, matched to the field's inner corners (1..4, 1..4 cells),
   give the homography from the image to the field by least squares.  The
   outer edges of the field are where that homography puts 0 and 5 cells:
   one cell spacing beyond the outer lines, in perspective.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import cv2
import numpy as np

from .errors import GridNotFoundError

#: Smallest side of the grid's bounding box, pixels (at the 640-pixel working width).
MIN_GRID_PX = 60
#: The cross-ratio of four evenly spaced lines, and how far a chosen four may be from it.
EVEN_CROSS_RATIO = 4.0 / 3.0
CROSS_RATIO_TOL = 0.12
#: Lines are searched among this many strongest Hough lines per direction.
CANDIDATES_PER_FAMILY = 8
#: Ink pixels within this distance of a Hough line refit it, pixels.
REFIT_BAND_PX = 4.0
#: Largest RMS distance of the 16 crossings from the fitted homography, as a share of a cell.
MAX_RMS_CELLS = 0.06


@dataclass(frozen=True)
class Grid:
    """The located field in a photo.

    Attributes
    ----------
    homography : np.ndarray, shape (3, 3)
        Maps image pixels (u, v, 1) to field coordinates in cells: (0, 0)
        the field's top-left corner as seen in the image, (5, 5) its bottom
        right; the drawn lines are at 1..4.
    corners : np.ndarray, shape (4, 2)
        The field's outer corners in the image (pixels): top left, top
        right, bottom right, bottom left (extrapolated: not drawn).
    crossings : np.ndarray, shape (4, 4, 2)
        The 16 crossings of the drawn lines, pixels; ``crossings[j, i]`` is
        where horizontal line j+1 (from the top) crosses vertical line i+1
        (from the left).
    rms_cells : float
        RMS distance of the crossings from the fitted homography, in cells.
    """

    homography: np.ndarray
    corners: np.ndarray
    crossings: np.ndarray
    rms_cells: float

    def image_to_field(self, points_px: np.ndarray) -> np.ndarray:
        """Field coordinates (cells) of image points, shape (N, 2)."""
        p = np.asarray(points_px, np.float64).reshape(-1, 1, 2)
        return cv2.perspectiveTransform(p, self.homography).reshape(-1, 2)

    def field_to_image(self, points_cells: np.ndarray) -> np.ndarray:
        """Image pixels of field points (cells), shape (N, 2)."""
        p = np.asarray(points_cells, np.float64).reshape(-1, 1, 2)
        return cv2.perspectiveTransform(p, np.linalg.inv(self.homography)).reshape(-1, 2)

    def scaled(self, factor: float) -> Grid:
        """The same grid in an image `factor` times larger (pixels multiplied by `factor`)."""
        S = np.diag([1.0 / factor, 1.0 / factor, 1.0])
        return Grid(self.homography @ S, self.corners * factor, self.crossings * factor, self.rms_cells)


def _cross_ratio(p: np.ndarray) -> float:
    return float((p[2] - p[0]) * (p[3] - p[1]) / ((p[2] - p[1]) * (p[3] - p[0])))


def _families(lines: np.ndarray, centre: tuple[float, float]) -> list[np.ndarray]:
    """Split Hough lines (rho, theta, votes) into near-vertical and near-horizontal.

    Returns two arrays of rows (a, b, c, position, votes) with the line
    ``a u + b v = c`` (unit normal) and its position along the transversal
    through `centre` (u for near-vertical lines, v for near-horizontal ones).
    """
    rho, theta, votes = lines[:, 0], lines[:, 1], lines[:, 2]
    a, b = np.cos(theta), np.sin(theta)
    uc, vc = centre
    out = []
    vertical = np.abs(a) >= np.abs(b)
    for k, fam in enumerate((vertical, ~vertical)):
        aa, bb, cc = a[fam], b[fam], rho[fam]
        if k == 0:
            flip = aa < 0  # normals pointing right: position grows to the right
            pos_num, pos_den = cc - bb * vc, aa
        else:
            flip = bb < 0
            pos_num, pos_den = cc - aa * uc, bb
        sign = np.where(flip, -1.0, 1.0)
        pos = pos_num / pos_den
        out.append(np.column_stack((aa * sign, bb * sign, cc * sign, pos, votes[fam])))
    return out


def _choose_four(fam: np.ndarray, min_sep: float, which: str) -> np.ndarray:
    """Four lines of a family that look evenly spaced in perspective, strongest first."""
    kept: list[np.ndarray] = []
    for row in fam[np.argsort(-fam[:, 4], kind="stable")]:
        if all(abs(row[3] - k[3]) >= min_sep for k in kept):
            kept.append(row)
            if len(kept) == CANDIDATES_PER_FAMILY:
                break
    if len(kept) < 4:
        raise GridNotFoundError(f"found {len(kept)} {which} line(s) of the field, need 4: is the whole field"
                                " in the picture, drawn dark enough and in focus?")
    kept.sort(key=lambda r: float(r[3]))
    pos = [float(r[3]) for r in kept]
    votes = [float(r[4]) for r in kept]
    best: tuple[float, tuple[int, ...]] | None = None
    for combo in itertools.combinations(range(len(kept)), 4):  # at most 70
        p0, p1, p2, p3 = (pos[i] for i in combo)
        g0, g1, g2 = p1 - p0, p2 - p1, p3 - p2
        if min(g0, g1, g2) < 0.45 * max(g0, g1, g2):
            continue  # no perspective of a table-top field squeezes one gap that much
        if abs((g0 + g1) * (g1 + g2) / (g1 * (p3 - p0)) - EVEN_CROSS_RATIO) > CROSS_RATIO_TOL:
            continue
        score = sum(votes[i] for i in combo)
        if best is None or score > best[0]:
            best = (score, combo)
    if best is None:
        raise GridNotFoundError(f"no four {which} lines are evenly spaced like the field's (tried "
                                f"{len(kept)} candidates): is the whole field in the picture?")
    return np.array([kept[i] for i in best[1]])


def _refit(line: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """The line (a, b, c) refitted to the ink pixels near it: total least squares, then once more closer."""
    a, b, c = (float(v) for v in line[:3])
    for band in (REFIT_BAND_PX, 0.5 * REFIT_BAND_PX):
        near = np.abs(xs * a + ys * b - c) <= band
        x, y = xs[near], ys[near]
        if len(x) < 10:
            break
        mx, my = float(x.mean()), float(y.mean())
        dx, dy = x - mx, y - my
        sxx, syy, sxy = float(dx @ dx), float(dy @ dy), float(dx @ dy)
        t = 0.5 * math.atan2(2 * sxy, sxx - syy)  # direction of most spread
        na, nb = -math.sin(t), math.cos(t)
        if na * a + nb * b < 0:
            na, nb = -na, -nb
        a, b, c = na, nb, na * mx + nb * my
    return np.array([a, b, c])


def _crossings(vert: np.ndarray, hori: np.ndarray) -> np.ndarray:
    """Crossings of every horizontal line j with every vertical line i, shape (4, 4, 2)."""
    out = np.empty((4, 4, 2))
    for j, (a2, b2, c2) in enumerate(hori):
        for i, (a1, b1, c1) in enumerate(vert):
            det = a1 * b2 - a2 * b1
            out[j, i] = ((c1 * b2 - c2 * b1) / det, (a1 * c2 - a2 * c1) / det)
    return out


def locate_grid(mask: np.ndarray) -> Grid:
    """Find the drawn 5x5 field in an ink mask.

    Parameters
    ----------
    mask : np.ndarray, uint8, shape (H, W)
        Non-zero where there is ink.

    Returns
    -------
    Grid

    Raises
    ------
    GridNotFoundError
        No piece of ink big enough, not four lines each way, lines not
        evenly spaced like the field's, or crossings that no homography fits.
    """
    H, W = mask.shape
    # pieces and Hough at half resolution (4x fewer pixels; a 1-px line survives the
    # "any ink" shrink), the refit at full resolution
    small = cv2.resize(mask, (W // 2, H // 2), interpolation=cv2.INTER_AREA)
    small = cv2.compare(small, 0, cv2.CMP_GT)
    n, _, stats, _ = cv2.connectedComponentsWithStats(small, connectivity=8)
    if n <= 1:
        raise GridNotFoundError("no ink in the picture: is the field drawn, and the camera pointed at it?")
    big = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    x, y, w, h = (int(v) for v in stats[big, :4])
    if 2 * min(w, h) < MIN_GRID_PX:
        raise GridNotFoundError(f"the largest drawing is {2 * w} x {2 * h} pixels, too small for the field "
                                f"(at least {MIN_GRID_PX} px each way): move the camera closer, or draw the field")
    # the whole mask over the grid piece's box: a line broken by glare still votes
    mx, my = w // 8, h // 8
    x0, y0 = max(0, x - mx), max(0, y - my)
    x1, y1 = min(W // 2, x + w + mx), min(H // 2, y + h + my)
    crop = small[y0:y1, x0:x1]
    found = cv2.HoughLinesWithAccumulator(crop, 1, math.pi / 180, max(15, int(0.4 * min(w, h))))
    if found is None:
        raise GridNotFoundError("no straight lines in the drawing: the field's lines are missing or too faint")
    lines = found.reshape(-1, 3).astype(np.float64)
    centre = ((x - x0) + w / 2, (y - y0) + h / 2)
    vert_f, hori_f = _families(lines, centre)
    vert = _choose_four(vert_f, 0.08 * w, "vertical")
    hori = _choose_four(hori_f, 0.08 * h, "horizontal")
    # to full-resolution pixels of the crop: u_small = (u - 0.5) / 2 - x0
    X0, Y0 = 2 * x0, 2 * y0
    full = mask[Y0:2 * y1, X0:2 * x1]
    nz = cv2.findNonZero(full)
    pts = nz.reshape(-1, 2).astype(np.float32) if nz is not None else np.zeros((0, 2), np.float32)
    xs, ys = np.ascontiguousarray(pts[:, 0]), np.ascontiguousarray(pts[:, 1])

    def to_full(r: np.ndarray) -> np.ndarray:
        a, b, c = r[:3]
        return np.array([a, b, 2 * c + 0.5 * (a + b)])

    vert_l = np.array([_refit(to_full(r), xs, ys) for r in vert])
    hori_l = np.array([_refit(to_full(r), xs, ys) for r in hori])
    cross = _crossings(vert_l, hori_l) + (X0, Y0)
    field = np.array([(i + 1, j + 1) for j in range(4) for i in range(4)], np.float64)
    Hm, _ = cv2.findHomography(cross.reshape(-1, 2), field, 0)
    if Hm is None:
        raise GridNotFoundError("the lines' crossings do not fit a flat field (degenerate)")
    g = Grid(Hm, np.empty((4, 2)), cross, 0.0)
    rms = float(np.sqrt(np.mean(np.sum((g.image_to_field(cross.reshape(-1, 2)) - field) ** 2, axis=1))))
    if rms > MAX_RMS_CELLS:
        raise GridNotFoundError(f"the lines' crossings fit a flat field only to {rms:.2f} cells RMS "
                                f"(at most {MAX_RMS_CELLS}): bent lines, or not the field")
    corners = g.field_to_image(np.array([(0.0, 0.0), (5.0, 0.0), (5.0, 5.0), (0.0, 5.0)]))
    return Grid(Hm, corners, cross, rms)
