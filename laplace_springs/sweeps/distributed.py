"""Running a sweep's chunks on a Dask cluster (the optional ``dask`` extra)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..model.errors import SceneError
from ..model.numbers import shown
from .chunks import evaluate_rows
from .compile import CompiledScene

__all__ = ["run_on_client"]


def run_on_client(client: Any, compiled: CompiledScene, rows: np.ndarray,
                  bounds: list[tuple[int, int]], times: np.ndarray, derivative: int,
                  target: float, report: Callable[[int, int], None] | None) -> list[Any]:
    """Evaluate the chunks ``rows[start:stop]`` on ``client``; results in chunk order.

    Each chunk runs the same code as the local path (the compiled scene is sent once;
    its NumPy functions are rebuilt on the workers), so the results are identical.
    """
    try:
        from distributed import as_completed
    except ImportError:  # pragma: no cover - depends on the environment
        raise ImportError("sweep(client=...) needs Dask: pip install \"laplace-springs[dask]\" "
                          "(dask and distributed)") from None
    if not (hasattr(client, "submit") and hasattr(client, "scatter")):
        raise SceneError(f"sweep: client must be a dask.distributed.Client, got {shown(client)}")
    shared = client.scatter(compiled, broadcast=True)
    futures = [client.submit(evaluate_rows, shared, rows[start:stop], times,
                             derivative=derivative, target=target, pure=False)
               for start, stop in bounds]
    index = {future.key: k for k, future in enumerate(futures)}
    results: list[Any] = [None] * len(futures)
    done = 0
    for future in as_completed(futures):
        k = index[future.key]
        results[k] = future.result()
        done += bounds[k][1] - bounds[k][0]
        if report is not None:
            report(done, len(rows))
    return results
