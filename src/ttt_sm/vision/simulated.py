"""A simulated camera: a board photographed by a pinhole camera on a stand.

The thesis' smart camera (section 3.6.3, fig. 3.31) stands above the board
and sees the field the arm drew.  :class:`SimulatedCamera` makes the photo
such a camera would take of any :class:`Photographable` board (the digital
twin's :class:`~ttt_sm.twin.whiteboard.Whiteboard` is one; this module does
not import it, so vision stays beside the twin, not on top of it):

* **perspective**: a pinhole camera beyond the board's far edge, looking
  down at the field (:meth:`CameraPose.beyond_far_edge`), its position,
  aim, roll and focal length jittered per camera (:class:`CameraJitter`).
  The board is a plane, so board -> image is one homography
  ``K [r1 r2 t]`` (:meth:`CameraPose.board_to_image`); the board is drawn
  from above (``render(view="above")``) and warped through it onto a
  table top;
* **lighting** (:class:`Lighting`): a gradient that leaves one side dim,
  vignetting, exposure, a colour tint;
* **optics and sensor**: Gaussian blur (focus) and noise;
* the **arm's shadow** (optional): the links (a polyline of the arm's
  joints, :class:`Shadow`) seen from a lamp, cast on the board, with a soft
  edge;
* the person's hand-drawn symbols and the robot's ink are whatever is on
  the board (:meth:`Whiteboard.draw_symbol`, the arm's pen).

Everything random comes from the camera's ``seed``: the pose jitter and the
lighting are drawn once (a camera on a stand does not move between photos),
the sensor noise afresh for every :meth:`SimulatedCamera.frame`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any, Protocol

import cv2
import numpy as np

from ttt_sm.params import ArmParams

from .camera import DEFAULT_SIZE
from .errors import VisionError

#: Default camera: this far beyond the field centre (towards +y, away from the robot), m ...
CAMERA_BEHIND_M = 0.27
#: ... and this high above the board, m (the stand of fig. 3.31).
CAMERA_HEIGHT_M = 0.40
#: Default focal length, pixels (640 x 480 sensor): the field spans about 280 px.
CAMERA_FOCAL_PX = 900.0
#: A lamp beside the robot, m: where the arm's shadow comes from.
LAMP_M = (0.30, 0.05, 0.90)
#: How much of the light the arm's shadow takes away (0 none, 1 black).
SHADOW_DEPTH = 0.45
#: Widths of the arm's links for its shadow, m: upright column, upper arm, forearm, pen holder.
SHADOW_WIDTHS_M = (0.05, 0.04, 0.035, 0.02)
#: Softness (Gaussian sigma) of the shadow's edge on the board, m.
SHADOW_SOFTNESS_M = 0.004


class Photographable(Protocol):
    """What the camera photographs: a board that draws itself seen from above.

    The twin's :class:`~ttt_sm.twin.whiteboard.Whiteboard` is one.
    """

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """(x_min, x_max, y_min, y_max) of the board, m."""
        ...

    def render(self, px_per_mm: float = 4.0, grid_mm: bool = False, region: Any = None, *,
               view: str = "field", desired: Any = None) -> np.ndarray:
        """The board as a BGR image; ``view="above"``: x right, y up, at ``px_per_mm``."""
        ...


@dataclass(frozen=True)
class CameraPose:
    """Where a pinhole camera is, where it looks, and its intrinsics.

    Attributes
    ----------
    position_m : (x, y, z)
        Centre of projection in the global frame, m.
    target_m : (x, y, z)
        The point on the optical axis, m (the image centre).
    roll_deg : float
        Turn of the camera about its optical axis, degrees (positive turns
        the picture clockwise).
    focal_px : float
        Focal length, pixels (square pixels, principal point at the centre).
    width_px, height_px : int
        Image size, pixels.

    Notes
    -----
    Without roll, the image's "down" is the world's +y (towards a camera
    beyond the far edge) tipped into the image plane: a camera beyond the
    far edge sees the robot at the top of its picture.
    """

    position_m: tuple[float, float, float]
    target_m: tuple[float, float, float]
    roll_deg: float = 0.0
    focal_px: float = CAMERA_FOCAL_PX
    width_px: int = DEFAULT_SIZE[0]
    height_px: int = DEFAULT_SIZE[1]

    @classmethod
    def beyond_far_edge(cls, params: ArmParams, *, behind_m: float = CAMERA_BEHIND_M,
                        height_m: float = CAMERA_HEIGHT_M, focal_px: float = CAMERA_FOCAL_PX,
                        size: tuple[int, int] = DEFAULT_SIZE) -> CameraPose:
        """The default camera: `behind_m` beyond the field centre (+y), `height_m` up, aimed at the centre."""
        b = params.board
        return cls((b.field_center_x, b.field_center_y + behind_m, b.surface_z + height_m),
                   (b.field_center_x, b.field_center_y, b.surface_z), 0.0, focal_px, size[0], size[1])

    def rotation(self) -> np.ndarray:
        """World -> camera rotation, shape (3, 3): rows are the camera's x (right), y (down), z (forward)."""
        c = np.asarray(self.position_m, float)
        z = np.asarray(self.target_m, float) - c
        n = float(np.linalg.norm(z))
        if not n > 0.0:
            raise VisionError("camera pose: position_m and target_m must differ")
        z /= n
        x = np.cross((0.0, 1.0, 0.0), z)  # image down ~ world +y
        if np.linalg.norm(x) < 1e-6:
            raise VisionError("camera pose: the camera must not look along the board's y axis")
        x /= np.linalg.norm(x)
        y = np.cross(z, x)
        a = math.radians(self.roll_deg)
        ca, sa = math.cos(a), math.sin(a)
        return np.array([ca * x + sa * y, -sa * x + ca * y, z])

    def intrinsics(self) -> np.ndarray:
        """Camera matrix K, shape (3, 3), pixels (pixel centres at integer coordinates)."""
        return np.array([[self.focal_px, 0.0, (self.width_px - 1) / 2],
                         [0.0, self.focal_px, (self.height_px - 1) / 2],
                         [0.0, 0.0, 1.0]])

    def board_to_image(self, surface_z: float = 0.0) -> np.ndarray:
        """Homography from board coordinates (x, y) in m on the plane z = `surface_z` to image pixels."""
        R = self.rotation()
        t = -R @ np.asarray(self.position_m, float)
        H = self.intrinsics() @ np.column_stack((R[:, 0], R[:, 1], R[:, 2] * surface_z + t))
        return H / H[2, 2]

    def board_footprint(self, surface_z: float = 0.0) -> np.ndarray:
        """What the camera sees of the board plane: its image's four corners on the plane z = `surface_z`
        (x, y in m, shape (4, 2); top left, top right, bottom right, bottom left of the image).

        A corner above the horizon (its ray never meets the plane) is a :class:`VisionError`."""
        H_inv = np.linalg.inv(self.board_to_image(surface_z))
        w, h = self.width_px - 1, self.height_px - 1
        corners = H_inv @ np.array([[0.0, w, w, 0.0], [0.0, 0.0, h, h], [1.0, 1.0, 1.0, 1.0]])
        if not np.all(corners[2] > 0):
            raise VisionError("camera pose: part of the image lies above the horizon; it sees no whole footprint")
        return (corners[:2] / corners[2]).T

    def project(self, points_m: Any) -> np.ndarray:
        """Image pixels (u, v) of world points, shape (N, 2); `points_m` has shape (N, 3)."""
        p = np.atleast_2d(np.asarray(points_m, float))
        R = self.rotation()
        cam = (p - np.asarray(self.position_m, float)) @ R.T
        uv = cam @ self.intrinsics().T
        return uv[:, :2] / uv[:, 2:3]

    def view(self) -> str:
        """How the image lies on the board, as :data:`ttt_sm.twin.whiteboard.VIEWS` names it.

        ``"far_edge"`` when the image's right is the board's -x and its up
        -y (a camera beyond the far edge), ``"above"`` for +x and +y.
        """
        R = self.rotation()
        right, up = R[0], -R[1]
        if right[0] < -0.7 and up[1] < -0.3:
            return "far_edge"
        if right[0] > 0.7 and up[1] > 0.3:
            return "above"
        raise VisionError(f"camera pose: the image is turned too far (right {right.round(2)}, up {up.round(2)})"
                          " for the cell mapping: keep the roll within +-45 deg")


@dataclass(frozen=True)
class CameraJitter:
    """How far each simulated camera's pose is off the nominal one (uniform, +- these values)."""

    position_m: float = 0.02
    target_m: float = 0.012
    roll_deg: float = 4.0
    focal_rel: float = 0.05

    def apply(self, pose: CameraPose, rng: np.random.Generator) -> CameraPose:
        """A pose drawn around `pose`."""
        dp = rng.uniform(-1.0, 1.0, 3) * self.position_m
        dt = rng.uniform(-1.0, 1.0, 2) * self.target_m
        return replace(pose,
                       position_m=(pose.position_m[0] + float(dp[0]), pose.position_m[1] + float(dp[1]),
                                   pose.position_m[2] + float(dp[2])),
                       target_m=(pose.target_m[0] + float(dt[0]), pose.target_m[1] + float(dt[1]),
                                 pose.target_m[2]),
                       roll_deg=pose.roll_deg + float(rng.uniform(-1.0, 1.0)) * self.roll_deg,
                       focal_px=pose.focal_px * (1.0 + float(rng.uniform(-1.0, 1.0)) * self.focal_rel))


@dataclass(frozen=True)
class Lighting:
    """How one simulated camera's photos are lit and degraded.

    Attributes
    ----------
    dim : float
        Brightness of the dim side of the picture relative to the bright
        side (1: even light; 0.3: the dim side gets 30 %).
    direction_deg : float
        Direction in the image from the dim side to the bright side,
        degrees (0: bright on the right, 90: bright at the bottom).
    spread : float
        Width of the transition from dim to bright, as a share of the
        picture's extent in that direction (1: across the whole picture;
        0.5: across its middle half, a lamp close by).
    exposure : float
        Grey level of the white board where the light is brightest, / 255.
    vignette : float
        Light lost in the image corners (0 none).
    tint : (b, g, r)
        Channel gains (a warm or cold lamp).
    noise_sigma : float
        Sensor noise, grey levels (Gaussian, per channel and pixel).
    blur_sigma_px : float
        Focus blur, pixels (Gaussian sigma).
    """

    dim: float = 1.0
    direction_deg: float = 0.0
    spread: float = 1.0
    exposure: float = 0.92
    vignette: float = 0.1
    tint: tuple[float, float, float] = (1.0, 1.0, 1.0)
    noise_sigma: float = 2.0
    blur_sigma_px: float = 0.7

    @classmethod
    def random(cls, rng: np.random.Generator, *, dim: tuple[float, float] = (0.25, 1.0),
               noise_sigma: tuple[float, float] = (1.0, 4.0),
               blur_sigma_px: tuple[float, float] = (0.4, 1.1)) -> Lighting:
        """Lighting drawn uniformly from the given ranges (and a random side dim)."""
        return cls(dim=float(rng.uniform(*dim)),
                   direction_deg=float(rng.uniform(0.0, 360.0)),
                   spread=float(rng.uniform(0.5, 1.0)),
                   exposure=float(rng.uniform(0.78, 1.0)),
                   vignette=float(rng.uniform(0.0, 0.25)),
                   tint=tuple(float(v) for v in rng.uniform(0.9, 1.05, 3)),  # type: ignore[arg-type]
                   noise_sigma=float(rng.uniform(*noise_sigma)),
                   blur_sigma_px=float(rng.uniform(*blur_sigma_px)))

    def illumination(self, width: int, height: int) -> np.ndarray:
        """Light falling on each pixel (0..1), float32, shape (height, width)."""
        v, u = np.mgrid[0:height, 0:width].astype(np.float32)
        cu, cv = (width - 1) / 2, (height - 1) / 2
        a = math.radians(self.direction_deg)
        half = 0.5 * self.spread * (abs(math.cos(a)) * width + abs(math.sin(a)) * height)
        s = np.clip(0.5 + ((u - cu) * math.cos(a) + (v - cv) * math.sin(a)) / (2 * half), 0.0, 1.0)
        s = s * s * (3 - 2 * s)  # smooth step: the lamp's fall-off
        light = self.dim + (1.0 - self.dim) * s
        r2 = ((u - cu) ** 2 + (v - cv) ** 2) / (cu ** 2 + cv ** 2)
        return (light * (1.0 - self.vignette * r2) * self.exposure).astype(np.float32)


@dataclass(frozen=True)
class Shadow:
    """The arm's shadow: where its links are and the lamp that casts it.

    ``links_m`` is the arm as a polyline, 5 points (x, y, z) in m: the
    column's foot, the shoulder, the elbow, the wrist and the pen tip
    (:func:`ttt_sm.vision.bench.shadow_of` makes it from joint angles with
    the twin's kinematics).
    """

    links_m: tuple[tuple[float, float, float], ...]
    lamp_m: tuple[float, float, float] = LAMP_M
    depth: float = SHADOW_DEPTH


class SimulatedCamera:
    """A camera on a stand photographing the simulated whiteboard (a :class:`~ttt_sm.vision.camera.Camera`).

    Parameters
    ----------
    board : Photographable
        The board it sees (the twin's whiteboard); each :meth:`frame` shows
        its ink at that moment.
    params : ArmParams
        Board geometry (and the arm's links, for the shadow).
    seed : int
        Seeds the pose jitter, the lighting (when not given), the table's
        grain and the sensor noise.
    pose : CameraPose, optional
        Nominal pose (default :meth:`CameraPose.beyond_far_edge`).
    jitter : CameraJitter or None
        How far the actual pose is off the nominal one (None: exactly it).
    lighting : Lighting, optional
        Default: :meth:`Lighting.random` from the seed.
    shadow : Shadow or callable returning a Shadow or None, optional
        The arm's shadow; a callable is asked at every frame (the arm moves).

    Attributes
    ----------
    pose : CameraPose
        The actual pose (after jitter).
    lighting : Lighting
        The actual lighting.
    """

    def __init__(self, board: Photographable, params: ArmParams, seed: int = 0, *,
                 pose: CameraPose | None = None, jitter: CameraJitter | None = CameraJitter(),
                 lighting: Lighting | None = None,
                 shadow: Shadow | Callable[[], Shadow | None] | None = None) -> None:
        self.board = board
        self.params = params
        self._rng = np.random.default_rng(seed)
        nominal = pose if pose is not None else CameraPose.beyond_far_edge(params)
        self.pose = jitter.apply(nominal, self._rng) if jitter is not None else nominal
        self.lighting = lighting if lighting is not None else Lighting.random(self._rng)
        self._shadow = shadow
        W, H = self.pose.width_px, self.pose.height_px
        self._illum = self.lighting.illumination(W, H)[:, :, None] * np.asarray(self.lighting.tint, np.float32)
        self._table = _table_top(W, H, self._rng)
        self._noise = np.empty((H, W, 3), np.float32)  # each frame's sensor noise is drawn into it
        b = params.board
        self._surface_z = b.surface_z
        # render the board a little finer than the camera sees it near its closest point
        x0, x1, y0, y1 = board.extent
        corners = np.array([(x, y, b.surface_z) for x in (x0, x1) for y in (y0, y1)])
        nearest = float(np.min(np.linalg.norm(corners - np.asarray(self.pose.position_m), axis=1)))
        self._px_per_mm = float(np.clip(1.3 * self.pose.focal_px / (nearest * 1e3), 1.0, 6.0))
        p = self._px_per_mm * 1e3
        # render pixel (u, v) of view "above" has its centre at x = x0 + (u + 0.5)/p, y = y1 - (v + 0.5)/p
        self._render_to_board = np.array([[1 / p, 0.0, x0 + 0.5 / p], [0.0, -1 / p, y1 - 0.5 / p], [0, 0, 1.0]])
        self._H = self.pose.board_to_image(b.surface_z) @ self._render_to_board
        self._size = (W, H)

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) of the frames, pixels."""
        return self._size

    def view(self) -> str:
        """How the image lies on the board (see :func:`ttt_sm.vision.orientation.board_cell`)."""
        return self.pose.view()

    def board_to_image(self) -> np.ndarray:
        """The true homography from board (x, y) in m to image pixels (for tests and overlays)."""
        return self.pose.board_to_image(self._surface_z)

    def frame(self) -> np.ndarray:
        """A photo of the board now: BGR uint8, shape (height, width, 3)."""
        top = self.board.render(self._px_per_mm, view="above")
        shadow = self._shadow() if callable(self._shadow) else self._shadow
        if shadow is not None:
            top = self._cast_shadow(top, shadow)
        W, H = self._size
        img = cv2.warpPerspective(top, self._H, (W, H), dst=self._table.copy(), flags=cv2.INTER_LINEAR,
                                  borderMode=cv2.BORDER_TRANSPARENT)
        # One float32 frame, worked on in place from here: a photo is taken while the
        # game waits for it, and every temporary of 640x480x3 floats costs a millisecond.
        lit = np.asarray(cv2.multiply(img, self._illum, dtype=cv2.CV_32F), np.float32)  # (no copy)
        s = self.lighting.blur_sigma_px
        if s > 0.0:
            cv2.GaussianBlur(lit, (0, 0), s, dst=lit)
        if self.lighting.noise_sigma > 0.0:
            # Sensor noise, independent per pixel and channel.  OpenCV's generator
            # fills a 640x480x3 frame three times faster than numpy's; seeding it
            # from this camera's own generator keeps a seed's photos reproducible.
            cv2.setRNGSeed(int(self._rng.integers(1, 2**31)))
            noise = self._noise
            # one mean and sigma per channel: scalars would fill channel 0 only
            cv2.randn(noise, np.zeros(3), np.full(3, float(self.lighting.noise_sigma)))
            lit += noise
        # rounded half up and clipped to 0..255 (astype truncates what the clip left non-negative)
        lit += 0.5
        np.clip(lit, 0, 255, out=lit)
        return lit.astype(np.uint8)

    def release(self) -> None:
        """Nothing to release (the :class:`~ttt_sm.vision.camera.Camera` protocol asks for it)."""

    def _cast_shadow(self, top: np.ndarray, shadow: Shadow) -> np.ndarray:
        """Darken the board render where the arm's links, seen from the lamp, fall on it."""
        joints = np.asarray(shadow.links_m, float)
        if joints.shape != (len(SHADOW_WIDTHS_M) + 1, 3):
            raise VisionError(f"Shadow.links_m: expected {len(SHADOW_WIDTHS_M) + 1} points (x, y, z),"
                              f" got an array of shape {joints.shape}")
        lamp = np.asarray(shadow.lamp_m, float)
        z0 = self._surface_z
        if np.any(joints[:, 2] >= lamp[2]):
            return top  # a link above the lamp casts no shadow on the board
        k = (lamp[2] - z0) / (lamp[2] - joints[:, 2])
        on_board = lamp[:2] + (joints[:, :2] - lamp[:2]) * k[:, None]
        p = self._px_per_mm * 1e3
        x0, _, _, y1 = self.board.extent
        uv = np.column_stack(((on_board[:, 0] - x0) * p - 0.5, (y1 - on_board[:, 1]) * p - 0.5))
        mask = np.zeros(top.shape[:2], np.float32)
        for i, width in enumerate(SHADOW_WIDTHS_M):
            a, b = np.round(uv[i] * 16).astype(np.int64), np.round(uv[i + 1] * 16).astype(np.int64)
            cv2.line(mask, (int(a[0]), int(a[1])), (int(b[0]), int(b[1])), 1.0,
                     max(1, round(width * p)), cv2.LINE_AA, shift=4)
        soft = cv2.GaussianBlur(mask, (0, 0), SHADOW_SOFTNESS_M * p)
        factor = 1.0 - shadow.depth * np.minimum(soft, 1.0)
        return (top.astype(np.float32) * factor[:, :, None]).astype(np.uint8)


def _table_top(width: int, height: int, rng: np.random.Generator) -> np.ndarray:
    """The table around the board: a brownish surface with a coarse grain, BGR uint8."""
    base = np.array([70, 100, 135], np.float32) * float(rng.uniform(0.7, 1.1))
    grain = cv2.GaussianBlur(rng.standard_normal((height, width), dtype=np.float32), (0, 0), 6.0) * 40.0
    streaks = cv2.GaussianBlur(rng.standard_normal((height, width), dtype=np.float32), (0, 0), sigmaX=40.0,
                               sigmaY=1.5) * 60.0
    tex = (base[None, None, :] + (grain + streaks)[:, :, None])
    return np.clip(tex, 0, 255).astype(np.uint8)
