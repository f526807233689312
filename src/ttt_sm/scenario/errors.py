"""Errors of the scenario package: each names the file and line it is about."""

from __future__ import annotations


class ScenarioError(ValueError):
    """A scenario file that cannot be read or does not follow the format.

    ``str(error)`` is ``FILE:LINE: message``, the shape editors and terminals
    turn into a link to the line.
    """

    def __init__(self, file: str, line: int, message: str) -> None:
        self.file = file
        self.line = line
        self.message = message
        super().__init__(f"{file}:{line}: {message}" if line else f"{file}: {message}")
