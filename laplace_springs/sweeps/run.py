"""``sweep``: one symbolic solve, many parameter sets, vectorised and chunked."""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp

from ..limits import limits
from ..model.errors import SceneError
from ..model.numbers import shown
from ..model.scene import Scene
from ..numeric.times import as_times
from ..policy import check_target
from .chunks import evaluate_rows
from .compile import CompiledScene, compile_scene, parameter_rows
from .distributed import run_on_client

__all__ = ["SweepResult", "ParameterGrid", "grid", "sweep"]



class ParameterGrid(dict):  # type: ignore[type-arg,unused-ignore]
    """The mapping parameter -> values of a Cartesian product, with its ``shape``.

    ``values.reshape(grid.shape + values.shape[1:])`` puts a sweep's result on the grid.
    """

    shape: tuple[int, ...]


def grid(*args: Mapping[Any, Any], **axes: Any) -> ParameterGrid:
    """The Cartesian product of parameter values, one row per combination.

    Parameters
    ----------
    *args : mapping, optional
        Parameter (name or Symbol) -> 1-D values.
    **axes
        More parameters by name.

    Returns
    -------
    ParameterGrid
        A dict name -> flat array (all of length Π len(values)), first parameter slowest;
        ``.shape`` is the grid's shape.

    Examples
    --------
    >>> g = grid({"k": [1, 2]}, c=[0.1, 0.2, 0.3])
    >>> g.shape, g["k"].tolist(), g["c"].tolist()
    ((2, 3), [1.0, 1.0, 1.0, 2.0, 2.0, 2.0], [0.1, 0.2, 0.3, 0.1, 0.2, 0.3])
    """
    items: dict[str, Any] = {}
    for mapping in (*args, axes):
        if not isinstance(mapping, Mapping):
            raise SceneError(f"grid: expected a mapping parameter -> values, got {shown(mapping)}")
        for key, value in mapping.items():
            name = key.name if isinstance(key, sp.Symbol) else key
            if not isinstance(name, str):
                raise SceneError(f"grid: parameter names must be strings or Symbols, got {shown(key)}")
            if name in items:
                raise SceneError(f"grid: parameter {name!r} is given twice")
            try:
                array = np.asarray(value, dtype=float).ravel()
            except (TypeError, ValueError):
                raise SceneError(f"grid: values of {name!r} must be real numbers, got {shown(value)}") from None
            if array.size == 0:
                raise SceneError(f"grid: parameter {name!r} has no values")
            items[name] = array
    shape = tuple(a.size for a in items.values())
    mesh = np.meshgrid(*items.values(), indexing="ij") if items else []
    result = ParameterGrid({name: m.ravel() for name, m in zip(items, mesh)})
    result.shape = shape
    return result


@dataclass
class SweepResult:
    """What :func:`sweep` returns with ``return_error=True``.

    Attributes
    ----------
    values : ndarray
        (P, n, T) values, one row per parameter set.
    error : ndarray
        (P, n, T) error estimates (absolute), as ``evaluate(return_error=True)`` gives.
    set_error : ndarray
        (P,) each set's largest error relative to max(‖x(t)‖∞, S₀).
    exact_sets : ndarray
        Indices of the sets that were evaluated one by one by the exact solver
        (nearly degenerate roots whose estimate missed the target, or data the
        vectorised path refused).
    roots : ndarray
        (P, N) complex roots of each set's denominator D(λ) (NaN for exact sets).
    names : tuple of str
        The coordinates of the second axis.
    """

    values: np.ndarray
    error: np.ndarray
    set_error: np.ndarray
    exact_sets: np.ndarray
    roots: np.ndarray
    names: tuple[str, ...]


def _outputs(scene: Scene, outputs: Any) -> list[int]:
    if outputs == "x" or outputs is None:
        return list(range(scene.n))
    items = [outputs] if isinstance(outputs, (str, int)) else list(outputs)
    chosen = []
    for item in items:
        if isinstance(item, (int, np.integer)) and not isinstance(item, bool) and 0 <= item < scene.n:
            chosen.append(int(item))
        elif isinstance(item, str) and item in scene.names:
            chosen.append(scene.names.index(item))
        elif isinstance(item, str) and item in scene.mass_names:
            chosen.append(scene.mass_names.index(item))
        else:
            raise SceneError(f"sweep: outputs: {shown(item)} is not a coordinate; coordinates are "
                             f"{', '.join(scene.names)} (or indices 0..{scene.n - 1})")
    return chosen


def _chunk_size(chunk: int | None, compiled: CompiledScene, T: int) -> int:
    if chunk is not None:
        if isinstance(chunk, bool) or not isinstance(chunk, (int, np.integer)) or chunk < 1:
            raise SceneError(f"sweep: chunk must be a positive integer, got {shown(chunk)}")
        return int(chunk)
    per_set = 16 * max(compiled.degree, 1) * max(T, 1) * max(len(compiled.numerators), 1)
    return max(64, min(50_000, limits().chunk_bytes // per_set))


def _progress(progress: Any) -> Callable[[int, int], None] | None:
    if progress is None or progress is False:
        return None
    if progress is True:
        def report(done: int, total: int) -> None:
            print(f"sweep: {done:,} of {total:,} parameter sets", file=sys.stderr, flush=True)
        return report
    if callable(progress):
        return progress  # type: ignore[no-any-return,unused-ignore]
    raise SceneError(f"sweep: progress must be True, False, None or a callable(done, total), "
                     f"got {shown(progress)}")


def sweep(scene: Scene, values: Mapping[Any, Any], times: Any, *, outputs: Any = "x",
          derivative: int = 0, client: Any = None, chunk: int | None = None,
          return_error: bool = False, target: float | None = None,
          progress: Any = None) -> np.ndarray | SweepResult:
    """Evaluate a symbolic scene's motion for many parameter sets at once.

    The scene is solved once, symbolically: the coefficients of D(λ) = det(λ²M + λC + K)
    (times the forces' denominator) and of each coordinate's numerator become NumPy
    functions of the parameters. Each chunk of parameter sets then gets its roots from
    one batched companion-matrix eigenvalue call, polished by Newton's method on the
    exact-coefficient polynomial; isolated roots contribute residue terms, clusters of
    close roots (critical damping, exceptional points, resonance) a divided difference
    computed without cancellation. Every set meets the contract of
    ``ls.solve(scene.subs(set)).evaluate(times)``: a set whose error estimate misses the
    target is recomputed that way.

    Parameters
    ----------
    scene : Scene
        A scene with declared parameters (``scene.parameters``), at most 8 coordinates;
        forces, if any, without delays.
    values : mapping
        Each parameter (name or Symbol) -> a number or a 1-D array; arrays share one
        length P (one parameter set per index). :func:`grid` builds a Cartesian product.
    times : array_like
        Nonnegative evaluation times (as for ``Solution.evaluate``).
    outputs : "x", str, int or sequence, optional
        The coordinates to return (names or indices); ``"x"`` is all of them.
    derivative : {0, 1, 2}, optional
        Return x, x' or x''.
    client : dask.distributed.Client, optional
        Run the chunks on this cluster (needs ``pip install "laplace-springs[dask]"``);
        the result is identical to the local one.
    chunk : int, optional
        Parameter sets per chunk (default: as many as fit in about 32 MB).
    return_error : bool, optional
        Return a :class:`SweepResult` with error estimates instead of the bare array.
    target : float, optional
        Relative accuracy (default :data:`laplace_springs.TARGET`).
    progress : bool or callable, optional
        ``True`` prints a line per chunk to stderr; a callable gets ``(done, total)``.

    Returns
    -------
    ndarray or SweepResult
        Values of shape (P, len(outputs), len(times)).

    Raises
    ------
    SceneError
        For a missing or unknown parameter, arrays of different lengths, a value that
        breaks the parameter's assumptions (a nonpositive stiffness), bad outputs.

    Examples
    --------
    A mass on a spring k with a dashpot c, released from x = 1; c = 2 is critical:

    >>> import laplace_springs as ls
    >>> from laplace_springs.sweeps import sweep
    >>> scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0],
    ...                                parameters=["c", "k"])
    >>> x = sweep(scene, {"k": [1, 1, 4], "c": [2, 0.5, 4]}, [0, 1, 2])
    >>> x.shape
    (3, 1, 3)
    >>> import numpy as np
    >>> bool(np.allclose(x[0, 0], [(1 + t) * np.exp(-t) for t in (0, 1, 2)], rtol=1e-13))
    True
    >>> bool(np.allclose(x[2, 0], [(1 + 2 * t) * np.exp(-2 * t) for t in (0, 1, 2)], rtol=1e-13))
    True
    """
    if not isinstance(scene, Scene):
        raise SceneError(f"sweep: expected a Scene, got {shown(scene)}")
    if derivative not in (0, 1, 2) or isinstance(derivative, bool):
        raise SceneError(f"sweep: derivative must be 0, 1 or 2, got {shown(derivative)}")
    if not isinstance(return_error, bool):
        raise SceneError(f"sweep: return_error must be True or False, got {shown(return_error)}")
    goal = check_target(target)
    chosen = _outputs(scene, outputs)
    compiled = compile_scene(scene)
    rows = parameter_rows(compiled, values)
    grid_times = as_times(times).hi
    size = _chunk_size(chunk, compiled, grid_times.size)
    bounds = [(start, min(start + size, len(rows))) for start in range(0, len(rows), size)]
    report = _progress(progress)
    if client is not None:
        parts = run_on_client(client, compiled, rows, bounds, grid_times, derivative, goal, report)
    else:
        parts = []
        for start, stop in bounds:
            parts.append(evaluate_rows(compiled, rows[start:stop], grid_times,
                                       derivative=derivative, target=goal))
            if report is not None:
                report(stop, len(rows))
    if parts:
        result_values = np.concatenate([p[0] for p in parts])[:, chosen]
        error = np.concatenate([p[1] for p in parts])[:, chosen]
        exact_mask = np.concatenate([p[2] for p in parts])
        roots = np.concatenate([p[3] for p in parts])
        set_error = np.concatenate([p[4] for p in parts])
    else:  # pragma: no cover - P >= 1 always
        result_values = error = np.zeros((0, len(chosen), grid_times.size))
        exact_mask, roots = np.zeros(0, bool), np.zeros((0, compiled.degree), complex)
        set_error = np.zeros(0)
    if not return_error:
        return result_values
    names = tuple(scene.names[i] for i in chosen)
    roots = np.where(exact_mask[:, None], np.nan, roots)
    return SweepResult(result_values, error, set_error, np.flatnonzero(exact_mask), roots, names)
