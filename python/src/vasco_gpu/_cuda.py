"""Whether the CUDA backend can run here: :func:`cuda_available` and its :class:`CudaStatus`."""

from __future__ import annotations

from typing import Iterator, Union

from . import _core

__all__ = ["CudaStatus", "cuda_available"]


class CudaStatus:
    """The answer of :func:`cuda_available`: true when the CUDA backend can run here.

    ``available`` is that answer and ``reason`` says why not (``''`` when it can run)::

        status = vg.cuda_available()
        if not status:
            print("CPU only:", status.reason)   # e.g. "no GPU found (...)"

    For code written when the answer was a pair it also unpacks and indexes as
    ``(available, reason)``: ``ok, why = vg.cuda_available()``, ``vg.cuda_available()[0]``,
    and compares equal to that pair. It is no tuple, though: its truth is ``available``.
    """

    __slots__ = ("_available", "_reason")

    def __init__(self, available: bool, reason: str = "") -> None:
        object.__setattr__(self, "_available", bool(available))
        object.__setattr__(self, "_reason", str(reason))

    @property
    def available(self) -> bool:
        """True when the CUDA backend can run here (a CUDA build and a usable GPU)."""
        return self._available

    @property
    def reason(self) -> str:
        """Why the CUDA backend cannot run here; ``''`` when it can."""
        return self._reason

    def __bool__(self) -> bool:
        return self._available

    def __iter__(self) -> Iterator[Union[bool, str]]:
        return iter((self._available, self._reason))

    def __getitem__(self, index):
        return (self._available, self._reason)[index]

    def __eq__(self, other: object) -> bool:
        if isinstance(other, CudaStatus):
            return (self._available, self._reason) == (other._available, other._reason)
        if isinstance(other, tuple):
            return (self._available, self._reason) == other
        return NotImplemented

    def __hash__(self) -> int:
        return hash((self._available, self._reason))

    def __setattr__(self, name: str, value: object) -> None:
        raise AttributeError(f"CudaStatus is read-only: cannot set {name!r}")

    def __reduce__(self):
        return (CudaStatus, (self._available, self._reason))

    def __repr__(self) -> str:
        return f"CudaStatus(available={self._available!r}, reason={self._reason!r})"


# What the CUDA runtime says when it finds no GPU to use, and what that means here.
_NO_DEVICE_PREFIX = "no CUDA device ("
_NO_DRIVER = "CUDA driver version is insufficient"
_NO_CAPABLE_DEVICE = "no CUDA-capable device is detected"


def _user_reason(reason: str) -> str:
    """The engine's reason why CUDA cannot run, in the words of a user without a GPU.

    The CUDA runtime's own texts for "there is no GPU" ("no CUDA-capable device is detected",
    and "CUDA driver version is insufficient ..." on a machine without the NVIDIA driver)
    become "no GPU found (...)", the runtime's text kept in the parentheses; other reasons
    (a GPU this build cannot use, a build without CUDA) are passed on as they are.
    """
    not_counted = reason.startswith(_NO_DEVICE_PREFIX) and reason.endswith(")")
    inner = reason[len(_NO_DEVICE_PREFIX):-1] if not_counted else reason
    if _NO_DRIVER in inner:
        return f"no GPU found (no NVIDIA driver, or one too old for this build's CUDA runtime: {inner})"
    if _NO_CAPABLE_DEVICE in inner:
        return f"no GPU found ({inner})"
    if not_counted:  # the runtime could not count the devices, for another reason
        return f"no GPU found (the CUDA runtime says: {inner})"
    if reason.startswith("CUDA device ") and reason.endswith(" (0 present)"):
        return "no GPU found (the CUDA runtime lists no device)"
    return reason


def cuda_available() -> CudaStatus:
    """Whether the CUDA backend can run here (a CUDA build and a usable GPU), and why not.

    Returns a :class:`CudaStatus`, true or false as the answer (``if vg.cuda_available():``);
    its ``reason`` says why not: "no GPU found (...)" on a machine without one, "this build has
    no CUDA backend (...)" for a build made without CUDA, or what keeps the GPU found from
    running this build's kernels. It unpacks as the pair it used to be:
    ``ok, why = vg.cuda_available()``. The first call starts the CUDA context (a few tenths of
    a second); the answer holds for the process.
    """
    ok, why = _core._cuda_available()
    return CudaStatus(True, "") if ok else CudaStatus(False, _user_reason(why))
