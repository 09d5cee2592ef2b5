"""The route policy: which route solves a scene, when an evaluation escalates, and what
every route promises. Every threshold that decides a route or an escalation is named here.

**The contract.** Every solution, whatever its route, returns from ``evaluate`` values
whose error at each time t satisfies

    error_i(t) = abs(x_i(t) − value_i) ≤ target · max(‖x(t)‖∞, S₀)   for every coordinate i,

with ``target`` = :attr:`~laplace_springs.limits.Limits.target` unless the caller says otherwise and
S₀ = ‖x0‖∞ + ‖v0‖∞/ρ, ρ the largest |pole| (the size of the initial data in units of
displacement). When it cannot (a target below float64's reach, a route that has nothing
better), the error bound it returns says by how much it may be wrong. That bound is an
upper bound for every entry and every time: never NaN, never inf.

**Escalation.** Each route first evaluates in float64 with a running error bound. A time
whose bound misses the contract is recomputed by a more precise route, alone: the
decision for a time never looks at the other times of the call, so a value does not
depend on them. The escalation routes are

* exact route → its own terms in mpmath at raised precision ("mp");
* modal route → the certified route ("certified") where the scene allows it, else the
  exact route's mpmath evaluation, else nothing (the bound then says so);
* certified route → ball arithmetic at doubled precision ("certified").

**Routes.** "exact" (partial fractions; symbols, forcing, closed forms), "modal" (float64
eigen-decomposition; fast for large scenes), "certified" (exact polynomials, certified
roots, ball arithmetic; any multiplicity). :func:`route_for` decides from
:class:`SceneFacts`; ``"auto"`` takes the fastest route that meets the contract: the
certified route for small rational scenes, the modal route for larger ones, the exact
route for symbols, forcing and what the others cannot take. Whatever the route, the
exact closed form and the seed's g-basis are built when asked (``x``, ``g_basis``, ...).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .limits import limits
from .model.errors import SceneError

__all__ = [
    "METHODS", "ROUTES", "SceneFacts", "Decision", "route_for", "after_modal_probe", "reference_scale",
    "column_scales", "escalate_columns", "check_target",
]


#: The routes a solution reports as its ``method``.
ROUTES = ("exact", "modal", "certified", "krylov")
#: What ``solve(method=...)`` accepts; "numeric" is the former name of "modal".
METHODS = ("auto", *ROUTES, "numeric")



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


@dataclass(frozen=True)
class SceneFacts:
    """What the policy needs to know of a scene.

    Attributes
    ----------
    n : int
        Coordinates.
    symbolic : bool
        Some entry has a free symbol.
    forced : bool
        An external force acts.
    rational : bool
        Every entry of M, C, K, x0, v0 is a rational number (the certified route's input).
    first_order : bool
        The scene has a first-order form: M invertible, or massless nodes held by
        dashpots (the modal and certified routes need it).
    classical : bool
        Undamped or classically damped (symmetric M, C, K with C M⁻¹ K = K M⁻¹ C, checked
        exactly): the symmetric modal route takes it.
    rayleigh : bool
        Rayleigh damping C = aK + bM (a, b ≥ 0, exactly) with a diagonal, positive M: the
        Chebyshev route takes it at any size up to Limits.chebyshev_max_coordinates.
    krylov : bool
        Rational, unforced, diagonal positive M, K ⪰ 0 and C + Cᵀ ⪰ 0 proved exactly (by
        diagonal dominance): the krylov route can bound its motion through the energy.
    """

    n: int
    symbolic: bool
    forced: bool
    rational: bool
    first_order: bool
    classical: bool = False
    rayleigh: bool = False
    krylov: bool = False

    @property
    def certified_ok(self) -> bool:
        return (self.rational and self.first_order and not self.forced and not self.symbolic
                and 2 * self.n <= limits().certified_max_order)

    @property
    def modal_ok(self) -> bool:
        return (self.first_order and not self.forced and not self.symbolic
                and self.n <= (limits().chebyshev_max_coordinates if self.rayleigh
                               else limits().classical_max_coordinates if self.classical
                               else limits().general_modal_max_coordinates))

    @property
    def modal_kind(self) -> str:
        """"chebyshev" (Rayleigh damping from Limits.chebyshev_min_coordinates, or beyond the eigen
        route's size), "classical" (the symmetric eigenproblem of size n) or "general" (2n,
        non-symmetric)."""
        if self.rayleigh and (self.n >= limits().chebyshev_min_coordinates
                              or self.n > limits().classical_max_coordinates):
            return "chebyshev"
        return "classical" if self.classical else "general"


@dataclass(frozen=True)
class Decision:
    """A route and why it was chosen."""

    route: str
    reason: str


def route_for(method: str, facts: SceneFacts) -> Decision:
    """The route ``solve(scene, method=method)`` takes first.

    ``"auto"`` may revise a modal decision after probing the modal route's bound
    (:func:`after_modal_probe`).

    Examples
    --------
    >>> facts = SceneFacts(n=8, symbolic=False, forced=False, rational=True, first_order=True)
    >>> route_for("auto", facts).route, route_for("certified", facts).route
    ('modal', 'certified')
    >>> route_for("auto", SceneFacts(2, False, False, True, True)).route
    'certified'
    >>> route_for("auto", SceneFacts(2, False, True, True, True)).route   # forced
    'exact'
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    if method == "numeric":
        method = "modal"
    if method != "auto":
        _check_applicable(method, facts)
        return Decision(method, f"method={method!r} was requested")
    if facts.symbolic:
        return Decision("exact", "auto: the scene has symbols; only the exact route keeps them")
    if facts.forced:
        return Decision("exact", "auto: the scene is forced; the exact route takes forcing")
    if facts.certified_ok and facts.n <= limits().certified_auto_max_coordinates:
        return Decision("certified", f"auto: {facts.n} coordinate(s) <= "
                        f"Limits.certified_auto_max_coordinates = {limits().certified_auto_max_coordinates}: "
                        "certified poles take milliseconds (the exact form is built when asked)")
    if facts.n <= limits().exact_auto_max_coordinates:
        return Decision("exact", f"auto: {facts.n} coordinate(s) <= Limits.exact_auto_max_coordinates = "
                        f"{limits().exact_auto_max_coordinates} and entries the certified route does not "
                        "take: exact partial fractions take milliseconds")
    if facts.modal_ok and facts.modal_kind == "chebyshev":
        return Decision("modal", f"auto: {facts.n} coordinates, Rayleigh damping C = aK + bM "
                        "(exactly) and a diagonal M: Chebyshev expansion in M⁻¹K with sparse "
                        "products, every time at once (no eigenvectors)")
    if facts.krylov and not facts.classical and facts.n >= limits().krylov_auto_min_coordinates:
        return Decision("krylov", f"auto: {facts.n} coordinates >= Limits.krylov_auto_min_coordinates = "
                        f"{limits().krylov_auto_min_coordinates} and damping that is not classical: Taylor "
                        "steps of the sparse first-order system, bounded through the energy "
                        "(no dense 2n x 2n eigenproblem)")
    if facts.modal_ok and facts.classical:
        return Decision("modal", f"auto: {facts.n} coordinates, undamped or classically damped "
                        "(C M⁻¹K = K M⁻¹C exactly): real modes from the symmetric eigenproblem of "
                        "size n, each mode in closed form")
    if facts.modal_ok:
        return Decision("modal", f"auto: {facts.n} coordinates: the modal route meets the "
                        "contract in milliseconds where exact partial fractions take seconds")
    if facts.first_order and not facts.forced:
        _check_applicable("modal", facts)  # a size refusal, with its reason
    return Decision("exact", "auto: the scene has no first-order form (massless nodes not held "
                    "by dashpots); the exact route handles it")


def _check_applicable(route: str, facts: SceneFacts) -> None:
    if route == "krylov" and not facts.krylov:
        raise SceneError("the krylov route cannot take this scene: it needs rational entries, no "
                         "forcing, a diagonal positive M, and K ⪰ 0 and C + Cᵀ ⪰ 0 proved by "
                         "diagonal dominance (every spring-and-dashpot network has them)")
    if route == "modal" and facts.first_order and not facts.forced and not facts.symbolic \
            and not facts.modal_ok:
        if facts.rayleigh:
            raise SceneError(
                f"the Chebyshev route holds n x (N+1) vectors of a Rayleigh-damped scene; this "
                f"scene has n = {facts.n:,} coordinates, more than Limits.chebyshev_max_coordinates = "
                f"{limits().chebyshev_max_coordinates:,}. Solve a coarser model")
        if facts.classical:
            raise SceneError(
                f"the modal route holds the n x n mode shapes of a classically damped scene "
                f"whose damping is not Rayleigh's (C = aK + bM with a diagonal M: those go up to "
                f"Limits.chebyshev_max_coordinates = {limits().chebyshev_max_coordinates:,}); this scene has "
                f"n = {facts.n:,} coordinates, more than Limits.classical_max_coordinates = "
                f"{limits().classical_max_coordinates:,}. Solve a coarser model")
        raise SceneError(
            f"the general modal route (damping that is not classical) holds the scene as dense "
            f"float64 matrices and decomposes its 2n x 2n first-order matrix; this scene has "
            f"n = {facts.n:,} coordinates, more than Limits.general_modal_max_coordinates = "
            f"{limits().general_modal_max_coordinates:,} (800 take about 30 s on one core, and the time "
            f"grows like n³). Undamped and classically damped scenes (C M⁻¹K = K M⁻¹C) go up to "
            f"Limits.classical_max_coordinates = {limits().classical_max_coordinates:,}, Rayleigh-damped ones "
            f"(C = aK + bM, diagonal M) up to Limits.chebyshev_max_coordinates = "
            f"{limits().chebyshev_max_coordinates:,}")
    if route == "modal" and not facts.modal_ok:
        why = ("has symbols" if facts.symbolic else "is forced" if facts.forced
               else "has no first-order form (massless nodes not held by dashpots, or a "
               "singular mass matrix)")
        raise SceneError(f"the modal route cannot take this scene: it {why}; use method='exact'")
    if route == "certified" and not facts.certified_ok:
        why = ("has symbols" if facts.symbolic else "is forced" if facts.forced
               else "has irrational entries" if not facts.rational
               else "has no first-order form (massless nodes not held by dashpots, or a "
               "singular mass matrix)" if not facts.first_order
               else f"is too large (2n = {2 * facts.n} > Limits.certified_max_order = {limits().certified_max_order})")
        raise SceneError(f"the certified route cannot take this scene: it {why}")


def after_modal_probe(facts: SceneFacts, worst: float, target: float) -> Decision | None:
    """For "auto": a better route when the modal bound at :attr:`~laplace_springs.limits.Limits.probe_times` misses the
    target (``worst`` is the largest bound/scale ratio found), else None (keep modal).

    >>> facts = SceneFacts(20, False, False, True, True)
    >>> after_modal_probe(facts, 1e-16, 1e-13) is None, after_modal_probe(facts, 1e-7, 1e-13).route
    (True, 'certified')
    """
    if worst <= target:
        return None
    if facts.certified_ok:
        return Decision("certified", f"auto: the modal route's own bound ({worst:.1e} of the "
                        f"solution's size) misses the target {target:g}, so the poles were "
                        "certified in ball arithmetic")
    return None


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
    with np.errstate(invalid="ignore"):
        return np.maximum(np.max(np.abs(values), axis=0), floor)


def escalate_columns(values: np.ndarray, bounds: np.ndarray, floor: float,
                     target: float) -> np.ndarray:
    """The columns (times) whose bound misses the contract: a boolean mask.

    A column escalates when some bound exceeds ``target`` times its own scale, or when a
    value or bound is not finite. Only the column's own numbers are looked at.

    Examples
    --------
    >>> values = np.array([[1.0, 1.0, 0.0]])
    >>> bounds = np.array([[1e-16, 1e-12, np.inf]])
    >>> escalate_columns(values, bounds, 0.5, 1e-13).tolist()
    [False, True, True]
    """
    scale = column_scales(values, floor)
    with np.errstate(invalid="ignore"):
        bad = ~np.all(np.isfinite(values) & np.isfinite(bounds), axis=0)
        return bad | np.any(bounds > target * scale[None, :], axis=0)
