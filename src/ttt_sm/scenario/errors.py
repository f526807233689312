"""Errors of the scenario package: each names the file and line it is about."""

from __future__ import annotations

from collections.abc import Sequence


class ScenarioError(ValueError):
    """A scenario file that cannot be read or does not follow the format.

    ``str(error)`` is ``FILE:LINE: message``, the shape editors and terminals
    turn into a link to the line.  A file with several mistakes raises
    :class:`ScenarioErrors`; :attr:`errors` lists the mistakes either way.
    """

    def __init__(self, file: str, line: int, message: str) -> None:
        self.file = file
        self.line = line
        self.message = message
        super().__init__(f"{file}:{line}: {message}" if line else f"{file}: {message}")

    @property
    def errors(self) -> tuple[ScenarioError, ...]:
        """Each mistake, one ``FILE:LINE: message`` each: here, this one."""
        return (self,)


class ScenarioErrors(ScenarioError):
    """Every mistake the loader found in one file, in the order of their lines, as a compiler reports them.

    Its ``file``, ``line`` and ``message`` are the first mistake's; ``str()`` is
    one ``FILE:LINE: message`` line per mistake.
    """

    def __init__(self, errors: Sequence[ScenarioError]) -> None:
        if len(errors) < 2:
            raise ValueError("ScenarioErrors holds two mistakes or more; raise the one ScenarioError")
        first = errors[0]
        super().__init__(first.file, first.line, first.message)
        self._errors = tuple(errors)
        self.args = ("\n".join(str(e) for e in self._errors),)

    def __str__(self) -> str:
        return self.args[0]

    @property
    def errors(self) -> tuple[ScenarioError, ...]:
        return self._errors

    @staticmethod
    def of(errors: Sequence[ScenarioError]) -> ScenarioError:
        """The error to raise for ``errors`` (at least one): the one, or all of them in line order."""
        unique = list({str(e): e for e in errors}.values())  # one mistake met twice is told once
        unique.sort(key=lambda e: e.line)
        return unique[0] if len(unique) == 1 else ScenarioErrors(unique)
