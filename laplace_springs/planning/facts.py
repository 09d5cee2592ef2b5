"""What the planner knows of a scene: :class:`SceneFacts`, read in time proportional to the
scene's nonzero entries and cached with the scene.

The facts are structural (size, nonzeros, exact or symbolic, forcing, the damping class,
a first-order form) and numerical where that is cheap and certain: for a rational scene
with a diagonal positive M, verified upper bounds on the spectrum of M⁻¹K and on every
pole |λ| (Gershgorin in the mass-weighted norm, summed with a safety margin that covers
float64 rounding), which the planner's cost models read.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, fields, replace
from operator import attrgetter

import numpy as np

from ..exact.screening import exact_refusal
from ..limits import limits
from ..model.periodic import Periodic
from ..model.scene import Scene
from ..numeric.chebyshev import rayleigh_coefficients
from ..numeric.classical import classical_damping
from ..numeric.first_order import (
    has_first_order_form,
    massless_nodes,
    rational_entries,
    scene_cache,
    scene_entries,
)
from ..numeric.krylov import krylov_refusal
from ..numeric.krylov_entries import entries_of
from ..numeric.refined import refined_cost, refined_refusal
from ..numeric.tiny import tiny_cost, tiny_refusal
from .standing import tiny_scene

__all__ = ["SceneFacts", "Quote", "scene_facts"]

#: Relative margin on sums of non-negative float64 terms (≤ n·u for n ≤ 10⁶ terms).
_MARGIN = 1 + 1e-9


@dataclass(frozen=True)
class Quote:
    """An engine module's own answer for a scene, taken once when the facts are read:
    why it cannot take the scene (None when it can), the seconds to build its data and the
    seconds per time (for derivative order 0). The engine module is the one home of these
    rules; the planner reads them as facts."""

    engine: str
    refusal: str | None
    build: float
    per_time: float


@dataclass(frozen=True)
class SceneFacts:
    """What the planner needs to know of a scene.

    Attributes
    ----------
    n : int
        Coordinates.
    symbolic : bool
        Some entry has a free symbol.
    forced : bool
        An external force acts (formula, periodic or sampled).
    rational : bool
        Every entry of M, C, K, x0, v0 is a rational number.
    first_order : bool
        M invertible, or massless nodes held by dashpots: y' = Z y exists.
    classical : bool or None
        Undamped or classically damped (C M⁻¹K = K M⁻¹C, checked exactly); None: not asked
        (a scene the tiny engine takes, unless an engine that needs it is asked for; the
        spectral bounds below are then None too).
    rayleigh : bool or None
        C = aK + bM exactly (a, b ≥ 0) with a diagonal positive M; None as ``classical``.
    krylov : bool
        Rational, unforced, diagonal positive M, K ⪰ 0 and C + Cᵀ ⪰ 0 proved exactly.
    nnz : int
        Nonzero entries of M, C and K together.
    diagonal_mass : bool
        M is diagonal (and has no massless node).
    stiffness_bound : float or None
        A verified upper bound on the eigenvalues of M⁻¹K (diagonal positive rational M),
        else None.
    pole_bound : float or None
        A verified upper bound on every |λ| with det(λ²M + λC + K) = 0 (same condition).
    mean_decay : float or None
        tr(M⁻¹C)/2n, the mean of −Re λ over the 2n poles (Σ λ = −tr(M⁻¹C)): the slowest
        mode decays no faster (same condition; float64, not verified: the planner's
        expectations read it).
    sampled : bool
        A force is a sampled history.
    periodic : bool
        A force is periodic (its pole sums reduce t modulo the period: about five times
        the work per time of a formula force).
    quotes : tuple of Quote
        The answers of engine modules that decide from the scene itself (the refined
        engine: its products depend on the sparsity of K; the exact route's screen of a
        small forced scene, see :func:`scene_facts`).
    """

    n: int
    symbolic: bool
    forced: bool
    rational: bool
    first_order: bool
    classical: bool | None = False   # None: not asked (a scene the tiny engine takes)
    rayleigh: bool | None = False
    krylov: bool | None = False   # None: not asked (a tiny scene)
    nnz: int = 0
    diagonal_mass: bool = False
    stiffness_bound: float | None = None
    pole_bound: float | None = None
    mean_decay: float | None = None
    sampled: bool = False
    periodic: bool = False
    quotes: tuple[Quote, ...] = ()

    def __hash__(self) -> int:
        """The hash of the fields, computed once (every plan is memoised by the facts)."""
        found: int | None = self.__dict__.get("_hash")
        if found is None:
            found = hash(_FIELD_VALUES(self))
            object.__setattr__(self, "_hash", found)
        return found

    def quote(self, engine: str) -> Quote | None:
        """The engine module's quote for this scene, if it gave one."""
        return next((q for q in self.quotes if q.engine == engine), None)

    def knowing(self, built: Iterable[str]) -> SceneFacts:
        """These facts, with what an engine's successful build proves: a built krylov
        engine takes the scene even where its check was not asked (a tiny scene)."""
        built = set(built)
        facts = self
        if facts.krylov is None and "krylov" in built:
            facts = replace(facts, krylov=True)
        if facts.classical is None and built & {"classical", "chebyshev"}:
            facts = replace(facts, classical=True, rayleigh="chebyshev" in built or None)
        return facts

    @property
    def numeric(self) -> bool:
        """Unforced, numbers only, with a first-order form: every float engine may try it."""
        return self.first_order and not self.forced and not self.symbolic


#: The field values of a SceneFacts as a tuple (one C call).
_FIELD_VALUES = attrgetter(*(f.name for f in fields(SceneFacts)))


def scene_facts(scene: Scene, method: str = "auto") -> SceneFacts:
    """The facts of a scene (cached with it); ``method`` names an engine whose own checks
    are then made even where auto leaves them out (krylov's and refined's on a tiny scene).

    Examples
    --------
    >>> scene = Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[1], v0=[0])
    >>> facts = scene_facts(scene)
    >>> facts.n, facts.rational, facts.classical, facts.krylov, facts.pole_bound
    (1, True, None, None, None)
    >>> asked = scene_facts(scene, "classical")   # asked where an engine needs them
    >>> asked.classical, round(asked.pole_bound, 6)
    (True, 3.0)
    >>> scene_facts(Scene.from_matrices(M=[[1]], K=[["k"]], x0=[1], v0=[0],
    ...                                 parameters=["k"])).symbolic
    True
    """
    table = scene_cache(scene)
    if "facts" not in table:
        table["facts"] = _facts(scene)
    facts: SceneFacts = table["facts"]
    if method == "krylov" and facts.krylov is None:
        facts = table["facts"] = replace(facts, krylov=krylov_refusal(scene) is None)
    if method in _DAMPING_METHODS and facts.classical is None:
        rayleigh, classical = _damping_class(scene)
        stiffness, poles, decay = _bounds(scene) if facts.diagonal_mass else (None, None, None)
        facts = table["facts"] = replace(facts, rayleigh=rayleigh, classical=classical,
                                         stiffness_bound=stiffness, pole_bound=poles,
                                         mean_decay=decay)
    if method == "refined" and facts.quote("refined") is None and facts.classical:
        facts = table["facts"] = replace(facts, quotes=facts.quotes + (_refined_quote(scene),))
    if method not in _EXACT_METHODS and _screened(facts):
        facts = _with_exact_quote(scene, facts, table)
    return facts


#: Methods whose engine is the exact route: it screens the scene itself when built (and
#: raises its own InversionError), so their facts do not quote its screen.
_EXACT_METHODS = frozenset({"exact", "mp"})


def _screened(facts: SceneFacts) -> bool:
    """Whether the planner asks the exact route's screen up front: a forced numeric scene
    with a first-order form below Limits.exo_min_coordinates, where the exact route is
    preferred (closed forms) and the exo engine serves only where exact refuses; and a
    free numeric scene with irrational entries (entries mixing many of them cost the
    exact route minutes: an exo piece's joined scene with √2, √5, ∛2 and e)."""
    if facts.symbolic or facts.sampled:
        return False
    if not facts.forced:
        return not facts.rational
    return facts.first_order and facts.n < limits().exo_min_coordinates


def _with_exact_quote(scene: Scene, facts: SceneFacts, table: dict) -> SceneFacts:
    """``facts`` with the exact route's screen as a quote
    (:func:`~laplace_springs.exact.screening.exact_refusal`: milliseconds, kept with the
    scene and the limits in force; the exact engine's build reads the same result): the
    planner declines exact and mp with its refusal, and the exo engine serves instead. Its
    costs are not quoted (the exact engine's own model stays)."""
    quote = Quote("exact", exact_refusal(scene), 0.0, 0.0)  # kept per scene and limits
    found = table.get("exact_quote")
    # one quoted object per base facts and screen (plans are memoised by the facts)
    if found is None or found[0] is not facts or found[1] != quote:
        found = table["exact_quote"] = (facts, quote,
                                        replace(facts, quotes=facts.quotes + (quote,)))
    quoted: SceneFacts = found[2]
    return quoted


def _facts(scene: Scene) -> SceneFacts:
    quick = _tiny_facts(scene)
    return quick if quick is not None else _general_facts(scene)


def _tiny_facts(scene: Scene) -> SceneFacts | None:
    """The facts of an unforced scene the tiny engine takes, from its exact reading alone
    (None for any other scene): what :func:`_general_facts` finds for it (rational, no
    symbols, an invertible M, so a first-order form and no massless node; the damping
    class and the krylov checks not asked) without reading the scene again, which is a
    fifth of a tiny scene's whole solve."""
    data = tiny_scene(scene)
    if data is None:
        return None
    M = data.M
    return SceneFacts(n=data.n, symbolic=False, forced=False, rational=True, first_order=True,
                      classical=None, rayleigh=None, krylov=None,
                      nnz=len(M) + len(data.C) + len(data.K),
                      diagonal_mass=len(M) == data.n and all(i == j for i, j in M),
                      quotes=(_tiny_quote(scene),))


def _general_facts(scene: Scene) -> SceneFacts:
    exact = {name: rational_entries(scene, name) for name in ("M", "C", "K", "x0", "v0")}
    rational = all(entries is not None for entries in exact.values())
    sampled = scene.sampled is not None
    # rational matrices have no symbols (read from their domain: no SymPy walk of every entry)
    symbolic = not (rational and scene.forcing is None and not sampled) and bool(scene.free_symbols)
    forced = scene.is_forced or sampled
    first_order = not symbolic and has_first_order_form(scene)
    unforced = first_order and not forced
    # the refined engine (long horizons) is asked beyond the tiny engine's sizes only: its
    # quote costs 90 us, more than the rest of a tiny scene's facts, and the tiny,
    # certified and exact engines serve every horizon below
    tiny = unforced and scene.n <= limits().tiny_max_coordinates
    tiny_quote = _tiny_quote(scene) if tiny else None
    rayleigh: bool | None
    classical: bool | None
    if tiny_quote is not None and tiny_quote.refusal is None:
        rayleigh = classical = None  # not asked
    else:
        rayleigh, classical = _damping_class(scene) if unforced else (False, False)
    M = exact["M"] if exact["M"] is not None else scene_entries(scene, "M")
    diagonal = all(i == j for i, j in M) and len(M) == scene.n and not massless_nodes(scene)
    nnz = 0   # from the rational dicts when read (SymPy's todok: 0.15 s at 4,000 masses)
    for name in ("M", "C", "K"):
        read = exact[name]
        nnz += len(read if read is not None else scene_entries(scene, name))
    # the spectral bounds are read by the symmetric and krylov engines' models: asked with
    # the damping class
    stiffness, poles, decay = _bounds(scene) if rational and diagonal and classical is not None \
        else (None, None, None)
    quotes = ((_refined_quote(scene),) if classical and not symbolic and not tiny else ()) + (
        (tiny_quote,) if tiny_quote is not None else ())
    return SceneFacts(n=scene.n, symbolic=symbolic, forced=forced,
                      rational=not symbolic and rational, first_order=first_order,
                      classical=classical, rayleigh=rayleigh,
                      krylov=_krylov_serves(scene) if unforced and rational else False,
                      nnz=nnz, diagonal_mass=diagonal, stiffness_bound=stiffness,
                      pole_bound=poles, mean_decay=decay, sampled=sampled, quotes=quotes,
                      periodic=scene.forcing is not None and scene.forcing.has(Periodic))


#: Methods whose engines read the damping class (asked even where the tiny engine serves).
_DAMPING_METHODS = frozenset({"classical", "chebyshev", "modal", "numeric", "refined"})


def _damping_class(scene: Scene) -> tuple[bool, bool]:
    """Whether an unforced scene's damping is Rayleigh's and classical, exactly: O(nnz), but
    about 40 µs on a pair, a tenth of its whole solve, so a scene the tiny engine takes
    leaves it unasked (the tiny, certified and exact engines serve it): (rayleigh, classical)."""
    rayleigh = rayleigh_coefficients(scene) is not None  # implies classical
    return rayleigh, rayleigh or classical_damping(scene)


def _krylov_serves(scene: Scene) -> bool | None:
    """Whether the krylov engine takes the scene; None (not asked) up to
    Limits.tiny_max_coordinates: its checks (a verified spectral bound from sparse power
    steps) cost milliseconds, more than a tiny scene's whole solve, and the tiny,
    certified and exact engines serve every scene of that size."""
    if scene.n <= limits().tiny_max_coordinates:
        return None
    return krylov_refusal(scene) is None


def _tiny_quote(scene: Scene) -> Quote:
    why = tiny_refusal(scene, t_max=0.0, count=0, order=0)
    build = tiny_cost(scene, t_max=0.0, count=0, order=0)
    return Quote("tiny", why, build, tiny_cost(scene, t_max=0.0, count=1, order=0) - build)


def _refined_quote(scene: Scene) -> Quote:
    why = refined_refusal(scene, t_max=0.0, count=0, order=0)
    if why is not None:
        return Quote("refined", why, 0.0, 0.0)
    build = refined_cost(scene, t_max=0.0, count=0, order=0)
    return Quote("refined", None, build, refined_cost(scene, t_max=0.0, count=1, order=0) - build)


def _bounds(scene: Scene) -> tuple[float | None, float | None, float | None]:
    """Verified bounds on λ_max(M⁻¹K) and on |λ| for a diagonal positive rational M, and
    the poles' mean decay rate tr(M⁻¹C)/2n.

    With D = M^{1/2}, the poles are those of the first-order operator in the energy
    norm, whose norm is at most √ρ(D⁻¹|K|D⁻¹) + ρ(D⁻¹|C|D⁻¹) (each spectral radius below a
    Gershgorin row sum); the row sums are of non-negative terms, so a relative margin of
    1e-9 covers their float64 rounding for up to 10⁶ terms per row.
    """
    n = scene.n
    M, C, K = (entries_of(scene, name) for name in ("M", "C", "K"))
    assert M is not None and C is not None and K is not None
    if M.rows.size == 0 or float(M.value.min()) <= 0:
        return None, None, None
    root = np.zeros(n)
    root[M.rows] = np.sqrt(M.value)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        rows_K = np.bincount(K.rows, np.abs(K.value) / (root[K.rows] * root[K.cols]), minlength=n)
        rows_C = np.bincount(C.rows, np.abs(C.value) / (root[C.rows] * root[C.cols]), minlength=n)
    stiffness = float(rows_K.max(initial=0.0)) * _MARGIN**3
    damping = float(rows_C.max(initial=0.0)) * _MARGIN**3
    if not (math.isfinite(stiffness) and math.isfinite(damping)):
        return None, None, None
    on_diagonal = C.rows == C.cols
    decay = float((C.value[on_diagonal] / np.square(root[C.rows[on_diagonal]])).sum()) / (2 * n)
    return stiffness, (math.sqrt(stiffness) + damping) * _MARGIN, decay
