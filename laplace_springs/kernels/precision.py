"""Working precision of mpmath and python-flint, one thread at a time.

Both libraries keep a single, process-wide working precision (``mpmath.mp.prec``,
``flint.ctx.prec``), not one per thread. A section that raises it and a thread that
computes at the same time share it: a sweep's chunks on Dask worker threads, each
escalating some times to an arbitrary-precision engine, could compute at each other's
precision (mpmath's digits would then be wrong; arb's balls stay rigorous but wide) or
leave the precision raised. Every precision section of the package goes through these
context managers, which hold one re-entrant lock while the precision is theirs. Both
libraries hold the GIL while they compute, so the lock costs threads no parallelism.

Examples
--------
>>> import mpmath
>>> with workdps(40):
...     mpmath.mp.dps
40
>>> import flint
>>> with flint_workprec(200):
...     flint.ctx.prec
200
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from contextlib import contextmanager

import mpmath
from flint import ctx

__all__ = ["workdps", "workprec", "flint_workprec", "flint_workdps"]

#: Held while a section's precision is in force (re-entrant: sections nest).
_LOCK = threading.RLock()


@contextmanager
def workdps(dps: int) -> Iterator[None]:
    """``mpmath.workdps(dps)`` under the package's precision lock."""
    with _LOCK, mpmath.workdps(dps):
        yield


@contextmanager
def workprec(bits: int) -> Iterator[None]:
    """``mpmath.workprec(bits)`` under the package's precision lock."""
    with _LOCK, mpmath.workprec(bits):
        yield


@contextmanager
def flint_workprec(bits: int) -> Iterator[None]:
    """python-flint's working precision set to ``bits`` (restored after), under the lock."""
    with _LOCK:
        saved = ctx.prec
        ctx.prec = bits
        try:
            yield
        finally:
            ctx.prec = saved


@contextmanager
def flint_workdps(dps: int) -> Iterator[None]:
    """python-flint's working precision set to ``dps`` digits (restored after), under the
    lock."""
    with _LOCK:
        saved = ctx.prec
        ctx.dps = dps
        try:
            yield
        finally:
            ctx.prec = saved
