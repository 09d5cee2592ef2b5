"""The unit of work of a sweep: one chunk of parameter sets, on the plan's route (run
locally or on a Dask worker).

Every route ends the same way: a time whose bound misses the target relative to
max(‖x(t)‖∞, S₀), or a set the route cannot take, is recomputed by solving that set alone
(:mod:`~laplace_springs.sweeps.one_by_one`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..policy import check_target
from .batched import evaluate_batch
from .compile import CompiledScene
from .kernels import UNIT, UNIT_EXTENDED, evaluate_block
from .one_by_one import solve_alone
from .parameters import ParameterSets, parameter_sets
from .paths import SweepPlan

__all__ = ["ChunkResult", "evaluate_chunk", "evaluate_rows"]


@dataclass
class ChunkResult:
    """Values of one chunk of P sets.

    Attributes
    ----------
    values, error : numpy.ndarray
        (P, outputs, T).
    set_error : numpy.ndarray
        (P,) each set's largest bound relative to max(‖x(t)‖∞, S₀).
    alone : numpy.ndarray
        (P,) bool: some time of the set was computed by solving it alone.
    roots : numpy.ndarray
        (P, N) complex poles of the route (NaN for sets solved alone).
    failures : list of (int, str)
        Sets that could not be evaluated (with ``on_error="nan"``): index in the chunk
        and the message.
    """

    values: np.ndarray
    error: np.ndarray
    set_error: np.ndarray
    alone: np.ndarray
    roots: np.ndarray
    failures: list[tuple[int, str]] = field(default_factory=list)


def _relative(values: np.ndarray, error: np.ndarray, floor: np.ndarray) -> np.ndarray:
    """(P, T) largest bound over the coordinates / max(‖x(t)‖∞, floor)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.maximum(np.max(np.abs(values), axis=1), floor[:, None])
        relative = np.max(error, axis=1) / np.where(scale > 0, scale, 1.0)
    return np.where(np.isfinite(relative), relative, np.inf)


def _recompute(plan: SweepPlan, sets: ParameterSets, b: int, times: np.ndarray, columns: np.ndarray,
               outputs: list[int], order: int, target: float, raise_errors: bool,
               out: ChunkResult, floor: np.ndarray) -> None:
    """Set ``b`` solved alone at the times ``columns`` (in place)."""
    alone = solve_alone(plan.scene, sets, b, times[columns], order, target, raise_errors=raise_errors)
    out.values[b][:, columns] = alone.values[outputs]
    out.error[b][:, columns] = alone.bounds[outputs]
    out.alone[b] = True
    out.roots[b] = np.nan
    if alone.failure is not None:
        out.failures.append((b, alone.failure))
    elif np.isfinite(alone.floor):
        floor[b] = alone.floor if columns.size == times.size else max(floor[b], 0.0)


def evaluate_chunk(plan: SweepPlan, sets: ParameterSets, times: np.ndarray, *, outputs: list[int],
                   order: int = 0, target: float | None = None, on_error: str = "raise") -> ChunkResult:
    """Evaluate the sets of one chunk on the plan's route (see the module notes).

    Examples
    --------
    >>> import laplace_springs as ls
    >>> from laplace_springs.sweeps.paths import sweep_plan
    >>> scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[[1]], x0=[1], v0=[0],
    ...                                parameters=["c"])
    >>> plan = sweep_plan(scene)
    >>> sets = parameter_sets(plan.names, plan.symbols, {"c": [2.0, 0.5]})
    >>> result = evaluate_chunk(plan, sets, np.array([1.0]), outputs=[0])
    >>> plan.route, round(float(result.values[0, 0, 0]), 12), bool(result.set_error.max() < 1e-13)
    ('compiled', 0.735758882343, True)
    """
    goal = check_target(target)
    raise_errors = on_error == "raise"
    if plan.route == "compiled":
        assert plan.compiled is not None
        values, error, bad, roots, floor = _compiled_block(plan.compiled, sets.rows, times, order, goal)
        values, error = values[:, outputs], error[:, outputs]
    elif plan.route == "batched":
        assert plan.batched is not None
        block = evaluate_batch(plan.batched, sets.parts(), times, outputs=outputs, order=order,
                               target=goal)
        values, error, roots, floor = block.values, block.bounds, block.poles, block.floor
        bad = ~block.served
    else:
        P = len(sets)
        values = np.zeros((P, len(outputs), times.size))
        error = np.full_like(values, np.inf)
        roots = np.full((P, 0), np.nan + 0j)
        floor = np.zeros(P)
        bad = np.ones(P, dtype=bool)
    out = ChunkResult(values, error, np.zeros(len(sets)), np.zeros(len(sets), dtype=bool),
                      roots.astype(complex))
    relative = _relative(values, error, floor)
    missed = ~(relative <= goal)
    for b in np.flatnonzero(bad | np.any(missed, axis=1)).tolist():
        columns = np.arange(times.size) if bad[b] else np.flatnonzero(missed[b])
        _recompute(plan, sets, b, times, columns, outputs, order, goal, raise_errors, out, floor)
    out.set_error = np.max(_relative(out.values, out.error, floor), axis=1, initial=0.0)
    return out


# ----------------------------------------------------------------------------- compiled


def _compiled_block(compiled: CompiledScene, rows: np.ndarray, times: np.ndarray, order: int,
                    target: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The vectorised kernel on the compiled scene: values, errors (P, n, T), sets it
    refused, roots and each set's floor S₀·ρ^order.

    The coefficients' errors are their rounding (counted from their expressions) and the
    parameters' own: a float stands for its shortest decimal and an exact rational is
    rounded, each within u relative, which moves a coefficient of degree d by d·u of its
    absolute bound. A set whose cheap estimate misses ``target`` gets the refined one.
    """
    den, num, den_abs, num_abs = compiled.coefficients(rows)
    den_counts, num_counts = compiled.rounding_counts()
    den_degrees, num_degrees = compiled.parameter_degrees()
    wide = compiled.coefficients_extended(rows)
    unit = UNIT if wide is None else UNIT_EXTENDED
    rounding = ((unit * den_counts + 1.01 * UNIT * den_degrees) * den_abs,
                (unit * num_counts + 1.01 * UNIT * num_degrees) * num_abs)
    block = evaluate_block(den, num, den_abs, num_abs, times, order, coefficient_error=rounding,
                           extended=wide)
    x0, v0 = compiled.initial_size(rows)
    finite = np.where(np.isfinite(block.roots), block.roots, 0)
    rho = np.max(np.abs(finite), axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        floor = x0 + np.where(rho > 0, v0 / rho, v0)
        floor = floor * rho**order
    values, error = block.values, block.error
    with np.errstate(invalid="ignore"):  # forced from rest (S₀ = 0): the motion's own size
        overall = np.max(np.abs(values), axis=(1, 2), initial=0.0)
    floor = np.where(floor > 0, floor, np.where(np.isfinite(overall), overall, 0.0))
    relative = _relative(values, error, floor)
    again = np.flatnonzero(~block.suspect & ~np.all(relative <= target, axis=1))
    if again.size:  # the tighter estimate (∂x/∂r_j summed before its modulus) for these sets
        second = evaluate_block(den[again], num[again], den_abs[again], num_abs[again], times,
                                order, coefficient_error=(rounding[0][again], rounding[1][again]),
                                refine=True,
                                extended=None if wide is None else (wide[0][again], wide[1][again]))
        values[again], error[again] = second.values, second.error
    return values, error, block.suspect, block.roots, floor


def evaluate_rows(compiled: CompiledScene, rows: np.ndarray, times: np.ndarray, *,
                  derivative: int = 0, target: float | None = None, exact: bool = True
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Values, error estimates, the mask of sets solved alone, roots and each set's
    relative error for the float parameter sets ``rows`` of a compiled scene (all
    coordinates).

    The vectorised kernel first; a set whose estimate misses ``target`` gets the
    kernel's refined estimate; a time that still misses it (or a set the kernel refused)
    is recomputed by ``ls.solve(scene.subs(set))`` when ``exact`` is true.
    """
    goal = check_target(target)
    values, error, bad, roots, floor = _compiled_block(compiled, rows, times, derivative, goal)
    alone = np.zeros(len(rows), dtype=bool)
    if exact:
        sets = parameter_sets(compiled.names, compiled.symbols,
                              {name: rows[:, k] for k, name in enumerate(compiled.names)})
        missed = ~(_relative(values, error, floor) <= goal)
        for b in np.flatnonzero(bad | missed.any(axis=1)):
            columns = np.arange(times.size) if bad[b] else np.flatnonzero(missed[b])
            result = solve_alone(compiled.scene, sets, int(b), times[columns], derivative, goal)
            values[b][:, columns], error[b][:, columns] = result.values, result.bounds
            alone[b] = True
            if bad[b]:
                floor[b] = result.floor
    set_error = np.max(_relative(values, error, floor), axis=1, initial=0.0)
    return values, error, alone, roots, set_error
