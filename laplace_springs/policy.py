"""The route policy: which route solves a scene, when an evaluation escalates, and what
every route promises. Every threshold that decides a route or an escalation is named here.

**The contract.** Every solution, whatever its route, returns from ``evaluate`` values
whose error at each time t satisfies

    error_i(t) = abs(x_i(t) − value_i) ≤ target · max(‖x(t)‖∞, S₀)   for every coordinate i,

with ``target`` = :data:`TARGET` unless the caller says otherwise and
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

from .analysis.modes import MODES_EXACT_MAX_COORDINATES
from .model.errors import SceneError
from .numeric.chebyshev import SHAPES_MAX_COORDINATES
from .numeric.first_order import NUMERIC_MAX_COORDINATES

__all__ = [
    "TARGET", "MIN_RELATIVE_BOUND", "METHODS", "ROUTES", "CERTIFIED_AUTO_MAX_COORDINATES",
    "EXACT_AUTO_MAX_COORDINATES", "EXACT_FALLBACK_MAX_COORDINATES",
    "EXACT_FORM_MAX_COORDINATES", "CERTIFIED_MAX_ORDER", "ESCALATION_DIGITS", "PROBE_TIMES",
    "NUMERIC_MAX_COORDINATES", "GENERAL_MODAL_MAX_COORDINATES", "CLASSICAL_MAX_COORDINATES",
    "CHEBYSHEV_MIN_COORDINATES", "CHEBYSHEV_MAX_COORDINATES",
    "CLOSED_FORM_MAX_COORDINATES", "MODES_EXACT_MAX_COORDINATES", "KRYLOV_AUTO_MIN_COORDINATES",
    "SceneFacts", "Decision", "route_for", "after_modal_probe", "reference_scale",
    "column_scales", "escalate_columns", "check_target",
]

#: Default accuracy of every evaluation, relative to max(‖x(t)‖∞, S₀) (see the contract).
TARGET = 1e-13
#: A float64 bound never claims less than this relative to the value (14 significant
#: digits): a decimal reference printed to 15 digits differs from a correctly rounded
#: float64 value by up to 5e-15 of it, and no float64 value is better than its decimal.
MIN_RELATIVE_BOUND = 1e-14

#: The routes a solution reports as its ``method``.
ROUTES = ("exact", "modal", "certified", "krylov")
#: What ``solve(method=...)`` accepts; "numeric" is the former name of "modal".
METHODS = ("auto", *ROUTES, "numeric")

#: "auto" certifies rational scenes up to this many coordinates. Measured with
#: benchmarks/bench_routes.py (damped chains, 1000 times): certified 2–10 ms for 1–4
#: masses where modal takes 3–21 ms and the exact route 20–160 ms; from 6 masses on the
#: two are close or modal is faster (8 masses: 18 ms against 35 ms).
CERTIFIED_AUTO_MAX_COORDINATES = 4
#: "auto" solves exactly up to this many coordinates when the certified route cannot take
#: the scene (irrational entries): Δ of degree ≤ 4, radicals, milliseconds.
EXACT_AUTO_MAX_COORDINATES = 2
#: Largest scene the exact route serves as a fallback or escalation (symbolic work grows
#: fast with the degree of Δ's irreducible factors).
EXACT_FALLBACK_MAX_COORDINATES = 8
#: Largest scene whose ``x`` is built as an exact closed form on other routes; beyond it
#: ``x`` is the modal form with Float coefficients.
EXACT_FORM_MAX_COORDINATES = 8
#: Largest first-order size (2n) the certified route takes: its roots cost about 1 s at
#: degree 100 and grow like the cube of the degree.
CERTIFIED_MAX_ORDER = 120
#: Largest scene the general (non-symmetric) modal route takes: it holds the 2n x 2n
#: first-order matrix densely and decomposes it four times (the motion and three perturbed
#: copies for its error bound). Damped chains, one core: 200 coordinates 1 s, 400 6 s,
#: 800 31 s; time grows like n³, memory like n². (The same number bounds the dense float64
#: arrays of :func:`laplace_springs.numeric.first_order.scene_arrays`.)
GENERAL_MODAL_MAX_COORDINATES = NUMERIC_MAX_COORDINATES
#: Largest undamped or classically damped scene the symmetric modal route takes: it holds
#: the n x n shapes (128 MB at 4,000) and a few arrays of modes x times. Measured on Rayleigh
#: chains, 1,000 times, one core: 1,000 masses about 0.2 s (tridiagonal eigenproblem).
#: Rayleigh-damped scenes (C = aK + bM, diagonal M) go further on the Chebyshev route.
CLASSICAL_MAX_COORDINATES = SHAPES_MAX_COORDINATES
#: "auto" solves Rayleigh-damped scenes (C = aK + bM exactly, a, b ≥ 0, diagonal positive
#: M) from this many coordinates by Chebyshev expansion in M⁻¹K
#: (:mod:`laplace_springs.numeric.chebyshev`: sparse products, no eigenvectors) instead of
#: the symmetric eigenproblem, because its own error bound meets the target where the eigen
#: route's does not. Measured with ``solve(scene).evaluate(times, return_error=True)``,
#: 1,000 times on [0, 50], one core (benchmarks/bench_scaling.py scenes), bound relative to
#: max |x|: Rayleigh chains of 20, 40, 64, 100 masses: Chebyshev 13–15 ms, bound 1.8e-14;
#: eigen route 6–9 ms but bound 8.5e-14 at 20, then escalated to the certified route
#: (0.4 s at 20, 0.9 s at 40) or, beyond its size, returned with bounds of 4.7e-10 (64) and
#: 1.2e-9 (100). Random meshes: Chebyshev 27–31 ms with bounds ≤ 4.4e-14, eigen route
#: 8–14 ms with 3.9e-9 to 5.4e-9 (or certified, 0.15–1.7 s). From 1,000 masses the
#: Chebyshev route is also the faster (chain: 0.05 s against 0.12 s for the hand-written
#: tridiagonal modal route).
CHEBYSHEV_MIN_COORDINATES = 16
#: Largest scene the Chebyshev route takes (the scene files' limit): it holds n x (N+1)
#: vectors, N ≈ t_max·√‖M⁻¹K‖/2 + a few dozen (8 MB at 10,000 masses and N = 100).
CHEBYSHEV_MAX_COORDINATES = 100_000
#: "auto" solves scenes whose damping is not classical from this many coordinates on the
#: krylov route (:mod:`laplace_springs.numeric.krylov`: Taylor steps of the sparse
#: first-order system in double-double arithmetic, bounded through the energy, which the
#: exact motion never increases) instead of the dense 2n x 2n eigenproblem. Measured on
#: chains with one extra wall dashpot, 1,000 times on [0, 50], one core: 200 masses 0.86 s
#: against 1.8 s (general modal route), 1,000 masses 2.7 s against 232 s and 762 MB.
KRYLOV_AUTO_MIN_COORDINATES = 200
#: Largest scene whose ``x`` on a modal route is a SymPy column (Float coefficients);
#: beyond it ``x`` is a :class:`~laplace_springs.numeric.classical.ModalForm` (a sum over
#: modes with coefficient vectors; ``x.as_matrix()`` builds the SymPy column on request):
#: 12 rows of 24 terms are still readable, 200 rows of 400 terms are not.
CLOSED_FORM_MAX_COORDINATES = 12
#: Decimal digits of an escalated float64 evaluation on the exact route.
ESCALATION_DIGITS = 20
#: Times (in the scene's time unit) at which "auto" checks the modal route's own bound
#: before it keeps the route.
PROBE_TIMES = (0.0, 1.0)


def check_target(target: float | None) -> float:
    """The target to use: :data:`TARGET` for None, else a number in [1e-300, 1).

    >>> check_target(None), check_target(1e-10)
    (1e-13, 1e-10)
    """
    if target is None:
        return TARGET
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
        Chebyshev route takes it at any size up to CHEBYSHEV_MAX_COORDINATES.
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
                and 2 * self.n <= CERTIFIED_MAX_ORDER)

    @property
    def modal_ok(self) -> bool:
        return (self.first_order and not self.forced and not self.symbolic
                and self.n <= (CHEBYSHEV_MAX_COORDINATES if self.rayleigh
                               else CLASSICAL_MAX_COORDINATES if self.classical
                               else GENERAL_MODAL_MAX_COORDINATES))

    @property
    def modal_kind(self) -> str:
        """"chebyshev" (Rayleigh damping from CHEBYSHEV_MIN_COORDINATES, or beyond the eigen
        route's size), "classical" (the symmetric eigenproblem of size n) or "general" (2n,
        non-symmetric)."""
        if self.rayleigh and (self.n >= CHEBYSHEV_MIN_COORDINATES
                              or self.n > CLASSICAL_MAX_COORDINATES):
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
    if facts.certified_ok and facts.n <= CERTIFIED_AUTO_MAX_COORDINATES:
        return Decision("certified", f"auto: {facts.n} coordinate(s) <= "
                        f"CERTIFIED_AUTO_MAX_COORDINATES = {CERTIFIED_AUTO_MAX_COORDINATES}: "
                        "certified poles take milliseconds (the exact form is built when asked)")
    if facts.n <= EXACT_AUTO_MAX_COORDINATES:
        return Decision("exact", f"auto: {facts.n} coordinate(s) <= EXACT_AUTO_MAX_COORDINATES = "
                        f"{EXACT_AUTO_MAX_COORDINATES} and entries the certified route does not "
                        "take: exact partial fractions take milliseconds")
    if facts.modal_ok and facts.modal_kind == "chebyshev":
        return Decision("modal", f"auto: {facts.n} coordinates, Rayleigh damping C = aK + bM "
                        "(exactly) and a diagonal M: Chebyshev expansion in M⁻¹K with sparse "
                        "products, every time at once (no eigenvectors)")
    if facts.krylov and not facts.classical and facts.n >= KRYLOV_AUTO_MIN_COORDINATES:
        return Decision("krylov", f"auto: {facts.n} coordinates >= KRYLOV_AUTO_MIN_COORDINATES = "
                        f"{KRYLOV_AUTO_MIN_COORDINATES} and damping that is not classical: Taylor "
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
                f"scene has n = {facts.n:,} coordinates, more than CHEBYSHEV_MAX_COORDINATES = "
                f"{CHEBYSHEV_MAX_COORDINATES:,}. Solve a coarser model")
        if facts.classical:
            raise SceneError(
                f"the modal route holds the n x n mode shapes of a classically damped scene "
                f"whose damping is not Rayleigh's (C = aK + bM with a diagonal M: those go up to "
                f"CHEBYSHEV_MAX_COORDINATES = {CHEBYSHEV_MAX_COORDINATES:,}); this scene has "
                f"n = {facts.n:,} coordinates, more than CLASSICAL_MAX_COORDINATES = "
                f"{CLASSICAL_MAX_COORDINATES:,}. Solve a coarser model")
        raise SceneError(
            f"the general modal route (damping that is not classical) holds the scene as dense "
            f"float64 matrices and decomposes its 2n x 2n first-order matrix; this scene has "
            f"n = {facts.n:,} coordinates, more than NUMERIC_MAX_COORDINATES = "
            f"{GENERAL_MODAL_MAX_COORDINATES:,} (800 take about 30 s on one core, and the time "
            f"grows like n³). Undamped and classically damped scenes (C M⁻¹K = K M⁻¹C) go up to "
            f"CLASSICAL_MAX_COORDINATES = {CLASSICAL_MAX_COORDINATES:,}, Rayleigh-damped ones "
            f"(C = aK + bM, diagonal M) up to CHEBYSHEV_MAX_COORDINATES = "
            f"{CHEBYSHEV_MAX_COORDINATES:,}")
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
               else f"is too large (2n = {2 * facts.n} > CERTIFIED_MAX_ORDER = {CERTIFIED_MAX_ORDER})")
        raise SceneError(f"the certified route cannot take this scene: it {why}")


def after_modal_probe(facts: SceneFacts, worst: float, target: float) -> Decision | None:
    """For "auto": a better route when the modal bound at :data:`PROBE_TIMES` misses the
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
