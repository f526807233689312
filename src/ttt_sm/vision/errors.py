"""Exceptions of the vision package: each names what was wrong and what to do.

All are ``ValueError`` subclasses through :class:`VisionError`, so a caller
(the CLI, the game) can catch the whole family with one clause.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import ClassVar

Cell = tuple[int, int]


class VisionError(ValueError):
    """Something the vision package was given, or saw, that it cannot use."""


class ImageError(VisionError):
    """The input is not a usable camera image: not an array, wrong type, shape or size, unreadable file."""


class GridNotFoundError(VisionError):
    """No 5x5 field (4 + 4 drawn lines) could be located in the image."""


class CameraError(VisionError):
    """A camera could not be opened or did not deliver a frame."""


class OrientationError(VisionError):
    """A photo is turned or mirrored against the camera placement (its ``view``): reading it would
    put every symbol in the wrong cell."""


def _cells_text(cells: Iterable[Cell]) -> str:
    return ", ".join(f"({r}, {c})" for r, c in cells)


class MoveError(VisionError):
    """What the camera sees is not one legal move of the person (percent-process, thesis 3.6.3).

    Attributes
    ----------
    cells : tuple[tuple[int, int], ...]
        The board cells (row, column) concerned, 1-based.
    message_for_person : str
        A sentence the game can show the person (what to do about it).
    """

    def __init__(self, message: str, cells: Iterable[Cell], message_for_person: str) -> None:
        super().__init__(message)
        self.cells: tuple[Cell, ...] = tuple(cells)
        self.message_for_person = message_for_person


class _CellsMoveError(MoveError):
    """A :class:`MoveError` about the cells it is given: a subclass declares its two sentences.

    ``what`` (the message) and ``advice`` (:attr:`MoveError.message_for_person`)
    are format strings of ``{n}``, how many cells, and ``{cells}``, them.
    """

    what: ClassVar[str]
    advice: ClassVar[str]

    def __init__(self, cells: Iterable[Cell]) -> None:
        cells = tuple(cells)
        named = {"n": len(cells), "cells": _cells_text(cells)}
        super().__init__(self.what.format(**named), cells, self.advice.format(**named))


class TooManyMovesError(_CellsMoveError):
    """Two or more new symbols appeared at once: only one move per turn."""

    what = "{n} new symbols at once in cells {cells}; one move per turn"
    advice = "I see {n} new symbols ({cells}). Please draw only one per turn and wipe the others."


class RobotCellMarkedError(_CellsMoveError):
    """The person drew into a cell the robot already occupies."""

    what = "new ink in the robot's cell(s) {cells}"
    advice = "Cell {cells} is already mine. Please wipe your mark there and draw in an empty cell."


class SymbolVanishedError(_CellsMoveError):
    """A symbol that was on the board (the robot's or the person's) is gone."""

    what = "symbol(s) disappeared from cell(s) {cells}"
    advice = "The symbol in {cells} has disappeared. Please redraw it (or restart the game)."


class PictureTurnedError(_CellsMoveError, OrientationError):
    """The symbols on the board are where a turned or mirrored camera picture would put them."""

    what = ("the marks of cells {cells} are seen where a turned or mirrored camera picture would put them;"
            " the camera's picture is turned or mirrored")
    advice = ("My marks appear where a turned or mirrored camera picture would put them. Please fix the camera"
              " (its mounting or its mirror setting), then play on.")
