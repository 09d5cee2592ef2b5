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

from .model.errors import SceneError

__all__ = [
    "TARGET", "MIN_RELATIVE_BOUND", "METHODS", "ROUTES", "CERTIFIED_AUTO_MAX_COORDINATES",
    "EXACT_AUTO_MAX_COORDINATES", "EXACT_FALLBACK_MAX_COORDINATES",
    "EXACT_FORM_MAX_COORDINATES", "CERTIFIED_MAX_ORDER", "ESCALATION_DIGITS", "PROBE_TIMES",
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
ROUTES = ("exact", "modal", "certified")
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
    """

    n: int
    symbolic: bool
    forced: bool
    rational: bool
    first_order: bool

    @property
    def certified_ok(self) -> bool:
        return (self.rational and self.first_order and not self.forced and not self.symbolic
                and 2 * self.n <= CERTIFIED_MAX_ORDER)

    @property
    def modal_ok(self) -> bool:
        return self.first_order and not self.forced and not self.symbolic


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
    if facts.modal_ok:
        return Decision("modal", f"auto: {facts.n} coordinates: the modal route meets the "
                        "contract in milliseconds where exact partial fractions take seconds")
    return Decision("exact", "auto: the scene has no first-order form (massless nodes not held "
                    "by dashpots); the exact route handles it")


def _check_applicable(route: str, facts: SceneFacts) -> None:
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
