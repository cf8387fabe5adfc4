"""The exception vasco_gpu raises for bad input files."""

from __future__ import annotations


class FileError(OSError, ValueError):
    """A file that cannot be read, parsed or trusted (a log, a carmen.ini, a map).

    ``str(error)`` is ``"FILE:LINE: what is wrong"`` (``"FILE: what is wrong"`` when no line
    applies). It is both an :class:`OSError` (a file could not be used) and a
    :class:`ValueError` (its content is wrong), so either ``except`` catches it.

    Attributes:
        file: the file the error is about.
        line: the 1-based line, or ``None`` when none applies.
        message: what is wrong, without the location.
    """

    def __init__(self, text: str, file: str | None = None, line: int | None = None,
                 message: str | None = None) -> None:
        super().__init__(text)
        self.file = file
        self.line = line
        self.message = message if message is not None else text

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""

    def __reduce__(self):
        return (type(self), (self.args[0] if self.args else "", self.file, self.line, self.message))
