"""glibc's allocator thresholds during a sweep task (Dask workers run with a fixed trim
threshold that makes NumPy temporaries cost page faults).

glibc serves an allocation above its mmap threshold (128 KiB at start) with a fresh
``mmap`` and returns it with ``munmap``; normally the threshold rises to the size of the
blocks freed (up to 32 MiB) and such blocks are reused from the heap. Setting any of
``MALLOC_TRIM_THRESHOLD_``, ``MALLOC_MMAP_THRESHOLD_``, ``MALLOC_TOP_PAD_``,
``MALLOC_MMAP_MAX_`` (or the matching ``GLIBC_TUNABLES``) switches that adjustment off for
the life of the process, and a Dask nanny starts every worker with
``MALLOC_TRIM_THRESHOLD_=65536`` (``distributed.nanny.pre-spawn-environ``). A sweep chunk
makes thousands of NumPy temporaries of a few hundred KiB to a few MiB (the double-double
residuals behind the bounds): in such a worker each one is mapped, zero-filled page by page
and unmapped, 14 times the page faults of a plain process and 1.5 to 1.8 times its time.

:func:`roomy_allocator` raises the two thresholds to the values the adjustment would
reach (32 MiB, and twice that for trimming) while a task runs, and when the last task
running in the process ends it puts back the thresholds the environment set and returns
the free memory to the system (``malloc_trim``), so the worker's memory between tasks is
what its settings ask for. It does nothing where the adjustment is on (a plain process:
calling ``mallopt`` there would switch it off for good) and off glibc.
"""

from __future__ import annotations

import ctypes
import os
import platform
import threading
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from typing import Any

__all__ = ["fixed_thresholds", "roomy_allocator"]

M_TRIM_THRESHOLD = -1
M_MMAP_THRESHOLD = -3
DEFAULT_THRESHOLD = 128 * 1024  # glibc's start value of both thresholds
ROOMY_MMAP = 32 * 1024 * 1024  # the ceiling of glibc's own adjustment on 64-bit systems
ROOMY_TRIM = 2 * ROOMY_MMAP  # the adjustment keeps trim = 2 x mmap threshold

#: Environment variables (and tunables) that switch glibc's adjustment off.
FIXING = ("MALLOC_TRIM_THRESHOLD_", "MALLOC_MMAP_THRESHOLD_", "MALLOC_TOP_PAD_", "MALLOC_MMAP_MAX_")
TUNABLES = ("glibc.malloc.trim_threshold", "glibc.malloc.mmap_threshold", "glibc.malloc.top_pad",
            "glibc.malloc.mmap_max")


def _setting(environ: Mapping[str, str], variable: str, tunable: str) -> int | None:
    """The value of a threshold fixed by the environment (None: not set or unreadable)."""
    text = environ.get(variable)
    for item in environ.get("GLIBC_TUNABLES", "").replace(":", " ").split():
        name, _, value = item.partition("=")
        if name == tunable:
            text = value
    try:
        return None if text is None else int(text, 0)
    except ValueError:
        return None


def fixed_thresholds(environ: Mapping[str, str]) -> tuple[int, int] | None:
    """The (trim, mmap) thresholds a process started with ``environ`` runs under, or None
    when glibc adjusts them itself (nothing to do).

    Examples
    --------
    >>> fixed_thresholds({"MALLOC_TRIM_THRESHOLD_": "65536"})
    (65536, 131072)
    >>> fixed_thresholds({"PATH": "/usr/bin"}) is None
    True
    """
    tunables = environ.get("GLIBC_TUNABLES", "")
    if not (any(name in environ for name in FIXING) or any(name in tunables for name in TUNABLES)):
        return None
    trim = _setting(environ, "MALLOC_TRIM_THRESHOLD_", "glibc.malloc.trim_threshold")
    mmap = _setting(environ, "MALLOC_MMAP_THRESHOLD_", "glibc.malloc.mmap_threshold")
    return (DEFAULT_THRESHOLD if trim is None else trim, DEFAULT_THRESHOLD if mmap is None else mmap)


def _libc() -> Any:
    """glibc's handle with ``mallopt`` and ``malloc_trim``, or None elsewhere."""
    if platform.system() != "Linux" or platform.libc_ver()[0] != "glibc":
        return None
    try:
        libc = ctypes.CDLL("libc.so.6")
        return libc if hasattr(libc, "mallopt") and hasattr(libc, "malloc_trim") else None
    except OSError:  # pragma: no cover - depends on the system
        return None


_FIXED = fixed_thresholds(os.environ)  # glibc read the environment at start: so do we, once
_LIBC = _libc() if _FIXED is not None else None
_LOCK = threading.Lock()
_RUNNING = [0]  # tasks of this process inside roomy_allocator (threads of one worker)


@contextmanager
def roomy_allocator() -> Iterator[None]:
    """Run the block with glibc's thresholds at 32 MiB (mmap) and 64 MiB (trim) when the
    process fixed them lower (see the module notes); a no-op otherwise.

    Examples
    --------
    >>> import numpy as np
    >>> with roomy_allocator():
    ...     total = float(np.ones(100_000).sum())
    >>> total
    100000.0
    """
    if _LIBC is None or _FIXED is None:
        yield
        return
    with _LOCK:
        _RUNNING[0] += 1
        if _RUNNING[0] == 1:
            _LIBC.mallopt(M_MMAP_THRESHOLD, max(ROOMY_MMAP, _FIXED[1]))
            _LIBC.mallopt(M_TRIM_THRESHOLD, max(ROOMY_TRIM, _FIXED[0]))
    try:
        yield
    finally:
        with _LOCK:
            _RUNNING[0] -= 1
            if _RUNNING[0] == 0:
                _LIBC.mallopt(M_MMAP_THRESHOLD, _FIXED[1])
                _LIBC.mallopt(M_TRIM_THRESHOLD, _FIXED[0])
                _LIBC.malloc_trim(0)
