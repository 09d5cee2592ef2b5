"""The result contract: what every evaluation promises, and the helpers that decide it.

Every solution, whatever engine evaluates it, returns from ``evaluate`` values whose error
at each time t satisfies

    error_i(t) = abs(x_i(t) − value_i) ≤ target · max(‖x(t)‖∞, S₀)   for every coordinate i,

with ``target`` = :attr:`~laplace_springs.limits.Limits.target` (1e-13) unless the caller
says otherwise and S₀ = ‖x0‖∞ + ‖v0‖∞/ρ, ρ the largest |pole| (the size of the initial
data in units of displacement). When no engine of the package can meet the target (a
target below float64's reach, a scene beyond every engine's limits), the error bound
returned with ``return_error=True`` says by how much a value may be wrong; that bound is
an upper bound for every entry and every time, never NaN, never inf. A value whose bound
exceeds max(target, :attr:`~laplace_springs.limits.Limits.refusal_bound`) of the scale is
never returned: the call raises a :class:`~laplace_springs.model.errors.LimitError` that
names the time, the bound and the way out.

**Escalation.** Which engine serves a request, and which engines recompute the times
whose bound misses the target, is decided by the planner
(:mod:`laplace_springs.planning`): the plan's chain is tried engine by engine, each with
the times still missing the target. The decision for a time looks at that time alone, so
a value does not depend on the other times of the call.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .limits import limits

__all__ = ["check_target", "reference_scale", "column_scales", "column_verdicts", "judge_columns",
           "Verdict", "escalate_columns"]


def check_target(target: float | None) -> float:
    """The target to use: :attr:`~laplace_springs.limits.Limits.target` for None, else a number in [1e-300, 1).

    >>> check_target(None), check_target(1e-10)
    (1e-13, 1e-10)
    """
    if target is None:
        return limits().target
    if isinstance(target, bool) or not isinstance(target, (int, float)) or not 1e-300 <= target < 1:
        raise ValueError(f"target must be a relative accuracy in [1e-300, 1), got {target!r}")
    return float(target)


def reference_scale(x0_norm: float, v0_norm: float, spectral_radius: float) -> float:
    """S₀ = ‖x0‖∞ + ‖v0‖∞/ρ of the contract (‖v0‖∞ when ρ = 0).

    >>> reference_scale(1.0, 4.0, 2.0)
    3.0
    """
    return float(x0_norm + (v0_norm / spectral_radius if spectral_radius > 0 else v0_norm))


def column_scales(values: np.ndarray, floor: float) -> np.ndarray:
    """max(‖x(t)‖∞, S₀) for each column (time) of ``values``."""
    if values.size == 0:
        return np.zeros(values.shape[1] if values.ndim == 2 else 0)
    return np.maximum(np.abs(values).max(axis=0), floor)


def column_verdicts(values: np.ndarray, bounds: np.ndarray, floor: float,
                    target: float) -> tuple[np.ndarray, np.ndarray]:
    """Per column (time): whether it escalates, and its largest bound over its scale.

    A column escalates when some bound exceeds ``target`` times its own scale
    max(‖x(t)‖∞, S₀), or when a value or bound is not finite (its relative bound is then
    inf). Only the column's own numbers are looked at.

    Examples
    --------
    >>> values = np.array([[1.0, 1.0, 0.0]])
    >>> bounds = np.array([[1e-16, 1e-12, np.inf]])
    >>> pending, relative = column_verdicts(values, bounds, 0.5, 1e-13)
    >>> pending.tolist(), relative.tolist()
    ([False, True, True], [1e-16, 1e-12, inf])
    """
    verdict = judge_columns(np.abs(values), bounds, floor, target)
    return verdict.pending, verdict.relative


@dataclass(frozen=True, eq=False)
class Verdict:
    """The verdicts of :func:`judge_columns`.

    Attributes
    ----------
    pending : numpy.ndarray
        Per column, whether it escalates (bool).
    relative : numpy.ndarray
        Per column, its largest bound over its scale (inf where a value or bound is not
        finite).
    largest : float
        max |value| over every entry (NaN or inf when one is not finite; 0 for none).
    worst : float
        An upper bound of ``relative.max()`` (the largest bound over S₀ where every
        number is finite, else ``relative.max()``; 0 for no columns).
    """

    pending: np.ndarray
    relative: np.ndarray
    largest: float
    worst: float


def judge_columns(sizes: np.ndarray, bounds: np.ndarray, floor: float, target: float) -> Verdict:
    """:func:`column_verdicts` from ``sizes`` = |values|, with the largest value and an upper
    bound of the worst relative bound (a caller's range checks need nothing more).

    Examples
    --------
    >>> verdict = judge_columns(np.array([[2.0, 1.0]]), np.array([[1e-16, 1e-17]]), 1.0, 1e-13)
    >>> verdict.pending.tolist(), verdict.largest, verdict.worst
    ([False, False], 2.0, 1e-16)
    """
    count = sizes.shape[1]
    if count == 0:
        return Verdict(np.zeros(0, dtype=bool), np.zeros(0), 0.0, 0.0)
    largest = sizes.max(axis=0)   # NaN or inf where a value is not finite
    top = bounds.max(axis=0)
    biggest, highest = float(largest.max()), float(top.max())
    if floor > 0 and biggest < math.inf and highest < math.inf:  # NaN fails both
        scale = np.maximum(largest, floor)  # every number finite, every scale positive
        relative = top / scale
        worst = highest / floor   # ≥ every relative bound
        pending = np.zeros(count, dtype=bool) if worst <= target else top > target * scale
        return Verdict(pending, relative, biggest, worst)
    bad = ~(np.isfinite(largest) & np.isfinite(top))
    scale = np.maximum(largest, floor)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        relative = np.where(top == 0, 0.0, top / np.where(scale > 0, scale, np.inf))
        pending = bad | (top > target * scale)
    relative[bad | np.isnan(relative)] = np.inf
    return Verdict(pending, relative, biggest, float(relative.max()))


def escalate_columns(values: np.ndarray, bounds: np.ndarray, floor: float,
                     target: float) -> np.ndarray:
    """The columns (times) whose bound misses the contract: a boolean mask
    (:func:`column_verdicts`).

    Examples
    --------
    >>> values = np.array([[1.0, 1.0, 0.0]])
    >>> bounds = np.array([[1e-16, 1e-12, np.inf]])
    >>> escalate_columns(values, bounds, 0.5, 1e-13).tolist()
    [False, True, True]
    """
    return column_verdicts(values, bounds, floor, target)[0]
