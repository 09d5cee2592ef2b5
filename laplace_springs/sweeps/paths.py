"""How a sweep evaluates a scene (its route), what each set is expected to cost, and the
chunks that follow from the costs.

Routes, tried in this order:

``compiled``
    The scene is solved once symbolically and every set is a vectorised residue sum
    (:mod:`~laplace_springs.sweeps.compile`, :mod:`~laplace_springs.sweeps.kernels`): up
    to :attr:`~laplace_springs.limits.Limits.sweep_max_coordinates` coordinates, formula
    forcing without delays or periods.
``batched``
    Unforced scenes of any size with a diagonal M and a symmetric K: batched
    eigen-decompositions with refined modes and a rigorous bound per set
    (:mod:`~laplace_springs.sweeps.batched`).
``alone``
    Everything else the solver takes (periodic, sampled or delayed forcing, moving
    supports with delays, forced scenes beyond the symbolic limit, massless nodes):
    ``ls.solve(scene.subs(set))`` for each set (:mod:`~laplace_springs.sweeps.one_by_one`).

Sets and times a route cannot bound within the target are solved alone on every route.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..limits import limits
from ..model.scene import Scene
from ..solving import plan_for
from .batched import BatchedScene, batched_refusal, batched_scene
from .compile import CompiledScene, compiled_or_reason
from .entries import SceneEntries, scene_entries_of
from .parameters import ParameterSets
from .validate import exact_check

__all__ = ["ROUTES", "SweepPlan", "sweep_plan", "set_costs", "chunk_bounds"]

#: The routes, fastest first.
ROUTES = ("compiled", "batched", "alone")
#: Engines whose cost grows with the stiffness times the horizon (Taylor steps, Chebyshev degree).
_STEPPING = ("krylov", "chebyshev")


@dataclass(frozen=True, eq=False)
class SweepPlan:
    """The route of a sweep and what it needs.

    Attributes
    ----------
    scene : Scene
    route : str
        One of :data:`ROUTES`.
    reason : str
        Why this route (and why not the faster ones).
    entries : SceneEntries
    compiled : CompiledScene or None
    batched : BatchedScene or None
    """

    scene: Scene
    route: str
    reason: str
    entries: SceneEntries
    compiled: CompiledScene | None = None
    batched: BatchedScene | None = None

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(s.name for s in self.scene.parameters)

    @property
    def symbols(self) -> tuple[sp.Symbol, ...]:
        return tuple(self.scene.parameters)

    @property
    def poles(self) -> int:
        """Number of poles the route reports per set."""
        if self.compiled is not None:
            return self.compiled.degree
        return 2 * self.scene.n if self.batched is not None else 0


def sweep_plan(scene: Scene) -> SweepPlan:
    """The route for sweeping ``scene`` (see the module notes).

    Examples
    --------
    >>> import laplace_springs as ls
    >>> one = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[[1]], x0=[1], v0=[0], parameters=["c"])
    >>> sweep_plan(one).route
    'compiled'
    >>> square = one.with_forcing([ls.square_wave(1, 2)])
    >>> plan = sweep_plan(square)
    >>> plan.route, plan.reason
    ('alone', 'each set solved alone: not compiled (forcing[0] = ... is periodic); not batched (the scene is forced)')
    """
    entries = scene_entries_of(scene)
    compiled = compiled_or_reason(scene)
    if not isinstance(compiled, str):
        return SweepPlan(scene, "compiled", "one symbolic solve, vectorised residue sums", entries,
                         compiled=compiled)
    why = batched_refusal(scene, entries)
    if why is None:
        return SweepPlan(scene, "batched", f"batched eigen-decompositions (not compiled: {compiled})",
                         entries, batched=batched_scene(scene, entries))
    return SweepPlan(scene, "alone", f"each set solved alone: not compiled ({compiled}); "
                     f"not batched ({why})", entries)


def _stiffness(plan: SweepPlan, sets: ParameterSets) -> np.ndarray:
    """A rough size ν of each set's largest pole: √max(row |K| / m) + max(row |C| / m)."""
    entries, n = plan.entries, plan.scene.n
    mass = np.ones((len(sets), n))
    for k, (i, j) in enumerate(entries.pattern["M"]):
        if i == j:
            mass[:, i] = np.abs(entries.floats("M", sets.rows)[:, k])
    rows = {}
    for name in ("K", "C"):
        values = np.abs(entries.floats(name, sets.rows))
        total = np.zeros((len(sets), n))
        for k, (i, _) in enumerate(entries.pattern[name]):
            total[:, i] += values[:, k]
        with np.errstate(divide="ignore", invalid="ignore"):
            rows[name] = np.max(np.where(mass > 0, total / mass, 0.0), axis=1, initial=0.0)
    nu = np.sqrt(rows["K"]) + rows["C"]
    return np.where(np.isfinite(nu), nu, 0.0)


def set_costs(plan: SweepPlan, sets: ParameterSets, times: np.ndarray) -> np.ndarray:
    """Estimated seconds per set (P,) on the plan's route (one core).

    compiled: 5 µs + 25 ns per degree, coordinate and time (measured: 10⁵ two-mass sets at
    100 times in 2.5 s); batched: 0.2 ms + 3·10⁻⁸·(2n)³ s (a 50-mass chain: 31 ms per set,
    of which 16 ms the eigen-decomposition); alone: the planner's estimate for the first
    set, scaled by each set's stiffness for engines that step through time.
    """
    P, n, T = len(sets), plan.scene.n, max(times.size, 1)
    if plan.route == "compiled":
        assert plan.compiled is not None
        per = 5e-6 + 2.5e-8 * plan.compiled.degree * n * T
        return np.full(P, per)
    if plan.route == "batched":
        return np.full(P, 2e-4 + 3e-8 * (2 * n) ** 3 + 2e-8 * n * n * T)
    first = exact_check(plan.scene, sets, 0)
    chosen = plan_for(first, times if times.size else None)
    base = max(chosen.seconds, 2e-3) + 2e-3
    if chosen.primary not in _STEPPING or not times.size:
        return np.full(P, base)
    nu = _stiffness(plan, sets)
    horizon = float(np.max(times))
    ratio = (1 + nu * horizon) / (1 + nu[0] * horizon)
    return base * np.where(np.isfinite(ratio), ratio, 1.0)


def _set_memory(plan: SweepPlan, outputs: int, T: int) -> float:
    """Bytes one set takes in a chunk's largest array (Limits.chunk_bytes bounds that)."""
    n = plan.scene.n
    if plan.route == "compiled":
        assert plan.compiled is not None
        return 16.0 * max(plan.compiled.degree, 1) * max(T, 1) * max(n, 1)
    if plan.route == "batched":
        assert plan.batched is not None
        width = plan.batched.width
        return 16.0 * max(n * (width + 1) * 2 * n, 4 * (2 * n) ** 2, 4 * outputs * T)
    return 8.0 * (4 * n * T) + 1e6


def chunk_bounds(plan: SweepPlan, costs: np.ndarray, outputs: int, T: int, *,
                 chunk: int | None = None, seconds: float | None = None) -> list[tuple[int, int]]:
    """[start, stop) of consecutive chunks: ``chunk`` sets each if given, else as many sets
    as fit in ``seconds`` of estimated work (default
    :attr:`~laplace_springs.limits.Limits.sweep_chunk_seconds`) and in
    :attr:`~laplace_springs.limits.Limits.chunk_bytes` of memory.

    Examples
    --------
    >>> import laplace_springs as ls
    >>> plan = sweep_plan(ls.Scene.from_matrices(M=[[1]], K=[["k"]], x0=[1], v0=[0],
    ...                                          parameters=["k"]))
    >>> chunk_bounds(plan, np.array([0.4, 0.4, 0.4, 2.0, 0.1]), 1, 10, seconds=1.0)
    [(0, 2), (2, 3), (3, 4), (4, 5)]
    """
    P = costs.size
    if chunk is not None:
        return [(start, min(start + chunk, P)) for start in range(0, P, chunk)]
    budget = limits().sweep_chunk_seconds if seconds is None else seconds
    most = max(1, int(limits().chunk_bytes // max(_set_memory(plan, outputs, T), 1.0)))
    bounds = []
    start = 0
    total = np.concatenate([[0.0], np.cumsum(costs)])
    while start < P:
        stop = int(np.searchsorted(total, total[start] + budget, side="right")) - 1
        stop = min(max(stop, start + 1), start + most, P)
        bounds.append((start, stop))
        start = stop
    return bounds


def describe_cost(costs: np.ndarray) -> str:
    """"~12 s of work" for the estimated costs."""
    total = float(np.sum(costs))
    return f"~{total:.2g} s of work" if math.isfinite(total) else "unknown work"
