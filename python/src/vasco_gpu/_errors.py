"""The exceptions vasco_gpu raises: one class per kind of failure of the C++ engine.

Every error of the engine carries a code (carmen_compat/error.h's ``ErrorCode``) and the
module picks the class from that code, never from the message. Each class is also the
built-in exception that callers catch for that kind of failure, so ``except ValueError`` or
``except RuntimeError`` keep working:

=================  ============================  ============================
code               class                         also a
=================  ============================  ============================
usage              :class:`UsageError`           ValueError
bad input          :class:`BadInputError`        ValueError
too large          :class:`TooLargeError`        ValueError, RuntimeError
out of memory      :class:`OutOfMemoryError`     MemoryError, RuntimeError
no GPU             :class:`NoGpuError`           RuntimeError
state              :class:`StateError`           RuntimeError
I/O                :class:`IoError`              OSError
internal           :class:`InternalError`        RuntimeError
=================  ============================  ============================

A failure about one file is a :class:`FileError` (with ``.file`` and ``.line``), whatever
its code.
"""

from __future__ import annotations


class Error(Exception):
    """Base of vasco_gpu's exceptions. ``code``: the engine's error code ("bad input", ...)."""

    code = "internal"


class UsageError(Error, ValueError):
    """A bad argument: an unknown name, a value out of range."""

    code = "usage"


class BadInputError(Error, ValueError):
    """An array or map whose content cannot be trusted (inconsistent offsets, NaN cells)."""

    code = "bad input"


class TooLargeError(Error, ValueError, RuntimeError):
    """Beyond a hard limit: grid cells, beam counts, shapes."""

    code = "too large"


class OutOfMemoryError(Error, MemoryError, RuntimeError):
    """Over the memory budget the session was given, or an allocation failed."""

    code = "out of memory"


class NoGpuError(Error, RuntimeError):
    """The CUDA backend cannot run here."""

    code = "no GPU"


class StateError(Error, RuntimeError):
    """The call does not fit the object's state (finish before any insert)."""

    code = "state"


class IoError(Error, OSError):
    """The file system refused: cannot open, write, rename, lock."""

    code = "I/O"


class InternalError(Error, RuntimeError):
    """A bug of vasco_gpu's, or a CUDA failure it did not foresee."""

    code = "internal"


# The class of each code name, as carmen::error_code_name spells it.
BY_CODE = {cls.code: cls for cls in (UsageError, BadInputError, TooLargeError, OutOfMemoryError, NoGpuError,
                                     StateError, IoError, InternalError)}


class FileError(Error, OSError, ValueError):
    """A file that cannot be read, parsed or trusted (a log, a carmen.ini, a map).

    ``str(error)`` is ``"FILE:LINE: what is wrong"`` (``"FILE: what is wrong"`` when no line
    applies). It is both an :class:`OSError` (a file could not be used) and a
    :class:`ValueError` (its content is wrong), so either ``except`` catches it.

    Attributes:
        file: the file the error is about.
        line: the 1-based line, or ``None`` when none applies.
        message: what is wrong, without the location.
        code: the engine's error code ("bad input", or "I/O" when the file system refused).
    """

    code = "bad input"

    def __init__(self, text: str, file: str | None = None, line: int | None = None,
                 message: str | None = None, code: str = "bad input") -> None:
        super().__init__(text)
        self.file = file
        self.line = line
        self.message = message if message is not None else text
        self.code = code

    def __str__(self) -> str:
        return str(self.args[0]) if self.args else ""

    def __reduce__(self):
        return (type(self), (self.args[0] if self.args else "", self.file, self.line, self.message, self.code))
