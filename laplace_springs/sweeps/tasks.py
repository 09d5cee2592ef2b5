"""One chunk of a sweep as a self-contained task: evaluate, reduce, write, summarise.

The same function runs in the caller's process and on Dask workers, so the two give the
same numbers. What it returns is small unless the caller keeps the values in memory: the
values and bounds go to their stores (written by the task itself when the store is a
file or a shared array), the quantities are reduced, and only per-set summaries travel.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from ..limits import Limits, using_limits
from .allocator import roomy_allocator
from .chunks import ChunkResult, evaluate_chunk
from .parameters import ParameterSets
from .paths import SweepPlan
from .reduce import reduce_chunk
from .stores import Store

__all__ = ["TaskResult", "run_chunk"]


@dataclass
class TaskResult:
    """What one chunk returns (values and error only when the client keeps them)."""

    start: int
    stop: int
    set_error: np.ndarray
    alone: np.ndarray
    roots: np.ndarray
    failures: list[tuple[int, str]] = field(default_factory=list)
    quantities: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    values: np.ndarray | None = None
    error: np.ndarray | None = None


def writes_itself(store: Store | None) -> bool:
    """Whether a task writes to ``store`` itself (a file, or a shared array such as Zarr);
    an in-memory NumPy array is filled by the caller."""
    return store is not None and not isinstance(store.target, np.ndarray)


def run_chunk(plan: SweepPlan, sets: ParameterSets, start: int, times: np.ndarray, *,
              outputs: list[int], order: int, target: float, on_error: str,
              stores: tuple[Store | None, Store | None] = (None, None),
              quantities: Mapping[str, Any] | None = None,
              keep: tuple[bool, bool] = (True, False), limits: Limits | None = None) -> TaskResult:
    """Evaluate the chunk ``sets`` (rows ``start`` … ``start + len(sets) − 1`` of the
    sweep) and deliver them (see the module notes).

    ``stores`` are the destinations of values and bounds (None: returned to the caller if
    ``keep`` says so). ``limits`` are the caller's (a task on a Dask worker runs under them,
    not under the worker's defaults; None: those in force). The evaluation runs under
    :func:`~.allocator.roomy_allocator` (a Dask worker fixes glibc's thresholds low, which
    costs the chunk's NumPy temporaries page faults and up to half its speed).
    """
    changes = {} if limits is None else {f.name: getattr(limits, f.name) for f in fields(limits)}
    with using_limits(**changes), roomy_allocator():
        return _deliver(evaluate_chunk(plan, sets, times, outputs=outputs, order=order,
                                       target=target, on_error=on_error),
                        start, times, stores, quantities, keep)


def _deliver(result: ChunkResult, start: int, times: np.ndarray,
             stores: tuple[Store | None, Store | None], quantities: Mapping[str, Any] | None,
             keep: tuple[bool, bool]) -> TaskResult:
    """Reduce, write and summarise one evaluated chunk (see :func:`run_chunk`)."""
    out = TaskResult(start, start + result.values.shape[0], result.set_error, result.alone,
                     result.roots, result.failures)
    if quantities:
        out.quantities = reduce_chunk(quantities, result.values, result.error, times)
    for array, store, wanted, name in ((result.values, stores[0], keep[0], "values"),
                                       (result.error, stores[1], keep[1], "error")):
        if writes_itself(store):
            assert store is not None
            store.write(start, array)
        elif wanted or store is not None:
            setattr(out, name, array)
    return out
