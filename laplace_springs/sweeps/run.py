"""``sweep``: one symbolic solve, many parameter sets, vectorised and chunked."""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import sympy as sp

from ..limits import limits
from ..model.errors import LimitError, SceneError
from ..model.names import coordinate_index
from ..model.numbers import shown
from ..model.scene import Scene
from ..numeric.first_order import scene_cache
from ..numeric.times import as_times
from ..policy import check_target
from .distributed import run_on_client
from .parameters import check_flat, parameter_sets
from .paths import SweepPlan, chunk_bounds, set_costs, sweep_plan
from .reduce import check_increasing, quantity_spec
from .stores import open_store
from .tasks import TaskResult, run_chunk, writes_itself
from .validate import validate_sets

__all__ = ["SweepResult", "ParameterGrid", "grid", "sweep", "plan_sweep"]



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
        Parameter (name or Symbol) -> a number or 1-D values (an array of more axes is a
        SceneError naming it and its shape: flatten it yourself).
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
            check_flat(value, f"grid: values of {name!r}")
            try:
                array = np.asarray(value, dtype=float).ravel()  # a number is one value
            except (TypeError, ValueError):
                raise SceneError(f"grid: values of {name!r} must be real numbers, got {shown(value)}") from None
            if array.size == 0:
                raise SceneError(f"grid: parameter {name!r} has no values")
            items[name] = array
    shape = tuple(a.size for a in items.values())
    count = math.prod(shape)
    if count > limits().sweep_max_sets:
        sizes = " x ".join(f"{size:,}" for size in shape)
        raise LimitError(f"grid: {sizes} = {count:,} parameter sets, more than Limits.sweep_max_sets = "
                         f"{limits().sweep_max_sets:,}; sweep the grid in parts (a slice of the first "
                         "parameter's values at a time)")
    mesh = np.meshgrid(*items.values(), indexing="ij") if items else []
    result = ParameterGrid({name: m.ravel() for name, m in zip(items, mesh)})
    result.shape = shape
    return result


@dataclass
class SweepResult:
    """What :func:`sweep` returns with ``return_error=True`` or ``quantities=``.

    Attributes
    ----------
    values : ndarray or None
        (P, n, T) values, one row per parameter set (the store given as ``out``, or None
        when only quantities were asked for).
    error : ndarray or None
        (P, n, T) bounds on the values' errors (absolute), as
        ``evaluate(return_error=True)`` gives (the store ``error_out``; None when not kept).
    set_error : ndarray
        (P,) each set's largest bound relative to max(‖x(t)‖∞, S₀).
    exact_sets : ndarray
        Indices of the sets some of whose times were computed by solving the set alone
        (``ls.solve(scene.subs(set))``): every set on the ``"alone"`` route, the sets and
        times a faster route could not bound within the target on the others.
    roots : ndarray
        (P, N) complex poles of each set on the route (NaN for sets solved alone).
    names : tuple of str
        The coordinates of the second axis.
    route : str
        ``"compiled"``, ``"batched"`` or ``"alone"`` (see :mod:`laplace_springs.sweeps.paths`).
    reason : str
        Why that route.
    quantities : dict
        Name -> (P, n) quantity per set (``quantities=``), and ``quantity_error`` the
        bounds on them.
    failures : dict
        Set index -> message, for sets that could not be evaluated (``on_error="nan"``:
        their values are NaN and their bounds infinite).
    """

    values: np.ndarray | None
    error: np.ndarray | None
    set_error: np.ndarray
    exact_sets: np.ndarray
    roots: np.ndarray
    names: tuple[str, ...]
    route: str = ""
    reason: str = ""
    quantities: dict[str, np.ndarray] = field(default_factory=dict)
    quantity_error: dict[str, np.ndarray] = field(default_factory=dict)
    failures: dict[int, str] = field(default_factory=dict)


def _outputs(scene: Scene, outputs: Any) -> list[int]:
    if outputs == "x" or outputs is None:
        return list(range(scene.n))
    items = [outputs] if isinstance(outputs, (str, int)) else list(outputs)
    chosen = []
    for item in items:
        if isinstance(item, (int, np.integer)) and not isinstance(item, bool) and 0 <= item < scene.n:
            chosen.append(int(item))
        elif isinstance(item, str) and item in (*scene.names, *scene.mass_names):
            chosen.append(coordinate_index(item, "sweep: outputs", names=scene.names,
                                           mass_names=scene.mass_names))  # a mass name first
        else:
            raise SceneError(f"sweep: outputs: {shown(item)} is not a coordinate; coordinates are "
                             f"{', '.join(scene.names)} (or indices 0..{scene.n - 1})")
    if not chosen:
        raise SceneError("sweep: outputs is empty")
    return chosen


def _chunk(chunk: Any) -> int | None:
    if chunk is None:
        return None
    if isinstance(chunk, bool) or not isinstance(chunk, (int, np.integer)) or chunk < 1:
        raise SceneError(f"sweep: chunk must be a positive integer, got {shown(chunk)}")
    return int(chunk)


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


def _check_memory(P: int, shape: tuple[int, int], keep: tuple[bool, bool]) -> None:
    """Refuse, before any work, values (and bounds) to be kept in memory beyond
    Limits.max_evaluation_values each: they stream to ``out=`` (``error_out=``) instead."""
    most, count = limits().max_evaluation_values, P * shape[0] * shape[1]
    for kept, store in zip(keep, ("out", "error_out")):
        if kept and count > most:
            raise LimitError(
                f"sweep: {P:,} sets x {shape[0]:,} outputs x {shape[1]:,} times = {count:,} values, "
                f"more than Limits.max_evaluation_values = {most:,} in memory; give {store}= (a .npy "
                "path or a numpy.memmap: each chunk is written there), ask for quantities=, or sweep "
                "fewer sets or times per call")


def plan_sweep(scene: Scene) -> SweepPlan:
    """The route :func:`sweep` takes for ``scene`` (made once per scene and kept with it).

    Examples
    --------
    >>> import laplace_springs as ls
    >>> chain = ls.Scene.from_components(
    ...     masses={f"m{i}": 1 for i in range(12)},
    ...     springs={"k0": ("wall", "m0", "k"), **{f"k{i}": (f"m{i-1}", f"m{i}", 1) for i in range(1, 12)}},
    ...     dashpots={"c": ("wall", "m0", "c")}, x0=[1] + [0] * 11, v0=[0] * 12,
    ...     parameters={"k": "positive", "c": "nonnegative"})
    >>> plan_sweep(chain).route
    'batched'
    """
    if not isinstance(scene, Scene):
        raise SceneError(f"sweep: expected a Scene, got {shown(scene)}")
    table = scene_cache(scene)
    if "sweep_plan" not in table:
        table["sweep_plan"] = sweep_plan(scene)
    plan: SweepPlan = table["sweep_plan"]
    return plan


class _Collector:
    """The sweep's results, filled chunk by chunk (in any order)."""

    def __init__(self, plan: SweepPlan, P: int, shape: tuple[int, int], stores: tuple[Any, Any],
                 keep: tuple[bool, bool], quantities: dict[str, Any] | None) -> None:
        n_out, T = shape
        self.stores = stores
        self.values = stores[0].array() if stores[0] is not None else (
            np.empty((P, n_out, T)) if keep[0] else None)
        self.error = stores[1].array() if stores[1] is not None else (
            np.empty((P, n_out, T)) if keep[1] else None)
        self.set_error = np.zeros(P)
        self.alone = np.zeros(P, dtype=bool)
        self.roots = np.full((P, plan.poles), np.nan + 0j)
        self.failures: dict[int, str] = {}
        self.quantities = {name: np.empty((P, n_out)) for name in (quantities or {})}
        self.quantity_error = {name: np.empty((P, n_out)) for name in (quantities or {})}

    def __call__(self, result: TaskResult) -> None:
        rows = slice(result.start, result.stop)
        for target, part, store in ((self.values, result.values, self.stores[0]),
                                    (self.error, result.error, self.stores[1])):
            if part is not None and target is not None and not writes_itself(store):
                target[rows] = part
        self.set_error[rows] = result.set_error
        self.alone[rows] = result.alone
        if result.roots.shape[1] == self.roots.shape[1]:
            self.roots[rows] = result.roots
        for index, message in result.failures:
            self.failures[result.start + index] = message
        for name, (value, bound) in result.quantities.items():
            self.quantities[name][rows] = value
            self.quantity_error[name][rows] = bound


def sweep(scene: Scene, values: Mapping[Any, Any], times: Any, *, outputs: Any = "x",
          derivative: int = 0, client: Any = None, chunk: int | None = None,
          return_error: bool = False, target: float | None = None, progress: Any = None,
          out: Any = None, error_out: Any = None, quantities: Any = None,
          on_error: str = "raise") -> Any:
    """Evaluate a scene's motion for many parameter sets, each as solving it alone would.

    Every set meets the contract of ``ls.solve(scene.subs(set)).evaluate(times)``: each
    value comes with a bound on its error (``return_error=True``), and a time whose bound
    misses the target relative to max(‖x(t)‖∞, S₀) is recomputed by solving the set
    alone. Every set is held to the checks of ``scene.subs`` first. The route depends on
    the scene (:func:`plan_sweep`, :mod:`laplace_springs.sweeps.paths`):

    * **compiled**: up to 8 coordinates with formula forcing (no delays or periods): the
      scene is solved once symbolically; each set's roots come from one batched
      companion-matrix eigenvalue call, polished by Newton's method, and isolated roots
      give residue terms, clusters (critical damping, resonance) divided differences.
    * **batched**: unforced scenes of any size with a diagonal M and a symmetric K
      (spring and dashpot networks): batched eigen-decompositions, one Newton step on
      every mode with residuals in double-double, and a rigorous bound from the energy
      of the error (:mod:`laplace_springs.sweeps.batched`).
    * **alone**: anything else the solver takes (periodic, sampled or delayed forces,
      forced scenes beyond 8 coordinates, massless nodes): ``ls.solve(scene.subs(set))``
      for each set.

    Parameters
    ----------
    scene : Scene
        A scene with declared parameters (``scene.parameters``).
    values : mapping
        Each parameter (name or Symbol) -> a number or a 1-D array (numbers, or text and
        exact rationals read by the package's parser; a float stands for its shortest
        decimal, as in ``Scene.subs``); arrays share one length P. :func:`grid` builds a
        Cartesian product, :func:`~laplace_springs.sweeps.uncertainty.sample_parameters`
        random samples.
    times : float or array_like
        Nonnegative evaluation times, read as float64 numbers: a number (one time) or a
        1-D array. An array of more axes is a SceneError naming its shape, not flattened:
        pass ``t.ravel()`` and reshape the result's last axis to ``t.shape``.
    outputs : "x", str, int or sequence, optional
        The coordinates to return (names or indices); ``"x"`` is all of them.
    derivative : {0, 1, 2}, optional
        Return x, x' or x''.
    client : dask.distributed.Client, optional
        Run the chunks on this cluster (needs ``pip install "laplace-springs[dask]"``);
        the result is identical to the local one, and survives a worker lost mid-run.
    chunk : int, optional
        Parameter sets per chunk (default: chunks of about
        :attr:`~laplace_springs.limits.Limits.sweep_chunk_seconds` of estimated work,
        within :attr:`~laplace_springs.limits.Limits.chunk_bytes` of memory).
    return_error : bool, optional
        Return a :class:`SweepResult` with the bounds.
    target : float, optional
        Relative accuracy (default :attr:`~laplace_springs.limits.Limits.target`).
    progress : bool or callable, optional
        ``True`` prints a line per chunk to stderr; a callable gets ``(done, total)``.
    out, error_out : str, path, numpy.memmap or array, optional
        Where the values (and the bounds) go, chunk by chunk, instead of memory: a ``.npy``
        path (created), a float64 ``numpy.memmap`` or an array of shape (P, n, T) with
        ``__setitem__`` (a Zarr array). With a client, the workers write files and shared
        stores themselves; nothing of that size reaches the client.
    quantities : sequence or mapping, optional
        Reduce each chunk to per-set quantities instead of keeping the motions:
        ``["peak", "rms", "final"]`` or ``{"settling_time": 0.05}``
        (:mod:`laplace_springs.sweeps.reduce`); the result is a :class:`SweepResult`
        with ``quantities`` and their bounds ``quantity_error``, each (P, n).
    on_error : {"raise", "nan"}, optional
        A set the solver refuses (a limit of the package) raises, naming the set; with
        ``"nan"`` it comes back as NaN values with infinite bounds, listed in
        ``SweepResult.failures``. A set ``Scene.subs`` refuses always raises.

    Returns
    -------
    ndarray or SweepResult
        Values of shape (P, len(outputs), len(times)) (the ``out`` store when given), or
        a :class:`SweepResult` with ``return_error`` or ``quantities``.

    Raises
    ------
    SceneError
        For a missing or unknown parameter, arrays of different lengths, a value that
        breaks the parameter's assumptions (a nonpositive stiffness) or that
        ``Scene.subs`` refuses (a negative mass), bad outputs or stores.

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
    >>> sweep(scene, {"k": [1, 4], "c": [0.5, 1]}, np.linspace(0, 20, 201),
    ...       quantities=["peak"]).quantities["peak"].round(6).tolist()
    [[1.0], [1.0]]
    """
    plan = plan_sweep(scene)
    if derivative not in (0, 1, 2) or isinstance(derivative, bool):
        raise SceneError(f"sweep: derivative must be 0, 1 or 2, got {shown(derivative)}")
    if not isinstance(return_error, bool):
        raise SceneError(f"sweep: return_error must be True or False, got {shown(return_error)}")
    if on_error not in ("raise", "nan"):
        raise SceneError(f"sweep: on_error must be 'raise' or 'nan', got {shown(on_error)}")
    goal = check_target(target)
    chosen = _outputs(scene, outputs)
    spec = quantity_spec(quantities) if quantities is not None else None
    sets = parameter_sets(plan.names, plan.symbols, values)
    validate_sets(scene, plan.entries, sets)
    check_flat(times, "sweep: times", "; pass t.ravel() and reshape the result's last axis to t.shape")
    grid_times = as_times(times).hi
    if spec is not None and "settling_time" in spec:
        check_increasing(grid_times, "sweep: settling_time")
    P, shape = len(sets), (len(chosen), grid_times.size)
    _check_memory(P, shape, keep=(spec is None and out is None, return_error and spec is None and error_out is None))
    stores = (None if out is None else open_store(out, (P, *shape), "out"),
              None if error_out is None else open_store(error_out, (P, *shape), "error_out"))
    keep = (spec is None, return_error and spec is None)
    costs = set_costs(plan, sets, grid_times)
    bounds = chunk_bounds(plan, costs, len(chosen), grid_times.size, chunk=_chunk(chunk))
    report = _progress(progress)
    collect = _Collector(plan, P, shape, stores, keep, spec)
    options: dict[str, Any] = {"times": grid_times, "outputs": chosen, "order": derivative,
                               "target": goal, "on_error": on_error, "stores": stores,
                               "quantities": spec, "keep": keep}
    if client is not None:
        run_on_client(client, plan, sets, bounds, options, collect, report)
    else:
        for start, stop in bounds:
            collect(run_chunk(plan, sets.subset(start, stop), start, **options))
            if report is not None:
                report(stop, P)
    if not (return_error or spec is not None):
        return collect.values
    names = tuple(scene.names[i] for i in chosen)
    return SweepResult(collect.values, collect.error, collect.set_error,
                       np.flatnonzero(collect.alone), collect.roots, names, plan.route, plan.reason,
                       collect.quantities, collect.quantity_error, collect.failures)
