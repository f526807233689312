"""Cameras: the simulated one looks like a camera on a stand, not a crop; files and devices."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import pytest

from ttt_sm.vision import (
    Camera,
    CameraError,
    ImageError,
    ImageFileCamera,
    OpenCVCamera,
    board_text,
    check_image,
    detect,
    read_image,
)
from ttt_sm.vision.bench import random_shadow
from ttt_sm.vision.scenes import random_scene, scene_from_text
from ttt_sm.vision.simulated import CameraJitter, CameraPose, Lighting, SimulatedCamera

EVEN = Lighting(dim=1.0, vignette=0.0, noise_sigma=0.0, blur_sigma_px=0.0)


def test_a_simulated_frame_is_a_640_by_480_bgr_image_and_every_source_is_a_camera(params):
    scene = random_scene(params, 1)
    cam = SimulatedCamera(scene.board, params, seed=1)
    img = cam.frame()
    assert img.shape == (480, 640, 3) and img.dtype == np.uint8
    assert cam.size == (640, 480)
    assert isinstance(cam, Camera)
    assert isinstance(ImageFileCamera(["x.png"]), Camera)


def test_the_simulated_camera_sees_the_field_in_perspective_from_beyond_the_far_edge(params):
    cam = SimulatedCamera(scene_from_text(params, "." * 25).board, params, jitter=None, lighting=EVEN)
    x0, x1, y0, y1 = params.board.field_bounds()
    near = cam.pose.project([(x0, y1, 0.0), (x1, y1, 0.0)])  # the far edge from the robot: near the camera
    far = cam.pose.project([(x0, y0, 0.0), (x1, y0, 0.0)])
    near_w, far_w = abs(near[1, 0] - near[0, 0]), abs(far[1, 0] - far[0, 0])
    assert near_w > 1.1 * far_w  # a trapezoid: not a top-down crop
    assert near[:, 1].mean() > far[:, 1].mean()  # the robot's side at the top of the image
    assert near[0, 0] > near[1, 0]  # +x to the left
    assert cam.view() == "far_edge"
    # the homography agrees with projecting the 3-D points
    H = cam.board_to_image()
    p = H @ np.array([x0, y1, 1.0])
    assert np.allclose(p[:2] / p[2], near[0], atol=1e-6)


def test_jitter_moves_and_turns_each_camera_differently_but_reproducibly(params):
    scene = random_scene(params, 2)
    a = SimulatedCamera(scene.board, params, seed=5, jitter=CameraJitter(roll_deg=10.0))
    b = SimulatedCamera(scene.board, params, seed=6, jitter=CameraJitter(roll_deg=10.0))
    a2 = SimulatedCamera(scene.board, params, seed=5, jitter=CameraJitter(roll_deg=10.0))
    assert a.pose != b.pose and a.pose == a2.pose
    assert a.lighting == a2.lighting
    assert np.array_equal(a.frame(), a2.frame())


def test_sensor_noise_changes_from_frame_to_frame(params):
    cam = SimulatedCamera(random_scene(params, 3).board, params, seed=3,
                          lighting=Lighting(noise_sigma=3.0))
    f1, f2 = cam.frame().astype(int), cam.frame().astype(int)
    d = f1 - f2
    # two independent draws of sigma 3 (before rounding and clipping): sqrt(2) * 3 = 4.2, in every channel
    for channel in range(3):
        assert 3.6 < d[:, :, channel].std() < 4.9


def test_the_lighting_gradient_leaves_one_side_dim(params):
    board = scene_from_text(params, "." * 25).board
    cam = SimulatedCamera(board, params, jitter=None,
                          lighting=Lighting(dim=0.3, direction_deg=0.0, vignette=0.0, noise_sigma=0.0))
    grey = cv2.cvtColor(cam.frame(), cv2.COLOR_BGR2GRAY)
    x0, x1, _, _ = params.board.field_bounds()
    cy = params.board.field_center_y
    (ul, vl), (ur, vr) = cam.pose.project([(x1, cy, 0.0), (x0, cy, 0.0)])  # +x is on the left
    left, right = grey[int(vl), int(ul) + 8], grey[int(vr), int(ur) - 8]
    assert right > 180 and left < 0.6 * right


def test_the_arm_casts_a_shadow_on_the_board(params):
    board = scene_from_text(params, "." * 25).board
    shadow = random_shadow(params, np.random.default_rng(0))
    lit = SimulatedCamera(board, params, seed=1, jitter=None, lighting=EVEN)
    shaded = SimulatedCamera(board, params, seed=1, jitter=None, lighting=EVEN, shadow=shadow)
    a = cv2.cvtColor(lit.frame(), cv2.COLOR_BGR2GRAY).astype(int)
    b = cv2.cvtColor(shaded.frame(), cv2.COLOR_BGR2GRAY).astype(int)
    darker = (a - b) > 40
    assert darker.sum() > 2000 and (b <= a + 1).all()
    # a callable shadow is asked at every frame
    calls = []
    cam = SimulatedCamera(board, params, seed=1, shadow=lambda: calls.append(1) or None)
    cam.frame()
    cam.frame()
    assert len(calls) == 2


def test_a_pose_turned_on_its_side_has_no_cell_mapping(params):
    pose = CameraPose.beyond_far_edge(params)
    turned = CameraPose(pose.position_m, pose.target_m, roll_deg=90.0)
    with pytest.raises(ValueError, match="roll"):
        turned.view()


def test_opening_a_missing_device_says_so():
    with pytest.raises(CameraError, match="cannot open the device"):
        OpenCVCamera("/dev/video-that-does-not-exist")
    with pytest.raises(CameraError):
        OpenCVCamera(97)


def test_photos_round_trip_through_image_files(params, tmp_path: Path):
    scene = random_scene(params, 11)
    cam = SimulatedCamera(scene.board, params, seed=11)
    paths = []
    for k, ext in enumerate(("png", "bmp")):
        img = cam.frame()
        p = tmp_path / f"photo{k}.{ext}"
        assert cv2.imwrite(str(p), img)
        paths.append(p)
        assert np.array_equal(read_image(p), img)  # lossless formats
    files = ImageFileCamera(paths)
    for _ in range(3):  # the last file repeats
        seen = board_text(detect(files.frame()).cells, cam.view())
        assert seen == scene.text
    jpg = tmp_path / "photo.jpg"
    cv2.imwrite(str(jpg), cam.frame(), [cv2.IMWRITE_JPEG_QUALITY, 85])
    assert board_text(detect(ImageFileCamera([jpg]).frame()).cells, cam.view()) == scene.text
    looped = ImageFileCamera(paths, loop=True)
    assert [np.array_equal(looped.frame(), read_image(p)) for p in paths * 2] == [True] * 4


def test_files_that_are_not_images_are_named_in_the_error(tmp_path: Path):
    text = tmp_path / "notes.png"
    text.write_text("not a picture")
    empty = tmp_path / "empty.png"
    empty.write_bytes(b"")
    with pytest.raises(ImageError, match="notes.png: not an image"):
        ImageFileCamera([text]).frame()
    with pytest.raises(ImageError, match="empty.png: not an image"):
        read_image(empty)
    with pytest.raises(ImageError, match="no such file"):
        read_image(tmp_path / "missing.png")
    with pytest.raises(CameraError, match="at least one"):
        ImageFileCamera([])
    small = tmp_path / "small.png"
    cv2.imwrite(str(small), np.full((100, 120, 3), 255, np.uint8))
    with pytest.raises(ImageError, match="120 x 100 pixels is the wrong size"):
        read_image(small)


@pytest.mark.parametrize("bad, message", [
    ("a string", "expected a numpy array"),
    (np.zeros((480, 640, 3), np.float32), "expected 8-bit pixels"),
    (np.zeros((480, 640, 2), np.uint8), "expected shape"),
    (np.zeros((480,), np.uint8), "expected shape"),
    (np.zeros((200, 640, 3), np.uint8), "wrong size"),
    (np.zeros((480, 5000), np.uint8), "wrong size"),
])
def test_check_image_says_what_is_wrong(bad, message):
    with pytest.raises(ImageError, match=message):
        check_image(bad)
    assert issubclass(ImageError, ValueError)


def test_check_image_accepts_grey_and_drops_alpha():
    assert check_image(np.zeros((480, 640), np.uint8)).shape == (480, 640)
    assert check_image(np.zeros((480, 640, 4), np.uint8)).shape == (480, 640, 3)
    assert check_image(np.zeros((480, 640, 1), np.uint8)).shape == (480, 640)
