"""Running a sweep's chunks on a Dask cluster (the optional ``dask`` extra).

Each chunk is one task running :func:`~laplace_springs.sweeps.tasks.run_chunk`, the code
the local path runs, so the results are identical. Chunks are cut by estimated cost
(:func:`~laplace_springs.sweeps.paths.chunk_bounds`), results are collected as they
complete and released at once (the client holds one chunk at a time; values written to a
file or a shared store never travel), and a worker lost in the middle costs only its
tasks: the scheduler runs them again on the workers left (tasks are pure functions of
their arguments, so a chunk computed twice writes the same rows twice and is counted
once here).

A task runs under the caller's limits (:func:`~laplace_springs.limits.using_limits` is
per thread: the workers would otherwise use the defaults and give other numbers), and
with glibc's allocator thresholds raised while it runs
(:mod:`~laplace_springs.sweeps.allocator`): a Dask nanny starts its workers with
``MALLOC_TRIM_THRESHOLD_=65536``, under which a chunk's NumPy temporaries cost 14 times
the page faults and each task ran at about half speed, so 2 workers were no faster than
one process. Both apply per task, so they hold for any client, workers that join later
included.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ..limits import limits
from ..model.errors import SceneError
from ..model.numbers import shown
from .parameters import ParameterSets
from .paths import SweepPlan
from .tasks import TaskResult, run_chunk

__all__ = ["run_on_client"]


def run_on_client(client: Any, plan: SweepPlan, sets: ParameterSets, bounds: list[tuple[int, int]],
                  options: dict[str, Any], collect: Callable[[TaskResult], None],
                  report: Callable[[int, int], None] | None) -> None:
    """Run the chunks ``bounds`` on ``client``; ``collect`` gets each chunk's result once,
    in the order they complete."""
    try:
        from distributed import as_completed
    except ImportError:  # pragma: no cover - depends on the environment
        raise ImportError("sweep(client=...) needs Dask: pip install \"laplace-springs[dask]\" "
                          "(dask and distributed)") from None
    if not (hasattr(client, "submit") and hasattr(client, "gather")):
        raise SceneError(f"sweep: client must be a dask.distributed.Client, got {shown(client)}")
    futures = {}
    options = {**options, "limits": limits()}  # the caller's, not the workers' defaults
    for start, stop in bounds:  # each task carries its own sets: nothing to lose but the task
        future = client.submit(run_chunk, plan, sets.subset(start, stop), start, pure=False,
                               **options)
        futures[future.key] = (future, start, stop)
    done = 0
    for future in as_completed([f for f, _, _ in futures.values()]):
        _, start, stop = futures.pop(future.key)
        result = future.result()
        future.release()
        collect(result)
        done += stop - start
        if report is not None:
            report(done, len(sets))
