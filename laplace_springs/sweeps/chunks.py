"""The unit of work of a sweep: one chunk of parameter sets (run locally or on a worker)."""

from __future__ import annotations

import numpy as np

from ..policy import check_target
from ..solving import solve
from .compile import CompiledScene
from .kernels import UNIT, UNIT_EXTENDED, evaluate_block

__all__ = ["evaluate_rows"]


def _exact_set(compiled: CompiledScene, row: np.ndarray, times: np.ndarray, derivative: int,
               target: float) -> tuple[np.ndarray, np.ndarray]:
    """One set by the exact solver: ls.solve(scene.subs(...)).evaluate(...)."""
    values = {name: float(value) for name, value in zip(compiled.names, row)}
    solution = solve(compiled.scene.subs(values))
    result = solution.evaluate(times, return_error=True, derivative=derivative, target=target)
    return np.asarray(result[0], dtype=float), np.asarray(result[1], dtype=float)


def evaluate_rows(compiled: CompiledScene, rows: np.ndarray, times: np.ndarray, *,
                  derivative: int = 0, target: float | None = None, exact: bool = True
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Values, error estimates, exact-set mask, roots and each set's relative error
    estimate for the parameter sets ``rows``.

    The vectorised kernel first; a set whose estimate misses ``target`` relative to
    max(‖x(t)‖∞, S₀) gets the kernel's refined estimate; if that misses too (or the
    kernel refused the set's data) the set is recomputed one by one by
    ``ls.solve(scene.subs(...))`` when ``exact`` is true.
    """
    goal = check_target(target)
    den, num, den_abs, num_abs = compiled.coefficients(rows)
    den_counts, num_counts = compiled.rounding_counts()
    wide = compiled.coefficients_extended(rows)
    unit = UNIT if wide is None else UNIT_EXTENDED
    rounding = (unit * den_counts * den_abs, unit * num_counts * num_abs)
    block = evaluate_block(den, num, den_abs, num_abs, times, derivative, coefficient_error=rounding,
                           extended=wide)
    x0, v0 = compiled.initial_size(rows)
    finite = np.where(np.isfinite(block.roots), block.roots, 0)
    rho = np.max(np.abs(finite), axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        floor = x0 + np.where(rho > 0, v0 / rho, v0)
        if derivative:
            floor = floor * np.maximum(rho, 1e-300) ** derivative
    values, error = block.values, block.error
    with np.errstate(invalid="ignore"):
        size = np.max(np.abs(values), axis=1)  # (P, T)
        overall = np.max(size, axis=1) if size.size else np.zeros(len(rows))
        floor = np.where(floor > 0, floor, overall)  # forced from rest: the motion's size
        scale = np.maximum(size, floor[:, None])
        relative = np.max(error, axis=1) / np.where(scale > 0, scale, 1.0)
    bad = block.suspect | ~np.all(relative <= goal, axis=1) if relative.size else block.suspect
    again = np.flatnonzero(bad & ~block.suspect)
    if again.size:  # the tighter estimate (∂x/∂r_j summed before its modulus) for these sets
        second = evaluate_block(den[again], num[again], den_abs[again], num_abs[again], times,
                                derivative, coefficient_error=(rounding[0][again], rounding[1][again]),
                                refine=True,
                                extended=None if wide is None else (wide[0][again], wide[1][again]))
        values[again], error[again] = second.values, second.error
        size[again] = np.max(np.abs(second.values), axis=1)
        scale[again] = np.maximum(size[again], floor[again, None])
        with np.errstate(invalid="ignore"):
            relative[again] = np.max(second.error, axis=1) / np.where(scale[again] > 0, scale[again], 1.0)
        bad = block.suspect | ~np.all(relative <= goal, axis=1)
    exact_mask = np.zeros(len(rows), dtype=bool)
    if exact:
        for b in np.flatnonzero(bad):
            values[b], error[b] = _exact_set(compiled, rows[b], times, derivative, goal)
            exact_mask[b] = True
            size[b] = np.max(np.abs(values[b]), axis=0)
            scale[b] = np.maximum(size[b], floor[b])
            relative[b] = np.max(error[b], axis=0) / np.where(scale[b] > 0, scale[b], 1.0)
    set_error = np.max(relative, axis=1) if relative.size else np.zeros(len(rows))
    return values, error, exact_mask, block.roots, set_error
