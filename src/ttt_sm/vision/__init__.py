"""Vision: cameras, locating the drawn field, reading its cells, the person's moves (thesis 3.6.3).

``camera`` (the :class:`Camera` protocol, :class:`OpenCVCamera`,
:class:`ImageFileCamera`), ``simulated`` (:class:`SimulatedCamera`: the
twin's whiteboard in perspective, lit unevenly, blurred, noisy), ``grid``
(the 4 + 4 lines and the field's homography), ``detect`` (per-cell ink
shares, X or O), ``orientation`` (image cells -> board cells), ``percent``
(percent-process: the person's moves, illegal ones reported), ``scenes``
and ``bench`` (simulated photos and the accuracy / speed targets).
docs/vision.md explains it all with pictures.

Detection and percent-process import no robot code; only the simulated
camera and the scenes use the twin.
"""

from .camera import Camera, ImageFileCamera, OpenCVCamera, check_image, read_image
from .detection import Detection, detect
from .errors import (
    CameraError,
    GridNotFoundError,
    ImageError,
    MoveError,
    OrientationError,
    PictureTurnedError,
    RobotCellMarkedError,
    SymbolVanishedError,
    TooManyMovesError,
    VisionError,
)
from .grid import Grid, locate_grid
from .orientation import (
    board_cell,
    board_text,
    board_values,
    check_orientation,
    check_robot_marks,
    establish_orientation,
    image_cell,
    image_text,
)
from .percent import PersonMoves, percent_process, read_moves, robot_ink_after_move

__all__ = [
    "Camera", "ImageFileCamera", "OpenCVCamera", "check_image", "read_image",
    "Detection", "detect", "Grid", "locate_grid",
    "board_cell", "board_text", "board_values", "image_cell", "image_text", "check_orientation", "check_robot_marks",
    "establish_orientation",
    "PersonMoves", "percent_process", "read_moves", "robot_ink_after_move",
    "VisionError", "ImageError", "GridNotFoundError", "CameraError",
    "MoveError", "TooManyMovesError", "RobotCellMarkedError", "SymbolVanishedError", "OrientationError",
    "PictureTurnedError",
]
