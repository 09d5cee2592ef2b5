"""The solution of a scene with sampled (measured) force histories.

x(t) = the solution of the scene without its sampled entries (any route: initial data and
formula forcing, exactly) + the response to the sampled forces from rest, exact for
their interpolants (:mod:`laplace_springs.numeric.sampled`).

``x`` has no closed form (a history of 10⁵ samples would be 10⁵ pieces): it raises a
SceneError; :meth:`~laplace_springs.solution.Solution.evaluate` gives values with bounds.
"""

from __future__ import annotations

from fractions import Fraction
from functools import cached_property
from typing import Any

import mpmath
import numpy as np
import sympy as sp

from ..exact.assembly import exact_motion
from ..kernels.precision import workdps
from ..limits import limits
from ..model.errors import SceneError
from ..model.sampled import formula_part
from ..model.scene import Scene
from ..model.symbols import TIME
from ..numeric.first_order import scene_arrays
from ..numeric.sampled import SampledInput, sampled_inputs
from ..numeric.times import Times
from ..planning.execute import Evaluator, execute
from ..planning.request import request_for
from ..solution import Solution, Verification
from .exact import ExactSolution

__all__ = ["SampledSolution", "solve_sampled"]


class SampledSolution(Solution):
    """Motion of a scene with sampled forces: ``base`` (the rest of the scene, any route)
    plus the responses to the sampled forces.

    ``method`` is the base route's name + ``"+sampled"``. ``x`` raises a SceneError (no
    closed form); ``evaluate`` adds the two parts and their bounds; times whose bound
    misses the target are recomputed in mpmath when the histories are short enough
    (:attr:`~laplace_springs.limits.Limits.mp_max_segments` segments).
    """

    _planned = False  # its own float64 pass (base + sampled responses) and mp escalation

    def __init__(self, scene: Scene, base: Solution, *, reason: str,
                 target: float | None = None) -> None:
        super().__init__(scene, reason=reason, target=target)
        self.base = base
        self.inputs: list[SampledInput] = sampled_inputs(scene)

    @property
    def method(self) -> str:  # type: ignore[override]
        return f"{self.base.method}+sampled"

    @property
    def x(self) -> sp.ImmutableMatrix:
        """No closed form: a SceneError (use :meth:`evaluate`)."""
        raise SceneError("a sampled force has no closed form (each sample would be a piece); "
                         "use evaluate(), or .base.x for the part without the sampled forces")

    @property
    def poles(self) -> np.ndarray:
        return self.base.poles

    @property
    def _spectral_radius(self) -> float:
        return max([self.base._spectral_radius, *(r.rho for r in self.inputs)])

    @cached_property
    def _base_floor(self) -> float:
        """S₀ plus the static displacement of the largest sampled force, |f|·max|M⁻¹|/ρ²."""
        M = scene_arrays(self.scene)[0]
        rho = self._spectral_radius
        data = [s for s in self.scene.sampled or () if s is not None]
        force = max(float(np.max(np.abs(s.values))) for s in data) * float(np.max(np.abs(np.linalg.inv(M))))
        span = max(s.end for s in data)
        return super()._base_floor + (force / rho**2 if rho > 1e-150 else force * span**2)

    @property
    def _mp_ok(self) -> bool:
        return all(r.data.times.size - 1 <= limits().mp_max_segments
                   and np.unique(np.diff(r.data.times)).size <= limits().mp_max_steps for r in self.inputs)

    @property
    def escalation(self) -> str | None:
        return "mp" if self._mp_ok else None

    @property
    def _escalation_engine(self) -> str | None:  # type: ignore[override]
        return self.escalation

    def _sampled_float(self, times: Times, order: int) -> tuple[np.ndarray, np.ndarray]:
        values = np.zeros((self.scene.n, len(times)))
        bounds = np.zeros_like(values)
        for response in self.inputs:
            v, b = response.values(times.hi, times.lo, order)
            values += v.T
            bounds += b.T
        return values, bounds

    def _own_engines(self) -> dict[str, Evaluator]:
        own: dict[str, Evaluator] = {self.method: self._combined}
        if self.escalation is not None:
            own[self.escalation] = self._escalate
        return own

    def _combined(self, times: Times, order: int, target: float) -> tuple[np.ndarray, np.ndarray]:
        """The base through its own plan (its escalations included) plus the sampled
        responses in float64 (double-double states)."""
        values, bounds = self._base_values(times, order, target)
        more, more_bounds = self._sampled_float(times, order)
        total = values + more
        return total, bounds + more_bounds + np.finfo(float).eps * np.abs(total)

    def _base_values(self, times: Times, order: int, target: float) -> tuple[np.ndarray, np.ndarray]:
        if not self.base._planned:
            return self.base._float(times, order)
        plan = self.base._plan(request_for(times, target=target, dps=None, order=order))
        values, bounds, _ = execute(plan, self.base._evaluator, times, self.scene.n, order, target,
                                    self.base._floor(order), progress=False)
        return values, bounds

    def _float(self, times: Times, order: int) -> tuple[np.ndarray, np.ndarray]:
        return self._combined(times, order, self.target)

    def _escalate(self, times: Times, order: int, target: float) -> tuple[np.ndarray, np.ndarray]:
        if not self._mp_ok:
            return self._float(times, order)
        values, bounds = self._digits(times, order, limits().escalation_digits)
        as_float = np.vectorize(float, otypes=[float])
        rounded = as_float(values)
        return rounded, as_float(bounds) + np.finfo(float).eps * np.abs(rounded)

    def _digits(self, times: Times, order: int, dps: int) -> tuple[np.ndarray, np.ndarray]:
        if not self._mp_ok:
            raise ValueError(f"evaluate(..., dps=) runs a sampled history in mpmath, which takes at "
                             f"most {limits().mp_max_segments} segments with {limits().mp_max_steps} distinct steps")
        values, bounds = self.base._digits(times, order, dps)
        exact = [Fraction(times.exact(i)) for i in range(len(times))]
        with workdps(dps + 5):
            for response in self.inputs:
                rows = response.digits(exact, order, dps)
                for col, row in enumerate(rows):
                    for i, value in enumerate(row):
                        values[i, col] = values[i, col] + value
            scale = max(self._floor(order), 1e-300)
            for col in range(len(times)):
                size = max([abs(values[i, col]) for i in range(self.scene.n)] + [mpmath.mpf(scale)])
                for i in range(self.scene.n):
                    bounds[i, col] = bounds[i, col] + size * mpmath.mpf(10) ** (-dps)
        return values, bounds

    def verify(self, *, samples: Any = ("0.37", "1.3", "4.1"),
               tolerance: float | None = None) -> Verification:
        """Residual of M x'' + C x' + K x = f(t) (formula and sampled forces) at t = 0 and
        the sample times, relative to the terms' size, and of the initial data."""
        tolerance = 1e-9 if tolerance is None else float(tolerance)
        M, C, K, x0, v0 = scene_arrays(self.scene)
        times = np.array([0.0, *(float(sp.Rational(str(s))) for s in samples)])
        x, v, a = (self.evaluate(times, derivative=order) for order in range(3))
        force = np.zeros_like(x)
        if self.scene.forcing is not None:
            for i, f in enumerate(self.scene.forcing):
                force[i] = [float(f.subs(TIME, sp.Rational(str(t)))) for t in times] if f != 0 else 0.0
        for i, data in enumerate(self.scene.sampled or ()):
            if data is not None:
                force[i] += data(times)
        residual = np.max(np.abs(M @ a + C @ v + K @ x - force))
        size = np.max(np.abs(M) @ np.abs(a) + np.abs(C) @ np.abs(v) + np.abs(K) @ np.abs(x)
                      + np.abs(force))
        start = np.max(np.abs(np.concatenate([x[:, 0] - x0, v[:, 0] - v0])))
        data_size = np.max(np.abs(np.concatenate([x0, v0])))
        return Verification(float(residual / size) if size else float(residual),
                            float(start / data_size) if data_size else float(start), tolerance)


def solve_sampled(scene: Scene, target: float | None = None, *, base: Solution | None = None,
                  reason: str = "") -> SampledSolution:
    """Solve a scene with sampled forces: ``base`` solves the rest (by default the exact
    route on the scene without its sampled entries), the sampled responses are added.

    Examples
    --------
    A unit force held for one second on x'' + 4x = f, from rest (zoh):
    x = (1 − cos 2t)/4 while it acts.

    >>> from laplace_springs.model.sampled import sampled
    >>> scene = Scene.from_matrices(M=[[1]], K=[[4]], x0=[0], v0=[0],
    ...                             forcing=[sampled([0, 1], [1, 1], kind="zoh")])
    >>> sol = solve_sampled(scene)
    >>> sol.method, round(float(sol.evaluate(0.5)[0, 0]), 13), round(float(1 - np.cos(1.0)) / 4, 13)
    ('exact+sampled', 0.114924423533, 0.114924423533)
    """
    if scene.sampled is None:
        raise SceneError("solve_sampled: the scene has no sampled forcing entries")
    if base is None:
        base = ExactSolution(exact_motion(formula_part(scene)),
                             reason="the scene without its sampled forces, exactly", target=target)
    why = reason or f"sampled forces: {base.method} route for the rest, exact per-segment response"
    return SampledSolution(scene, base, reason=why, target=target)
