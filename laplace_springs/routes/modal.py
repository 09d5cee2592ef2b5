"""The modal route: float64 modes with a measured error bound, escalating to the certified
route (or the exact route's mpmath evaluation) for the times whose bound misses the target.
"""

from __future__ import annotations

from functools import cached_property
from typing import Any

import numpy as np
import sympy as sp

from ..model.scene import Scene
from ..numeric.certified import CertifiedPoles, certified_digits, certified_poles, certified_values
from ..numeric.modal import ModalMotion
from ..numeric.times import Times
from ..policy import CERTIFIED_MAX_ORDER, EXACT_FALLBACK_MAX_COORDINATES
from ..solution import Solution
from .exact import ExactSolution, exact_solution_of

__all__ = ["ModalSolution"]


class ModalSolution(Solution):
    """Motion x(t) of a numeric scene from a conditioned float64 eigen-decomposition.

    Holds a :class:`~laplace_springs.numeric.modal.ModalMotion`. Times whose float64 bound
    misses the target go to the certified route where the scene allows it (rational
    entries, 2n ≤ :data:`~laplace_springs.policy.CERTIFIED_MAX_ORDER`), else to the exact
    route's mpmath evaluation (up to
    :data:`~laplace_springs.policy.EXACT_FALLBACK_MAX_COORDINATES` coordinates).
    """

    method = "modal"

    def __init__(self, scene: Scene, motion: ModalMotion, *, reason: str,
                 target: float | None = None, certified: CertifiedPoles | None = None) -> None:
        super().__init__(scene, reason=reason, target=target)
        self.motion = motion
        self._given_certified = certified

    @property
    def modes(self) -> Any:
        """The float64 modes and blocks (:class:`~laplace_springs.numeric.modal.Modes`)."""
        return self.motion.modes

    @property
    def poles(self) -> np.ndarray:
        return self.motion.poles()

    @property
    def _spectral_radius(self) -> float:
        return float(np.max(np.abs(self.poles), initial=0.0))

    @cached_property
    def _exact_form(self) -> ExactSolution | None:
        return exact_solution_of(self.scene, method=self.method, target=self.target)

    @cached_property
    def x(self) -> sp.ImmutableMatrix:
        """x(t): the exact closed form up to EXACT_FORM_MAX_COORDINATES coordinates (built on
        first use), else terms t^p e^{αt}(a cos βt + b sin βt) with Float coefficients."""
        exact = self._exact_form
        return exact.x if exact is not None else self.motion.closed_form()

    @cached_property
    def _certified(self) -> CertifiedPoles | None:
        if self._given_certified is not None:
            return self._given_certified
        if 2 * self.scene.n > CERTIFIED_MAX_ORDER:
            return None
        return certified_poles(self.scene)

    @cached_property
    def _exact_fallback(self) -> ExactSolution | None:
        if self.scene.n > EXACT_FALLBACK_MAX_COORDINATES:
            return None
        return self._exact_form

    @property
    def escalation(self) -> str | None:
        if self._certified is not None:
            return "certified"
        return "mp" if self.scene.n <= EXACT_FALLBACK_MAX_COORDINATES else None

    def _float(self, times: Times, order: int) -> tuple[np.ndarray, np.ndarray]:
        values = self.motion.values(times.hi, order)
        bounds = self.motion.bound(times.hi, order)
        if times.lo.any():  # a decimal time: the float evaluated at hi, off by lo·x'
            slope = np.abs(self.motion.values(times.hi, order + 1))
            bounds = bounds + 2 * np.abs(times.lo)[None, :] * slope
        return values, bounds

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
