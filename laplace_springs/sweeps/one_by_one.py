"""Parameter sets solved alone: ``ls.solve(scene.subs(set)).evaluate(times)``.

The fallback of every sweep path: scenes no batched path takes (periodic, sampled or
delayed forcing, forced scenes beyond the symbolic limit, massless nodes, non-symmetric
K), sets a batched path cannot bound within the target, and times whose bound misses it.
Each set meets the contract of solving it alone because it is solved alone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.errors import SceneError
from ..model.scene import Scene
from ..solving import solve
from .parameters import ParameterSets
from .validate import exact_check

__all__ = ["Alone", "solve_alone", "reference_floor"]


@dataclass
class Alone:
    """One set solved alone: values and bounds (n, T) of all coordinates, the contract's
    floor S₀·ρ^order, the poles, the engine, and the error message if it failed."""

    values: np.ndarray
    bounds: np.ndarray
    floor: float
    poles: np.ndarray
    method: str
    failure: str | None = None


def reference_floor(scene: Scene, poles: np.ndarray, order: int) -> float:
    """S₀·ρ^order with S₀ = ‖x0‖∞ + ‖v0‖∞/ρ, ρ the largest |pole| (as ``Solution`` does)."""
    finite = poles[np.isfinite(poles)] if poles.size else poles
    rho = float(np.max(np.abs(finite), initial=0.0))
    x0 = max((abs(float(v)) for v in scene.x0), default=0.0)
    v0 = max((abs(float(v)) for v in scene.v0), default=0.0)
    base = x0 + (v0 / rho if rho > 0 else v0)
    return base * rho**order


def solve_alone(scene: Scene, sets: ParameterSets, b: int, times: np.ndarray, order: int,
                target: float, *, raise_errors: bool = True) -> Alone:
    """Set ``b`` solved alone at float ``times``.

    A set ``Scene.subs`` refuses raises its SceneError (naming the set); a set the solver
    cannot evaluate within its limits raises that error naming the set, or, with
    ``raise_errors=False``, comes back as NaN values with infinite bounds and the message.

    Examples
    --------
    >>> from laplace_springs.sweeps.parameters import parameter_sets
    >>> scene = Scene.from_matrices(M=[[1]], C=[["c"]], K=[[1]], x0=[1], v0=[0], parameters=["c"])
    >>> sets = parameter_sets(("c",), scene.parameters, {"c": [2.0]})
    >>> alone = solve_alone(scene, sets, 0, np.array([1.0]), 0, 1e-13)
    >>> round(float(alone.values[0, 0]), 12), alone.failure is None   # (1 + t) e^{-t}
    (0.735758882343, True)
    """
    numeric = exact_check(scene, sets, b)
    try:
        solution = solve(numeric, target=target)
        values, bounds = solution.evaluate(times, return_error=True, derivative=order, target=target)
        poles = np.asarray(solution.poles, dtype=complex).ravel()
    except (SceneError, ValueError, OverflowError, ArithmeticError) as error:
        message = f"sweep: set {b} ({sets.describe(b)}): {error}"
        if raise_errors:
            raise type(error)(message) from None
        nan = np.full((scene.n, times.size), np.nan)
        return Alone(nan, np.full_like(nan, np.inf), np.nan, np.zeros(0, complex), "", message)
    values = np.asarray(values, dtype=float)
    bounds = np.asarray(bounds, dtype=float)
    return Alone(values, bounds, reference_floor(numeric, poles, order), poles, solution.method)
