"""Quantities of each set computed chunk by chunk, so a sweep of 10⁶ sets never holds all
the motions: ``sweep(..., quantities=["peak", "rms"])``.

Each quantity comes with a bound on its error that follows from the bounds of the values
it is computed from:

``peak``
    max over the times of |x_i(t)|; error ≤ max_t bound_i(t) (a maximum moves by at most
    the largest change of its arguments).
``rms``
    √(mean over the times of x_i(t)²); error ≤ √(mean of bound_i(t)²) (Minkowski).
``final``
    x_i at the last time; error ≤ its bound.
``settling_time``
    the last time at which |x_i| exceeds a tolerance (0 if never, inf if still at the last
    time); the error bound is the spread between the last times at which |x_i| is surely
    and possibly above it (0 when the bounds decide every time).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from ..model.errors import SceneError
from ..model.numbers import shown

__all__ = ["check_increasing", "QUANTITIES", "quantity_spec", "reduce_chunk"]

Reducer = Callable[[np.ndarray, np.ndarray, np.ndarray, Any], tuple[np.ndarray, np.ndarray]]


def _peak(values: np.ndarray, error: np.ndarray, times: np.ndarray, _: Any) -> tuple[np.ndarray, np.ndarray]:
    return np.max(np.abs(values), axis=-1), np.max(error, axis=-1) * (1 + 2**-52)


def _rms(values: np.ndarray, error: np.ndarray, times: np.ndarray, _: Any) -> tuple[np.ndarray, np.ndarray]:
    T = values.shape[-1]
    value = np.sqrt(np.mean(values**2, axis=-1))
    rounding = (T + 4) * 2.0**-53 * value
    return value, np.sqrt(np.mean(error**2, axis=-1)) * (1 + 1e-12) + rounding


def _final(values: np.ndarray, error: np.ndarray, times: np.ndarray, _: Any) -> tuple[np.ndarray, np.ndarray]:
    return values[..., -1].copy(), error[..., -1].copy()


def _last_above(mask: np.ndarray, times: np.ndarray) -> np.ndarray:
    T = times.size
    last = T - 1 - np.argmax(mask[..., ::-1], axis=-1)
    out = np.where(mask.any(axis=-1), times[last], 0.0)
    return np.where(mask[..., -1], np.inf, out)


def _settling(values: np.ndarray, error: np.ndarray, times: np.ndarray,
              tolerance: Any) -> tuple[np.ndarray, np.ndarray]:
    size = np.abs(values)
    value = _last_above(size > tolerance, times)
    surely = _last_above(size - error > tolerance, times)
    possibly = _last_above(size + error > tolerance, times)
    with np.errstate(invalid="ignore"):
        spread = np.where(possibly == surely, 0.0, possibly - surely)
    return value, spread


#: Quantity name -> (reducer, whether it takes an option).
QUANTITIES: dict[str, tuple[Reducer, bool]] = {
    "peak": (_peak, False),
    "rms": (_rms, False),
    "final": (_final, False),
    "settling_time": (_settling, True),
}


def check_increasing(times: np.ndarray, what: str) -> None:
    """Refuse times that do not increase (the settling time reads them in order), naming
    the first that does not.

    >>> check_increasing(np.array([0.0, 2.0, 1.0]), "settling_time")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: settling_time: times must increase, but times[2] = 1.0 follows times[1] = 2.0
    """
    if (steps := np.flatnonzero(~(np.diff(times) > 0))).size:  # a NaN time fails too
        i = int(steps[0]) + 1
        raise SceneError(f"{what}: times must increase, but times[{i}] = {float(times[i])!r} "
                         f"follows times[{i - 1}] = {float(times[i - 1])!r}")


def quantity_spec(quantities: Any) -> dict[str, Any]:
    """Check ``quantities``: names, or a mapping name -> option (the tolerance of
    ``settling_time``).

    Examples
    --------
    >>> quantity_spec(["peak", "rms"])
    {'peak': None, 'rms': None}
    >>> quantity_spec({"settling_time": 0.05})
    {'settling_time': 0.05}
    """
    if isinstance(quantities, str):
        quantities = [quantities]
    items = dict(quantities) if isinstance(quantities, Mapping) else dict.fromkeys(quantities)
    for name, option in items.items():
        if name not in QUANTITIES:
            raise SceneError(f"sweep: unknown quantity {shown(name)}; known: {', '.join(QUANTITIES)}")
        takes = QUANTITIES[name][1]
        if takes and not (isinstance(option, (int, float)) and not isinstance(option, bool)
                          and np.isfinite(option) and option >= 0):
            raise SceneError(f"sweep: quantity {name!r} needs a nonnegative tolerance, "
                             f"e.g. {{'{name}': 0.05}}; got {shown(option)}")
        if not takes and option is not None:
            raise SceneError(f"sweep: quantity {name!r} takes no option, got {shown(option)}")
    if not items:
        raise SceneError("sweep: quantities is empty")
    return items


def reduce_chunk(spec: Mapping[str, Any], values: np.ndarray, error: np.ndarray,
                 times: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """name -> (quantity, bound), each (sets, outputs), for one chunk's values and bounds.

    Examples
    --------
    >>> v = np.array([[[0.5, -2.0, 1.0]]])
    >>> out = reduce_chunk({"peak": None}, v, np.full_like(v, 1e-15), np.arange(3.0))
    >>> out["peak"][0].tolist(), bool(out["peak"][1][0, 0] >= 1e-15)
    ([[2.0]], True)
    """
    if values.shape[-1] == 0:
        raise SceneError("sweep: quantities need at least one time")
    return {name: QUANTITIES[name][0](values, error, times, option) for name, option in spec.items()}
