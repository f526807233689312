"""The simulated whiteboard: ink from the spring-loaded pen, wiping by the sponge.

The board is the horizontal plane ``z = surface_z`` over the rectangle of
``[board]`` in the parameter file.  :meth:`Whiteboard.update` takes the arm's
TRUE joint angles every chart step and works out what touches the board:

* the **pen** (thesis section 3.3.1): its tip is at the end of the tool axis,
  ``fk(q)[:3]``.  Below the surface the spring lets the pen slide back into
  its holder along the tool axis until the real tip rests on the board
  (``compression``); beyond ``spring_travel`` the holder itself hits the board
  (an *overpress*; the pen still inks).  The 0.4 mm radial clearance of the
  holder lets board friction drag the tip behind the holder's motion by up to
  the thesis' 0.35 mm (eqs. 3.1-3.13): a play operator, see :meth:`Whiteboard.update`.
* the **sponge** (section 3.6.1, Erase): on the lateral surface of the end
  effector, facing the board at phi = 90 deg; it wipes every pixel its square
  pad sweeps.
* a **person's hand** (:meth:`Whiteboard.draw_stroke`, :meth:`Whiteboard.draw_symbol`) for the game.

Ink lives in a raster (``resolution_mm`` per pixel, over the board) and as
stroke polylines with times and an author; the two stay consistent when the
sponge wipes.  :meth:`Whiteboard.render` draws the board as an image
(optionally on millimetre paper like the thesis' figs. 3.19-3.20);
docs/whiteboard.md explains the model, the image orientation and the costs.

One module per idea; this package exports the names users import:

* :mod:`.contact`: the contact physics of pen and sponge (:class:`Contact`);
* :mod:`.raster`: the ink raster;
* :mod:`.strokes`: the ink as polylines, split by wipes (:class:`Stroke`);
* :mod:`.hand`: the person's hand;
* :mod:`.metrics`: what the ink measures;
* :mod:`.render`: pictures of the board;
* :mod:`.board`: :class:`Whiteboard`, the board that puts them together.
"""

from __future__ import annotations

from .board import Whiteboard
from .contact import (
    INK_WIDTH_M,
    PEN_MAX_TILT_RAD,
    SPONGE_MAX_TILT_RAD,
    TIP_DEVIATION_PER_CLEARANCE,
    Contact,
)
from .errors import WhiteboardError
from .hand import HAND_INK_WIDTH_M, HAND_JITTER_M, HAND_SPEED_M_S
from .metrics import CELL_MARGIN_M, TAIL_TOL_M
from .raster import Region
from .render import DESIRED_BGR, GRID_BGR, HAND_INK_BGR, ROBOT_INK_BGR, VIEWS
from .strokes import Stroke

__all__ = [
    "CELL_MARGIN_M",
    "DESIRED_BGR",
    "GRID_BGR",
    "HAND_INK_BGR",
    "HAND_INK_WIDTH_M",
    "HAND_JITTER_M",
    "HAND_SPEED_M_S",
    "INK_WIDTH_M",
    "PEN_MAX_TILT_RAD",
    "ROBOT_INK_BGR",
    "SPONGE_MAX_TILT_RAD",
    "TAIL_TOL_M",
    "TIP_DEVIATION_PER_CLEARANCE",
    "VIEWS",
    "Contact",
    "Region",
    "Stroke",
    "Whiteboard",
    "WhiteboardError",
]
