"""Where a sweep's values go: memory, a NumPy ``.npy`` file mapped into memory, or any
array store the caller gives (a Zarr array), written chunk by chunk.

A store is described by a :class:`Store` (picklable: a path and a layout, or the caller's
array object), so that Dask workers write their own chunks and nothing but small
per-set summaries travels back to the client. Writing a chunk twice (a task recomputed
after its worker was lost) writes the same numbers to the same rows.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..model.errors import SceneError
from ..model.numbers import shown

__all__ = ["Store", "open_store"]


@dataclass(frozen=True)
class Store:
    """A (P, outputs, T) float64 destination.

    Attributes
    ----------
    kind : str
        ``"npy"`` (a file written through ``numpy.memmap``) or ``"array"`` (an object
        with ``__setitem__``, such as a Zarr array).
    path : str
        The file of an ``"npy"`` store.
    offset : int
        Where the data start in the file.
    shape : tuple of int
    target : object
        The array object of an ``"array"`` store.
    """

    kind: str
    shape: tuple[int, ...]
    path: str = ""
    offset: int = 0
    target: Any = None

    def array(self, mode: str = "r+") -> Any:
        """The store as an array (a fresh memory map for ``"npy"``)."""
        if self.kind == "npy":
            return np.memmap(self.path, dtype=np.dtype(np.float64), mode=mode,  # type: ignore[call-overload]
                             offset=self.offset, shape=self.shape)
        return self.target

    def write(self, start: int, values: np.ndarray) -> None:
        """Rows ``start`` … ``start + len(values)`` (flushed to disk for files)."""
        target = self.array()
        target[start:start + values.shape[0]] = values
        if self.kind == "npy":
            target.flush()
            del target


def open_store(out: Any, shape: tuple[int, ...], what: str) -> Store:
    """The :class:`Store` for ``out``: a path (a new ``.npy`` file is created there), a
    ``numpy.memmap`` of the right shape, or an array object with ``shape`` and
    ``__setitem__`` (Zarr).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "x.npy"
    >>> store = open_store(path, (2, 1, 3), "out")
    >>> store.write(1, np.ones((1, 1, 3)))
    >>> np.load(path).sum()
    np.float64(3.0)
    """
    if isinstance(out, (str, os.PathLike)):
        path = os.fspath(out)
        if os.path.isdir(path):
            raise SceneError(f"sweep: {what} = {path!r} is a directory; give a file name (.npy)")
        if not path.endswith(".npy"):
            raise SceneError(f"sweep: {what} = {path!r} must name a .npy file")
        array = np.lib.format.open_memmap(path, mode="w+", dtype=np.float64, shape=shape)
        offset = int(array.offset)
        del array
        return Store("npy", shape, path=path, offset=offset)
    if isinstance(out, np.memmap):
        if out.shape != shape or out.dtype != np.float64 or out.filename is None:
            raise SceneError(f"sweep: {what} must be a float64 memmap of shape {shape}, got "
                             f"{out.dtype} {out.shape}")
        out.flush()
        return Store("npy", shape, path=os.fspath(out.filename), offset=int(out.offset))
    if isinstance(out, np.ndarray):
        if out.shape != shape:
            raise SceneError(f"sweep: {what} must have shape {shape}, got {out.shape}")
        return Store("array", shape, target=out)
    if hasattr(out, "__setitem__") and tuple(getattr(out, "shape", ())) == shape:
        return Store("array", shape, target=out)
    raise SceneError(f"sweep: {what} must be a .npy path, a numpy.memmap or an array with shape "
                     f"{shape} (e.g. a Zarr array), got {shown(out)}")
