"""Finding the drawn field in a photo: its 4 + 4 lines, their 16 crossings, the field's homography.

The robot draws only the 4 inner lines each way (section 3.6.1); the
field's outer border is not drawn.  So the field is located from the lines
themselves, with no fixed region of interest:

1. the ink mask (pixels clearly darker than their local background, see
   :func:`ttt_sm.vision.detection.ink_image`) is split into connected pieces;
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

import functools
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
#: Four lines are chosen among this many best-inked, distinct lines per direction.
CANDIDATES_PER_FAMILY = 10
#: Angle step of the Hough transform, rad (the lines are refitted afterwards).
HOUGH_THETA_RAD = math.radians(1.5)
#: The strongest Hough lines per direction whose ink coverage is measured.
HOUGH_LINES_PER_FAMILY = 20
#: A field's lines and symbols ink a small share of its box (10-20 % at half resolution).
MAX_INK_DENSITY = 0.35
#: The grid is looked for in this many of the biggest pieces of ink, biggest first.
CANDIDATE_PIECES = 4
#: Ink pixels within this distance of a Hough line refit it, pixels.
REFIT_BAND_PX = 4.0
#: Largest RMS distance of the 16 crossings from the fitted homography, as a share of a cell.
MAX_RMS_CELLS = 0.06


@dataclass(frozen=True, eq=False)  # eq on arrays is ambiguous
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


def _coverage(fam: np.ndarray, ink: np.ndarray, vertical: bool) -> np.ndarray:
    """Share of each line's run across the box that lies on ink (`ink`: a slightly thickened mask).

    A drawn grid line is inked all along; a line that Hough assembled from
    symbols' strokes, or that crosses a grid line at a small angle, is not.
    """
    h, w = ink.shape
    t = np.arange(h if vertical else w, dtype=np.float64)
    a, b, c = fam[:, 0:1], fam[:, 1:2], fam[:, 2:3]
    if vertical:
        u, v = (c - b * t) / a, np.broadcast_to(t, (len(fam), len(t)))
    else:
        u, v = np.broadcast_to(t, (len(fam), len(t))), (c - a * t) / b
    ui, vi = np.rint(u).astype(np.int64), np.rint(v).astype(np.int64)
    inside = (ui >= 0) & (ui < w) & (vi >= 0) & (vi < h)
    hits = np.zeros(ui.shape, bool)
    hits[inside] = ink[vi[inside], ui[inside]] != 0
    return hits.sum(axis=1) / len(t)


def _choose_four(fam: np.ndarray, ink: np.ndarray, vertical: bool, min_sep: float) -> np.ndarray:
    """Four lines of a family that are well inked and look evenly spaced in perspective."""
    which = "vertical" if vertical else "horizontal"
    if len(fam) == 0:
        raise GridNotFoundError(f"found no {which} lines of the field: is the whole field in the picture?")
    fam = fam[np.argsort(-fam[:, 4], kind="stable")]
    # Hough answers a line with several near-identical ones: keep the strongest per 2-px slot
    _, first = np.unique(np.floor(fam[:, 3] / 2.0), return_index=True)
    top = fam[np.sort(first)[:HOUGH_LINES_PER_FAMILY]]
    top[:, 4] = _coverage(top, ink, vertical)
    top = top[np.argsort(-top[:, 4], kind="stable")]
    pos = top[:, 3].tolist()
    kept_at: list[int] = []
    for i, p in enumerate(pos):  # best-inked first; a line near a kept one is the same line
        if all(abs(p - pos[k]) >= min_sep for k in kept_at):
            kept_at.append(i)
            if len(kept_at) == CANDIDATES_PER_FAMILY:
                break
    kept = list(top[kept_at])
    if len(kept) < 4:
        raise GridNotFoundError(f"found {len(kept)} {which} line(s) of the field, need 4: is the whole field"
                                " in the picture, drawn dark enough and in focus?")
    rows = np.array(kept)
    rows = rows[np.argsort(rows[:, 3])]
    combos = _combinations(len(rows))
    p = rows[combos, 3]
    g = np.diff(p, axis=1)
    cross_ratio = (g[:, 0] + g[:, 1]) * (g[:, 1] + g[:, 2]) / (g[:, 1] * (p[:, 3] - p[:, 0]))
    ok = ((g.min(axis=1) >= 0.45 * g.max(axis=1))  # no table-top perspective squeezes a gap more
          & (np.abs(cross_ratio - EVEN_CROSS_RATIO) <= CROSS_RATIO_TOL))
    if not ok.any():
        raise GridNotFoundError(f"no four {which} lines are evenly spaced like the field's (tried "
                                f"{len(kept)} candidates): is the whole field in the picture?")
    score = np.where(ok, rows[combos, 4].sum(axis=1), -1.0)
    return rows[combos[int(np.argmax(score))]]


@functools.cache
def _combinations(n: int) -> np.ndarray:
    """All 4-subsets of range(n), sorted, shape (C(n, 4), 4)."""
    return np.array(list(itertools.combinations(range(n), 4)), np.int64).reshape(-1, 4)


def _refit(lines: np.ndarray, mask: np.ndarray, vertical: bool) -> np.ndarray:
    """Lines (rows a, b, c) refitted to the ink pixels of `mask` near them (robust least squares).

    Only a band of :data:`REFIT_BAND_PX` on either side of each line is read
    (row by row for near-vertical lines, column by column for
    near-horizontal ones); a second fit to the pixels within half the band
    of the first keeps a symbol that touches the line from pulling it.
    (``cv2.DIST_HUBER`` would do that too, at ten times the cost.)
    """
    h, w = mask.shape
    r = int(math.ceil(REFIT_BAND_PX))
    offsets = np.arange(-r, r + 1)
    a, b, c = lines[:, 0:1], lines[:, 1:2], lines[:, 2:3]
    t = np.arange(h if vertical else w)
    along = np.rint((c - b * t) / a if vertical else (c - a * t) / b).astype(np.int64)
    across = along[:, :, None] + offsets  # (lines, t, offsets)
    tt = np.broadcast_to(t[None, :, None], across.shape)
    inside = (across >= 0) & (across < (w if vertical else h))
    on = np.zeros(across.shape, bool)
    on[inside] = (mask[tt[inside], across[inside]] if vertical else mask[across[inside], tt[inside]]) != 0
    out = np.array(lines[:, :3], np.float64)
    for i in range(len(out)):
        sel = on[i]
        if np.count_nonzero(sel) < 10:
            continue
        u, v = (across[i][sel], tt[i][sel]) if vertical else (tt[i][sel], across[i][sel])
        pts = np.column_stack((u, v)).astype(np.float32)
        la, lb, lc = out[i]
        for band in (None, 0.5 * REFIT_BAND_PX):
            if band is not None:  # again, closer: most of a touching symbol drops out
                pts = pts[np.abs(pts[:, 0] * la + pts[:, 1] * lb - lc) <= band]
                if len(pts) < 10:
                    break
            vx, vy, x0, y0 = (float(k) for k in cv2.fitLine(pts, cv2.DIST_L2, 0, 0.01, 0.01).ravel())
            la, lb = (-vy, vx) if -vy * la + vx * lb >= 0 else (vy, -vx)  # keep the normal's side
            lc = la * x0 + lb * y0
        out[i] = (la, lb, lc)
    return out


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
    _, small = cv2.threshold(small, 0, 255, cv2.THRESH_BINARY)
    n, _, stats, _ = cv2.connectedComponentsWithStats(small, connectivity=8)
    if n <= 1:
        raise GridNotFoundError("no ink in the picture: is the field drawn, and the camera pointed at it?")
    # the field lies inside the picture, so its piece does not reach the picture's edge (dark
    # grain on a dim table does, and can outdo it in size): inner pieces first, biggest first
    px, py, pw, ph, area = (stats[1:, k] for k in range(5))
    edge = (px == 0) | (py == 0) | (px + pw == small.shape[1]) | (py + ph == small.shape[0])
    order = 1 + np.lexsort((-area, edge))
    big_enough = order[2 * np.minimum(pw, ph)[order - 1] >= MIN_GRID_PX].tolist()
    if not big_enough:
        w, h = (int(v) for v in stats[1 + int(np.argmax(area)), 2:4])
        raise GridNotFoundError(f"the largest drawing is {2 * w} x {2 * h} pixels, too small for the field "
                                f"(at least {MIN_GRID_PX} px each way): move the camera closer, or draw the field")
    first_error: GridNotFoundError | None = None
    for k in big_enough[:CANDIDATE_PIECES]:
        try:
            return _grid_from_piece(mask, small, tuple(int(v) for v in stats[k, :4]))  # type: ignore[arg-type]
        except GridNotFoundError as exc:
            first_error = first_error or exc
    assert first_error is not None
    raise first_error


def _grid_from_piece(mask: np.ndarray, small: np.ndarray, box: tuple[int, int, int, int]) -> Grid:
    """The grid whose lines run through one piece's bounding box (`box` in half-resolution pixels)."""
    H, W = mask.shape
    x, y, w, h = box
    # the whole mask over the piece's box: a line broken by glare or a shadow still votes
    mx, my = w // 8, h // 8
    x0, y0 = max(0, x - mx), max(0, y - my)
    x1, y1 = min(W // 2, x + w + mx), min(H // 2, y + h + my)
    crop = small[y0:y1, x0:x1]
    density = cv2.countNonZero(crop) / crop.size
    if density > MAX_INK_DENSITY:
        raise GridNotFoundError(f"{density:.0%} of the drawing's area reads as ink: that is not a field of thin"
                                " lines (a dark or very noisy picture?)")
    found = cv2.HoughLinesWithAccumulator(crop, 1, HOUGH_THETA_RAD, max(15, int(0.4 * min(w, h))))
    if found is None:
        raise GridNotFoundError("no straight lines in the drawing: the field's lines are missing or too faint")
    lines = found.reshape(-1, 3).astype(np.float64)
    centre = ((x - x0) + w / 2, (y - y0) + h / 2)
    vert_f, hori_f = _families(lines, centre)
    ink = cv2.dilate(crop, np.ones((3, 3), np.uint8))
    vert = _choose_four(vert_f, ink, True, 0.04 * w)
    hori = _choose_four(hori_f, ink, False, 0.04 * h)
    # to full-resolution pixels of the crop: u_small = (u - 0.5) / 2 - x0
    X0, Y0 = 2 * x0, 2 * y0
    full = mask[Y0:2 * y1, X0:2 * x1]

    def to_full(rows: np.ndarray) -> np.ndarray:
        a, b, c = rows[:, 0], rows[:, 1], rows[:, 2]
        return np.column_stack((a, b, 2 * c + 0.5 * (a + b)))

    vert_l = _refit(to_full(vert), full, True)
    hori_l = _refit(to_full(hori), full, False)
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
    slack = 0.02 * W
    if (corners[:, 0].min() < -slack or corners[:, 1].min() < -slack or corners[:, 0].max() > W + slack
            or corners[:, 1].max() > H + slack):
        raise GridNotFoundError(f"the field's edge lies outside the picture (corners at "
                                f"{np.round(corners).astype(int).tolist()} in a {W} x {H} image): aim the"
                                " camera at the field's centre or move it back")
    return Grid(Hm, corners, cross, rms)
