"""The Taylor ("krylov") route: large sparse scenes with non-classical damping.

The motion is marched through the sparse first-order system in Taylor steps
(:mod:`laplace_springs.numeric.krylov`: the large terms formed to about 2^-70, the rest in
float64) with a bound from the energy, which never grows for spring and dashpot networks.
Time grows like nnz·ν·t_max, memory like nnz: no eigen-decomposition, no dense matrix.
"""

from __future__ import annotations

from functools import cached_property
from typing import Any

import numpy as np

from ..limits import limits
from ..model.errors import SceneError
from ..model.scene import Scene
from ..numeric.first_order import rational_entries
from ..numeric.krylov import KrylovMotion, krylov_motion, krylov_refusal
from ..numeric.times import Times
from ..solution import Solution
from .exact import ExactSolution, exact_solution_of

__all__ = ["KrylovSolution", "krylov_solution", "krylov_ok"]


class KrylovSolution(Solution):
    """Motion x(t) of a numeric scene from Taylor steps of z' = A z.

    ``x`` is the exact closed form up to
    :attr:`~laplace_springs.limits.Limits.exact_form_max_coordinates` coordinates and a
    SceneError beyond (the route has no modes: use :meth:`evaluate`). :attr:`poles` is
    partial beyond 200 coordinates (see :meth:`KrylovMotion.poles`). Times whose bound
    misses the target go to the exact route's mpmath evaluation up to
    :attr:`~laplace_springs.limits.Limits.exact_fallback_max_coordinates` coordinates; beyond,
    the bound says how large the error may be (it is near 1e-14 of the solution's size
    for t·ν up to a few hundred).
    """

    method = "krylov"

    def __init__(self, scene: Scene, motion: KrylovMotion, *, reason: str | None,
                 target: float | None = None) -> None:
        super().__init__(scene, reason=reason, target=target)
        self.motion = motion

    def _require_numbers(self) -> None:
        """Nothing to check: the route was built from rational entries."""

    @cached_property
    def poles(self) -> np.ndarray:
        """All poles up to 200 coordinates; beyond, the 6 of largest modulus and the 6
        nearest 0 (ARPACK), so ``poles.real.max()`` is the slowest decay found."""
        return self.motion.poles()

    @cached_property
    def _spectral_radius(self) -> float:
        """max |λ| (ARPACK, or the energy bound ν ≥ ρ where ARPACK fails)."""
        poles = self.poles
        return float(np.max(np.abs(poles))) if len(poles) else float(self.motion.data.nu)

    def _floor(self, order: int) -> float:
        """S₀·ρ^order; S₀ = ‖x0‖∞ without computing ρ when v0 = 0 and order = 0 (read from
        the exact nonzero entries: the route was built from rational ones)."""
        v0 = rational_entries(self.scene, "v0")
        x0 = rational_entries(self.scene, "x0")
        if order == 0 and not v0 and x0 is not None:
            return float(max((abs(float(v)) for v in x0.values()), default=0.0))
        return super()._floor(order)

    @cached_property
    def _exact_form(self) -> ExactSolution | None:
        return exact_solution_of(self.scene, method=self.method, target=self.target)

    @property
    def x(self) -> Any:
        """The exact closed form up to Limits.exact_form_max_coordinates coordinates; beyond, a
        SceneError (this route marches in time and has no modes)."""
        exact = self._exact_form
        if exact is None:
            raise SceneError(
                f"the krylov route marches the {self.scene.n:,}-coordinate scene in time and has "
                "no closed form: use evaluate(); solve(scene, method='modal') builds the modal form "
                "(up to Limits.general_modal_max_coordinates coordinates)")
        return exact.x

    def latex(self, **kw: Any) -> str:
        """LaTeX of :attr:`x` (a SceneError beyond Limits.exact_form_max_coordinates coordinates)."""
        self.x  # noqa: B018 - raises when there is no closed form
        return super().latex(**kw)

    def _float(self, times: Times, order: int) -> tuple[np.ndarray, np.ndarray]:
        return self.motion.evaluate(times, order)

    def _escalate(self, times: Times, order: int, target: float) -> tuple[np.ndarray, np.ndarray]:
        exact = self._exact_form if self.scene.n <= limits().exact_fallback_max_coordinates else None
        if exact is not None:
            return exact._escalate(times, order, target)
        return self._float(times, order)

    def _digits(self, times: Times, order: int, dps: int) -> tuple[np.ndarray, np.ndarray]:
        exact = self._exact_form if self.scene.n <= limits().exact_fallback_max_coordinates else None
        if exact is not None:
            return exact._digits(times, order, dps)
        raise ValueError("evaluate(..., dps=) needs the exact route, which takes at most "
                         f"Limits.exact_fallback_max_coordinates = {limits().exact_fallback_max_coordinates} "
                         f"coordinates; this scene has {self.scene.n:,}")


def krylov_ok(scene: Scene) -> bool:
    """Whether the krylov route takes the scene: rational entries, no forcing, diagonal
    positive M, symmetric K ⪰ 0 and C + Cᵀ ⪰ 0 proved by diagonal dominance.

    >>> from laplace_springs import Scene
    >>> krylov_ok(Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[1], v0=[0]))
    True
    >>> krylov_ok(Scene.from_matrices(M=[[1]], K=[["k"]], x0=[1], v0=[0], parameters=["k"]))
    False
    """
    return krylov_refusal(scene) is None


def krylov_solution(scene: Scene, *, reason: str, target: float | None = None) -> KrylovSolution:
    """Solve a scene on the krylov route (a SceneError naming why it cannot).

    Examples
    --------
    x'' + x' + 4x = 0, x(0) = 1:

    >>> from laplace_springs import Scene
    >>> sol = krylov_solution(Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[1], v0=[0]),
    ...                       reason="requested")
    >>> sol.method, sol.evaluate([0.0, 1.0]).round(8)
    ('krylov', array([[ 1.        , -0.07064455]]))
    """
    return KrylovSolution(scene, krylov_motion(scene), reason=reason, target=target)
