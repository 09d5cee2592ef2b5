"""The modal route: float64 modes with a measured error bound, escalating to the certified
route (or the exact route's mpmath evaluation) for the times whose bound misses the target.
"""

from __future__ import annotations

import math
from functools import cached_property
from typing import Any

import numpy as np

from ..limits import limits
from ..model.errors import InversionError
from ..model.scene import Scene
from ..numeric.certified import CertifiedPoles, certified_digits, certified_poles, certified_values
from ..numeric.chebyshev import ChebyshevMotion
from ..numeric.classical import ClassicalMotion
from ..numeric.times import Times
from ..policy import reference_scale
from ..solution import Solution
from .exact import ExactSolution, exact_solution_of

__all__ = ["ModalSolution"]


class ModalSolution(Solution):
    """Motion x(t) of a numeric scene from float64 modes.

    Hosts a float64 engine's motion: a :class:`~laplace_springs.numeric.modal.ModalMotion`
    (the conditioned eigen-decomposition of the 2n x 2n first-order matrix), a
    :class:`~laplace_springs.numeric.classical.ClassicalMotion` (real modes of the symmetric
    eigenproblem of size n, decomposed on first use), a
    :class:`~laplace_springs.numeric.chebyshev.ChebyshevMotion` (Chebyshev expansion in M⁻¹K;
    ``modes`` and ``x`` built on request up to
    :attr:`~laplace_springs.limits.Limits.classical_max_coordinates`), or a motion of the
    planner's engine interface (``evaluate(times, order)``, ``poles()``, ``engine``: the
    refined and tiny engines). :attr:`method` names the engine. Times whose float64 bound
    misses the target are recomputed by the next engines of the plan
    (:mod:`laplace_springs.planning`).
    """

    def __init__(self, scene: Scene, motion: Any, *, reason: str | None,
                 target: float | None = None, certified: CertifiedPoles | None = None) -> None:
        super().__init__(scene, reason=reason, target=target)
        self.motion = motion
        self._given_certified = certified

    @property
    def method(self) -> str:  # type: ignore[override]
        """The engine: "classical" (symmetric eigenproblem), "chebyshev" (expansion in
        M⁻¹K), "modal" (the general 2n x 2n eigenproblem), or the motion's own ``engine``."""
        if isinstance(self.motion, ChebyshevMotion):
            return "chebyshev"
        if isinstance(self.motion, ClassicalMotion):
            return "classical"
        return str(getattr(self.motion, "engine", "modal"))

    def _require_numbers(self) -> None:
        """Nothing to check: :func:`~laplace_springs.solve` never gives this route symbols
        (and reading a large scene's symbols costs time on every evaluation)."""

    @property
    def modes(self) -> Any:
        """The float64 modes and blocks (:class:`~laplace_springs.numeric.modal.Modes`)."""
        return self.motion.modes

    @property
    def poles(self) -> np.ndarray:
        return self.motion.poles()

    @cached_property
    def _spectral_radius(self) -> float:  # the motion's poles do not change
        """max |λ| from the motion's float64 poles; where they overflow (a damping of
        1e300), from the certified poles, which the escalation evaluates with (so the
        contract's scale S₀ρ^k is the same as on the certified route)."""
        radius = self._float_radius()
        if not math.isfinite(radius) and self._certified is not None:
            return float(self._certified.spectral_radius())
        return radius

    def _float_radius(self) -> float:
        if isinstance(self.motion, ChebyshevMotion):  # no eigenvalues computed for evaluate()
            return float(self.motion.spectral_radius)
        radius = getattr(self.motion, "spectral_radius", None)  # the tiny engine keeps it
        if radius is not None:
            return float(radius)
        return float(np.max(np.abs(self.poles), initial=0.0))

    @cached_property
    def _base_floor(self) -> float:
        data = getattr(self.motion, "data", None)  # the symmetric routes' float x0, v0 (no
        if data is None:                           # massless nodes): no SymPy walk of x0, v0
            return super()._base_floor
        return reference_scale(max(map(abs, data.x0.tolist()), default=0.0),
                               max(map(abs, data.v0.tolist()), default=0.0), self._spectral_radius)

    @cached_property
    def _exact_form(self) -> ExactSolution | None:
        """The exact solution, or None beyond Limits.exact_form_max_coordinates and where
        the exact route has no closed form (a factor of Δ with irrational coefficients)."""
        try:
            return exact_solution_of(self.scene, method=self.method, target=self.target)
        except InversionError as exc:
            self.inexact_reason = str(exc)
            return None

    #: Why ``x`` is not the exact closed form of a scene small enough for one (the exact
    #: route's refusal), once ``x`` has been built; None otherwise.
    inexact_reason: str | None = None

    @cached_property
    def x(self) -> Any:
        """x(t), built on first use: the exact closed form up to Limits.exact_form_max_coordinates
        coordinates where it exists; otherwise, up to Limits.closed_form_max_coordinates, a SymPy column of terms
        t^p e^{αt}(a cos βt + b sin βt) with Float coefficients; beyond, the same terms as a
        :class:`~laplace_springs.numeric.classical.ModalForm` (a sum over modes with
        coefficient vectors: ``x[i]`` is row i, ``x.as_matrix()`` the whole column)."""
        exact = self._exact_form
        if exact is not None:
            return exact.x
        if self.scene.n <= limits().closed_form_max_coordinates:
            return self.motion.closed_form()
        return self.motion.modal_form()

    def latex(self, **kw: Any) -> str:
        """LaTeX of x(t); for a scene beyond Limits.closed_form_max_coordinates a summary of its
        modal form (``x.as_matrix()`` gives the full column)."""
        if self._exact_form is None and self.scene.n > limits().closed_form_max_coordinates:
            form = self.x
            return (f"x(t) = \\sum_{{j=1}}^{{{len(form.powers)}}} t^{{p_j}} e^{{\\alpha_j t}}"
                    f"\\left(a_j \\cos \\beta_j t + b_j \\sin \\beta_j t\\right)"
                    f"\\quad ({self.scene.n} \\text{{ coordinates}})")
        return super().latex(**kw)

    @cached_property
    def _certified(self) -> CertifiedPoles | None:
        if self._given_certified is not None:
            return self._given_certified
        if 2 * self.scene.n > limits().certified_max_order:
            return None
        return certified_poles(self.scene)

    @cached_property
    def _exact_fallback(self) -> ExactSolution | None:
        if self.scene.n > limits().exact_fallback_max_coordinates:
            return None
        return self._exact_form

    def _float(self, times: Times, order: int) -> tuple[np.ndarray, np.ndarray]:
        if hasattr(self.motion, "evaluate"):  # an engine of the planner's interface
            result: tuple[np.ndarray, np.ndarray] = self.motion.evaluate(times, order)
            return result
        values = self.motion.values(times.hi, order)
        bounds = self.motion.bound(times.hi, order)
        if times.lo.any():  # a decimal time: the float evaluated at hi, off by lo·x'
            slope = np.abs(self.motion.values(times.hi, order + 1))
            bounds = bounds + 2 * np.abs(times.lo)[None, :] * slope
        return values, bounds

    def _covered_values(self, times: Times, most: float) -> np.ndarray | None:
        motion = self.motion
        if not hasattr(motion, "bound_until") or not motion.bound_until(times.span[1]) <= most:
            return None
        values: np.ndarray = motion.values(times, 0)
        return values

    def _escalate(self, times: Times, order: int, target: float) -> tuple[np.ndarray, np.ndarray]:
        if self._certified is not None:
            return certified_values(self._certified, times, order, target, self._floor(order))
        exact = self._exact_fallback
        if exact is not None:
            return exact._escalate(times, order, target)
        return self._float(times, order)

    def _digits(self, times: Times, order: int, dps: int) -> tuple[np.ndarray, np.ndarray]:
        if self._certified is not None:
            return certified_digits(self._certified, times, order, dps, self._floor(order))
        exact = self._exact_fallback
        if exact is not None:
            return exact._digits(times, order, dps)
        raise ValueError("evaluate(..., dps=) needs the certified or the exact route, and this "
                         f"scene suits neither ({self.scene.n} coordinates, entries "
                         "not all rational or too large for them)")
