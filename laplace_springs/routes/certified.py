"""The certified route: poles and residues certified in ball arithmetic from the exact
polynomials of the first-order system; float64 values from the stable pole-sum kernels,
escalated to ball evaluation at more bits where their bound misses the target.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
import sympy as sp

from ..model.scene import Scene
from ..numeric.certified import CertifiedPoles, certified_digits, certified_values, closed_form
from ..numeric.pole_sum import derivative_sum
from ..numeric.terms import NumericTerms, float_values
from ..numeric.times import Times
from ..solution import Solution
from .exact import ExactSolution, exact_solution_of

__all__ = ["CertifiedSolution"]


class CertifiedSolution(Solution):
    """Motion x(t) from certified poles and residues (ball arithmetic).

    Holds :class:`~laplace_springs.numeric.certified.CertifiedPoles`. Float64 values come
    from the stable pole-sum kernels; times whose bound misses the target are evaluated
    in ball arithmetic, whose radius certifies the bound.
    """

    method = "certified"
    _escalation_engine = "ball"

    def __init__(self, scene: Scene, poles: CertifiedPoles, *, reason: str | None,
                 target: float | None = None) -> None:
        super().__init__(scene, reason=reason, target=target)
        self.certified = poles

    @cached_property
    def poles(self) -> np.ndarray:
        nodes = self._fast(0).poles.nodes
        return np.array([complex(z) for z in nodes], dtype=complex)

    @property
    def _spectral_radius(self) -> float:
        return self.certified.spectral_radius()

    @cached_property
    def _exact_form(self) -> ExactSolution | None:
        return exact_solution_of(self.scene, method=self.method, target=self.target)

    @cached_property
    def x(self) -> sp.ImmutableMatrix:
        """x(t): the exact closed form up to Limits.exact_form_max_coordinates coordinates (built on
        first use), else real terms with Float coefficients from the certified poles."""
        exact = self._exact_form
        return exact.x if exact is not None else sp.ImmutableMatrix(closed_form(self.certified))

    def _fast(self, order: int) -> NumericTerms:
        cache = self.__dict__.setdefault("_fast_cache", {})
        if order not in cache:
            form = self.certified.pole_sum(40)
            cache[order] = NumericTerms((), derivative_sum(form, order) if order else form, 40)
        return cache[order]

    def _float(self, times: Times, order: int) -> tuple[np.ndarray, np.ndarray]:
        return float_values(self._fast(order), self.scene.n, times.hi, times.lo)

    def _escalate(self, times: Times, order: int, target: float) -> tuple[np.ndarray, np.ndarray]:
        return certified_values(self.certified, times, order, target, self._floor(order))

    def _digits(self, times: Times, order: int, dps: int) -> tuple[np.ndarray, np.ndarray]:
        return certified_digits(self.certified, times, order, dps, self._floor(order))
