"""Uncertain parameters: sampling them and summarising a sweep over the samples."""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp

from ..limits import limits
from ..model.errors import LimitError, SceneError
from ..model.numbers import shown

__all__ = ["DISTRIBUTIONS", "Summary", "sample_parameters", "summarize"]

#: Distribution name -> the meaning of its two numbers.
DISTRIBUTIONS = {
    "normal": "mean, standard deviation",
    "uniform": "low, high",
    "lognormal": "median, standard deviation of the logarithm",
}


def _real(value: Any, entry: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise SceneError(f"{entry} must be a real number, got {shown(value)}")
    number = float(value)
    if not np.isfinite(number):
        raise SceneError(f"{entry} must be finite, got {shown(value)}")
    return number


def sample_parameters(spec: Mapping[Any, Any], size: int, seed: Any = None) -> dict[str, np.ndarray]:
    """Random parameter sets for a Monte Carlo sweep.

    Parameters
    ----------
    spec : mapping
        Parameter (name or Symbol) -> a number (the same in every set) or
        ``(distribution, a, b)`` with distribution ``"normal"`` (mean, standard
        deviation), ``"uniform"`` (low, high) or ``"lognormal"`` (median, standard
        deviation of the logarithm).
    size : int
        Number of parameter sets.
    seed : int or numpy.random.Generator, optional
        For reproducible samples.

    Returns
    -------
    dict
        Name -> array of ``size`` values, ready for :func:`laplace_springs.sweeps.sweep`.

    Examples
    --------
    >>> sets = sample_parameters({"k": ("normal", 1, 0.05), "c": 0.1}, 4, seed=1)
    >>> sorted(sets), sets["k"].shape, sets["c"].tolist()
    (['c', 'k'], (4,), [0.1, 0.1, 0.1, 0.1])
    """
    if isinstance(size, bool) or not isinstance(size, (int, np.integer)) or size < 1:
        raise SceneError(f"sample_parameters: size must be a positive integer, got {shown(size)}")
    if size > limits().sweep_max_sets:
        raise LimitError(f"sample_parameters: {int(size):,} sets, more than Limits.sweep_max_sets = "
                         f"{limits().sweep_max_sets:,}; sample and sweep in parts")
    if not isinstance(spec, Mapping):
        raise SceneError(f"sample_parameters: expected a mapping parameter -> distribution, got {shown(spec)}")
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    out: dict[str, np.ndarray] = {}
    for key, value in spec.items():
        name = key.name if isinstance(key, sp.Symbol) else key
        if not isinstance(name, str):
            raise SceneError(f"sample_parameters: parameter names must be strings, got {shown(key)}")
        entry = f"sample_parameters: {name!r}"
        if not isinstance(value, Sequence) or isinstance(value, str):
            out[name] = np.full(int(size), _real(value, entry))
            continue
        if len(value) != 3 or value[0] not in DISTRIBUTIONS:
            known = "; ".join(f"{k} ({v})" for k, v in DISTRIBUTIONS.items())
            raise SceneError(f"{entry}: expected a number or (distribution, a, b) with a "
                             f"distribution among {known}; got {shown(value)}")
        kind = value[0]
        a, b = _real(value[1], f"{entry} {kind} first value"), _real(value[2], f"{entry} {kind} second value")
        if kind == "normal":
            if b < 0:
                raise SceneError(f"{entry}: the standard deviation must be nonnegative, got {b}")
            out[name] = rng.normal(a, b, int(size))
        elif kind == "uniform":
            if b < a:
                raise SceneError(f"{entry}: uniform needs low <= high, got {a} > {b}")
            out[name] = rng.uniform(a, b, int(size))
        else:
            if a <= 0 or b < 0:
                raise SceneError(f"{entry}: lognormal needs a positive median and a nonnegative "
                                 f"sigma, got {a}, {b}")
            out[name] = a * np.exp(rng.normal(0.0, b, int(size)))
    return out


@dataclass
class Summary:
    """Statistics over the parameter sets of a sweep (axis 0), per remaining entry.

    Attributes
    ----------
    mean, std : ndarray
        Mean and standard deviation, e.g. (n, T) for a sweep's values or (n,) for a
        per-set quantity.
    levels : tuple of float
        The quantile levels.
    quantiles : ndarray
        (len(levels), ...) one array per level.
    count : int
        The sets summarised (sets with NaN values, failed with ``on_error="nan"``, are left
        out entry by entry).
    """

    mean: np.ndarray
    std: np.ndarray
    levels: tuple[float, ...]
    quantiles: np.ndarray
    count: int = 0

    def band(self, low: float, high: float) -> tuple[np.ndarray, np.ndarray]:
        """The quantiles at two of the levels, e.g. ``band(0.05, 0.95)``."""
        return self.quantile(low), self.quantile(high)

    def quantile(self, level: float) -> np.ndarray:
        """The quantile at one of the levels (0.5 is the median)."""
        try:
            return self.quantiles[self.levels.index(float(level))]
        except ValueError:
            raise SceneError(f"Summary: levels are {self.levels}, got {shown(level)}") from None

    def percentile(self, percent: float) -> np.ndarray:
        """The quantile at ``percent``/100 (``percentile(95)``), one of the levels."""
        return self.quantile(float(percent) / 100)


def summarize(values: Any, levels: Sequence[float] = (0.05, 0.5, 0.95)) -> Summary:
    """Mean, standard deviation and quantiles (percentiles) over the parameter sets.

    Parameters
    ----------
    values : ndarray or SweepResult
        A sweep's (P, n, T) values, or any per-set array (P, ...) such as a quantity
        ``result.quantities["peak"]`` (P, n) of a Monte Carlo sweep.
    levels : sequence of float
        Quantile levels in [0, 1] (``Summary.percentile(95)`` reads the 0.95 level).

    Returns
    -------
    Summary

    Examples
    --------
    >>> s = summarize(np.arange(5.0).reshape(5, 1, 1))
    >>> float(s.mean[0, 0]), s.band(0.05, 0.95)[1][0, 0].item(), s.percentile(50).item()
    (2.0, 3.8, 2.0)
    """
    source = getattr(values, "values", values)
    if source is None:
        raise SceneError("summarize: this sweep kept no values (it reduced them to quantities); "
                         "summarize one of them, e.g. summarize(result.quantities['peak'])")
    array = np.asarray(source, dtype=float)
    if array.ndim < 1 or array.shape[0] == 0:
        raise SceneError(f"summarize: expected values with parameter sets on axis 0, got shape {array.shape}")
    try:
        chosen = tuple(float(level) for level in levels)
    except (TypeError, ValueError):
        raise SceneError(f"summarize: quantile levels must be numbers in [0, 1], got {shown(levels)}") from None
    if not chosen or not all(0 <= level <= 1 for level in chosen):
        raise SceneError(f"summarize: quantile levels must lie in [0, 1], got {shown(levels)}")
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # an entry NaN in every set stays NaN
        return Summary(np.nanmean(array, axis=0), np.nanstd(array, axis=0), chosen,
                       np.nanquantile(array, chosen, axis=0),
                       int(np.sum(np.all(np.isfinite(array.reshape(array.shape[0], -1)), axis=1))))
