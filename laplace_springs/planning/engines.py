"""The engines the planner chooses from: what each can serve and what it costs.

Each engine is described by one :class:`Engine` entry: its name (the fixed vocabulary of
``Solution.method`` and of evaluation reports), its tier, a refusal test and a cost model.
The refusal and the cost read only :class:`~laplace_springs.planning.facts.SceneFacts` and
a :class:`~laplace_springs.planning.request.Request`: they are pure and cheap, no
decomposition is made to decide. The engines themselves (the numbers) live in
:mod:`laplace_springs.numeric` and are built by :mod:`laplace_springs.routes.engines`.

Tiers
-----
0
    float64 engines with a running error bound: ``tiny``, ``certified``, ``classical``,
    ``chebyshev``, ``modal``, ``krylov``, ``exact``.
1
    float64 values from refined data (double-double phases and eigenpairs): ``refined``.
2
    arbitrary precision: ``ball`` (certified poles in ball arithmetic) and ``mp`` (the
    exact terms in mpmath). Only these serve ``dps=``.

Cost models
-----------
Seconds on one core of the development machine (2 cores, OpenBLAS), fitted to the
measurements quoted in :mod:`laplace_springs.limits`; they rank engines, they are not
promises. ``build`` is paid once per solution, ``run`` per request.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from ..limits import limits
from ..numeric.classical import NOT_CLASSICAL
from .facts import SceneFacts
from .request import Request

__all__ = ["Cost", "Refusal", "Engine", "ENGINES", "ENGINE_NAMES", "engine"]

_DOUBLE = 8.0  # bytes per float64


@dataclass(frozen=True)
class Cost:
    """Estimated seconds (to build the engine's data, and to run the request) and peak
    memory in bytes."""

    build: float
    run: float
    memory: float = 0.0

    @property
    def seconds(self) -> float:
        return self.build + self.run


@dataclass(frozen=True)
class Refusal:
    """Why an engine declines a request: a sentence, and the limit when it is one."""

    engine: str
    reason: str
    limit: str | None = None

    def __str__(self) -> str:
        return f"{self.engine}: {self.reason}"

    @classmethod
    def from_text(cls, engine: str, reason: str) -> Refusal:
        """The refusal of ``reason``, its limit the first ``Limits.<name>`` the text names.

        >>> Refusal.from_text("tiny", "coordinates 5 > Limits.tiny_max_coordinates = 4").limit
        'tiny_max_coordinates'
        """
        if "Limits." not in reason:
            return cls(engine, reason)
        return cls(engine, reason, reason.split("Limits.", 1)[1].split(maxsplit=1)[0].strip(".,;)"))


@dataclass(frozen=True)
class Engine:
    """One engine of the planner's table.

    Attributes
    ----------
    name : str
        Its name in ``Solution.method`` and in reports.
    tier : int
        0, 1 or 2 (see the module notes).
    summary : str
        What it does, for reasons and plans.
    refusal : callable
        ``(facts, request) -> str | None``: why it cannot serve, or None.
    cost : callable
        ``(facts, request) -> Cost``.
    horizon : callable
        ``(facts, request) -> float``: the largest time it serves for this request (inf
        when any).
    expectation : callable
        ``(facts, request) -> str | None``: why its bound is expected to miss the target
        (it still serves; "auto" prefers engines expected to meet it), or None.
    precision : float
        The relative bound it typically reaches (a time that escalates goes only to
        engines that reach further).
    defers_to : str, optional
        An engine preferred where both serve: while it serves the request (and this
        engine is not asked for by name), this one declines with ``deferral``'s sentence.
    deferral : callable
        ``(facts, request) -> str | None``: why the engine defers to ``defers_to`` for
        this request, or None (it serves beside it).
    """

    name: str
    tier: int
    summary: str
    refusal: Callable[[SceneFacts, Request], str | None]
    cost: Callable[[SceneFacts, Request], Cost]
    horizon: Callable[[SceneFacts, Request], float] = lambda facts, request: math.inf
    expectation: Callable[[SceneFacts, Request], str | None] = lambda facts, request: None
    precision: float = 1e-14
    defers_to: str | None = None
    deferral: Callable[[SceneFacts, Request], str | None] = lambda facts, request: None

    def refuses(self, facts: SceneFacts, request: Request) -> Refusal | None:
        """A :class:`Refusal`, or None when the engine can serve the request."""
        if request.dps is not None and self.tier < 2:
            return Refusal(self.name, "evaluates in float64 only (dps= needs ball or mp)")
        why = self.refusal(facts, request)
        if why is None:
            return None
        return Refusal.from_text(self.name, why)

    def defers(self, facts: SceneFacts, request: Request) -> Refusal | None:
        """Its :class:`Refusal` in favour of ``defers_to`` (the caller knows that engine
        serves the request), or None."""
        why = None if self.defers_to is None else self.deferral(facts, request)
        return None if why is None else Refusal.from_text(self.name, why)


# ----------------------------------------------------------------------------- refusals


def _numeric(facts: SceneFacts) -> str | None:
    if facts.symbolic:
        return "the scene has symbols"
    if facts.forced:
        return "the scene is forced"
    if not facts.first_order:
        return "the scene has no first-order form (massless nodes not held by dashpots)"
    return None


def _size(facts: SceneFacts, field: str, what: str, order: bool = False) -> str | None:
    value = getattr(limits(), field)
    size = 2 * facts.n if order else facts.n
    if size > value:
        return f"{what} {size:,} > Limits.{field} = {value:,}"
    return None


def _quoted_refusal(name: str) -> Callable[[SceneFacts, Request], str | None]:
    """The refusal an engine module quoted for the scene (numeric/<name>.py decides)."""
    def refusal(facts: SceneFacts, request: Request) -> str | None:
        if why := _numeric(facts):
            return why
        quote = facts.quote(name)
        if quote is None:
            return f"the {name} engine has not quoted this scene"
        return quote.refusal
    return refusal


def _quoted_cost(name: str) -> Callable[[SceneFacts, Request], Cost]:
    """The cost model an engine module quoted: its build, then a cost per time."""
    def cost(facts: SceneFacts, request: Request) -> Cost:
        quote = facts.quote(name)
        build, per_time = (quote.build, quote.per_time) if quote else (math.inf, 0.0)
        return Cost(build, request.count * per_time * (1 + request.order / 3))
    return cost


def _certified_refusal(facts: SceneFacts, request: Request) -> str | None:
    return (_numeric(facts) or (None if facts.rational else "needs rational entries")
            or _size(facts, "certified_max_order", "first-order size 2n =", order=True))


def _not_asked() -> str:
    return ("its damping class is not asked on scenes the tiny engine takes "
            f"(at most Limits.tiny_max_coordinates = {limits().tiny_max_coordinates} "
            "coordinates); method='classical', 'chebyshev' or 'refined' asks it")


def _symmetric_refusal(facts: SceneFacts, request: Request) -> str | None:
    if facts.classical is None:
        return _numeric(facts) or _not_asked()
    return (_numeric(facts)
            or (None if facts.classical else NOT_CLASSICAL)
            or _size(facts, "classical_max_coordinates", "coordinates"))


def _classical_expectation(facts: SceneFacts, request: Request) -> str | None:
    """The eigen route's bound grows like t·‖residual‖/ω_min: about 50·t·ρ·n·u of the
    solution's size (measured: one mass ω = 2, 2.9e-15·t; the seed's pair 3.3e-14·t;
    Rayleigh chains, times on [0, 50]: 20 masses 8.5e-14, 100 masses 1.2e-9)."""
    if facts.pole_bound is None:
        return None
    expected = 50 * request.t_max * facts.pole_bound * facts.n * 2.0**-53
    if expected <= request.target:
        return None
    return (f"its bound is expected to miss the target at t = {request.t_max:g} "
            f"(50·t·ρ·n·u = {expected:.1e} > {request.target:g})")


def _chebyshev_refusal(facts: SceneFacts, request: Request) -> str | None:
    if why := _numeric(facts):
        return why
    if facts.rayleigh is None:
        return _not_asked()
    if not facts.rayleigh:
        return "the damping is not Rayleigh's (C = aK + bM with a diagonal M)"
    if facts.stiffness_bound is None:
        return "no verified bound on the spectrum of M⁻¹K (needs rational entries)"
    return _size(facts, "chebyshev_max_coordinates", "coordinates")


def _modal_refusal(facts: SceneFacts, request: Request) -> str | None:
    return _numeric(facts) or _size(facts, "general_modal_max_coordinates", "coordinates")


def _krylov_refusal(facts: SceneFacts, request: Request) -> str | None:
    if why := _numeric(facts):
        return why
    if facts.krylov is None:
        return (f"scenes of at most Limits.tiny_max_coordinates = {limits().tiny_max_coordinates}"
                " coordinates are left to the tiny, certified and exact engines")
    if not facts.krylov or facts.pole_bound is None:
        return ("needs rational entries, a diagonal positive M, and K ⪰ 0, C + Cᵀ ⪰ 0 proved "
                "by diagonal dominance")
    return None


def _modal_expectation(facts: SceneFacts, request: Request) -> str | None:
    """The general modal engine's bound (sampled on perturbed decompositions) is about
    (2e-14 + 2e-15·n) of the solution's size, whatever t, once the motion has decayed
    (measured on damped chains of 2 to 50 masses, t = 1, 10, 100: 1.4e-14 at 2 masses, 1e-13
    to 1.4e-13 at 50). While a mode is alive it grows like its eigenvalue's error times t,
    about u·ρ·n·t (lightly damped chains and meshes of 5 to 30 masses, one or a few light
    dashpots: 1e-13 to 3.5e-12 at t = 10 to 100, up to four times that estimate; the
    executor then recomputes most times with another engine). The slowest mode decays no
    faster than the poles' mean rate ᾱ = tr(M⁻¹C)/2n, so the growth is counted up to t
    where ᾱ·t < 5 (heavily damped networks, ᾱ·t ≥ 6 at t = 10: 3e-15 to 1.3e-13, counted
    without it)."""
    expected = 2e-14 + 2e-15 * facts.n
    if facts.pole_bound is not None and facts.mean_decay is not None \
            and facts.mean_decay * request.t_max < 5:
        expected += 2.0**-53 * facts.pole_bound * facts.n * request.t_max
    if expected <= request.target:
        return None
    return f"its bound is expected to miss the target ({expected:.1e} > {request.target:g})"


def _screen(facts: SceneFacts) -> str | None:
    """The exact route's own refusal of a small forced scene, where the facts quote its
    screen (:func:`~laplace_springs.planning.facts.scene_facts`), else None."""
    quote = facts.quote("exact")
    return None if quote is None else quote.refusal


def _exact_refusal(facts: SceneFacts, request: Request) -> str | None:
    return _size(facts, "max_exact_coordinates", "coordinates") or _screen(facts)


def _exo_refusal(facts: SceneFacts, request: Request) -> str | None:
    """Formula and periodic forces on numeric scenes with a first-order form."""
    if not facts.forced:
        return "the scene is not forced (the free-motion engines serve it)"
    if facts.symbolic:
        return "the scene has symbols"
    if facts.sampled:
        return "sampled forces take the sampled route"
    if not facts.first_order:
        return "the scene has no first-order form (massless nodes not held by dashpots)"
    return None


def _exo_deferral(facts: SceneFacts, request: Request) -> str | None:
    """Below Limits.exo_min_coordinates exact partial fractions give closed forms in
    seconds: the exo engine serves only the scenes the exact route refuses (its screen,
    quoted by the facts, or its build: entries of very different sizes, a factor with
    irrational coefficients)."""
    least = limits().exo_min_coordinates
    if facts.n < least:
        return (f"coordinates {facts.n} < Limits.exo_min_coordinates = {least}: exact partial "
                "fractions serve it with a closed form")
    return None


def _mp_refusal(facts: SceneFacts, request: Request) -> str | None:
    return _size(facts, "exact_fallback_max_coordinates", "coordinates") or _screen(facts)


# ----------------------------------------------------------------------------- costs


def _chebyshev_degree(facts: SceneFacts, t: float) -> float:
    """Chebyshev degree N ≈ t·√ν/2 + 40 for the largest time t (ν ≥ λ_max(M⁻¹K))."""
    return t * math.sqrt(facts.stiffness_bound or 0.0) / 2 + 40


def _chebyshev_horizon(facts: SceneFacts, request: Request) -> float:
    """The largest t whose 2·n·(N+1) vectors fit in Limits.chebyshev_max_vector_floats."""
    if not facts.stiffness_bound:
        return math.inf
    degree = limits().chebyshev_max_vector_floats / (2 * max(facts.n, 1)) - 41
    return max(degree - 40, 0.0) * 2 / math.sqrt(facts.stiffness_bound)


def _krylov_steps(facts: SceneFacts, t: float) -> float:
    return t * (facts.pole_bound or 0.0) / limits().krylov_step_norm


def _krylov_horizon(facts: SceneFacts, request: Request) -> float:
    if not facts.pole_bound:
        return math.inf
    return limits().krylov_max_steps * limits().krylov_step_norm / facts.pole_bound


def _run(request: Request, per_value: float, n: int) -> float:
    return request.count * max(n, 1) * per_value


def _certified_cost(facts: SceneFacts, request: Request) -> Cost:
    """Roots and residues, then the pole sums' Newton data on first use (measured: 8-mass
    chain 3.5 ms + 34 ms; 50-mass chain 0.1 s + 1.9 s)."""
    degree = 2 * facts.n
    return Cost(1.5e-3 + 1.5e-4 * degree**2 + 1e-6 * degree**3,
                _run(request, 2e-8 * degree, facts.n))


def _classical_cost(facts: SceneFacts, request: Request) -> Cost:
    n = facts.n
    build = 1e-4 + (2e-8 * n * n if facts.diagonal_mass else 1e-8 * n**3)
    return Cost(build, _run(request, 4e-9 * n, n), _DOUBLE * n * n)


def _chebyshev_cost(facts: SceneFacts, request: Request) -> Cost:
    degree = _chebyshev_degree(facts, min(request.t_max, _chebyshev_horizon(facts, request)))
    # a recurrence step costs at least its Python and sparse-call overhead, about 9 µs (6
    # masses at t = 1e5: N = 412,432 in 3.6 s); below ~700 nonzeros that dominates
    build = 1e-3 + degree * max(1.2e-8 * (facts.nnz + facts.n), 9e-6)
    run = request.count * degree * (5e-9 * facts.n + 2e-7)
    return Cost(build, run, 2 * _DOUBLE * facts.n * (degree + 1))


def _modal_cost(facts: SceneFacts, request: Request) -> Cost:
    order = 2 * facts.n  # four decompositions of the 2n x 2n matrix: 200 coordinates 1 s
    return Cost(2e-3 + 1.5e-8 * order**3, _run(request, 1e-8 * order, facts.n),
                4 * 16 * order * order)


def _krylov_cost(facts: SceneFacts, request: Request) -> Cost:
    """Steps of θ = Limits.krylov_step_norm, each about 60 sparse products (a third of them
    double-double): 0.3 ms + 60·(2.5 ns per nonzero + 20 ns per coordinate) (measured,
    θ = 4 to 5, one core, loaded machine: chains of 1,000 and 4,000 masses 1.8–3.4 and
    8.6 ms per step, a 4,000-mass mesh 10 ms; a 2,000-mass Rayleigh chain 0.32–0.42 s in
    all against the Chebyshev engine's 0.23–0.30 s); the build reads the entries and checks
    them exactly (5 µs per nonzero: 4,000-mass mesh 0.13 s)."""
    steps = _krylov_steps(facts, min(request.t_max, _krylov_horizon(facts, request))) + 1
    return Cost(1e-3 + 5e-6 * facts.nnz, steps * (3e-4 + 60 * (2.5e-9 * facts.nnz + 2e-8 * facts.n))
                + _run(request, 4e-8, facts.n), _DOUBLE * 8 * (facts.nnz + facts.n))


def _krylov_expectation(facts: SceneFacts, request: Request) -> str | None:
    """Its bound is the values' own float64 rounding, up to about 5e-14 of the scale at
    θ = 5 (1,000-mass chain 2e-14, 10,000-mass mesh 4.4e-14 at t = 50), plus what every
    step adds (taken as 4e-17 per step, the previous march's measured rate)."""
    expected = 5e-14 + 4e-17 * _krylov_steps(facts, request.t_max)
    if expected <= request.target:
        return None
    return f"its bound is expected to miss the target ({expected:.1e} > {request.target:g})"


def _refined_refusal(facts: SceneFacts, request: Request) -> str | None:
    """The refined engine's own rule (numeric/refined.py), read from the facts' quote; a
    derivative order beyond Limits.refined_max_order."""
    if why := _symmetric_refusal(facts, request):
        return why
    if why := _quoted_refusal("refined")(facts, request):
        return why
    most = limits().refined_max_order
    if request.order > most:
        return f"derivative order {request.order} > Limits.refined_max_order = {most}"
    return None


def _refined_cost(facts: SceneFacts, request: Request) -> Cost:
    """The engine's own model (numeric/refined.refined_cost): decomposition and refinement,
    then a cost per time that does not depend on t; a third more per derivative order."""
    quoted = _quoted_cost("refined")(facts, request)
    return Cost(quoted.build, quoted.run, 3 * _DOUBLE * facts.n * facts.n)


def _exact_cost(facts: SceneFacts, request: Request) -> Cost:
    n = facts.n
    if n <= 2:
        build = 0.02
    elif facts.rational and not facts.forced:
        # free rational scenes, named roots (damped chains of unequal masses, solve + x +
        # five values): 8 coordinates 0.2-0.4 s, 12 0.8-1.1 s, 16 1.0-1.3 s, 40 4.3 s
        build = 0.1 * n
    else:  # the written-out form: damped chains 8 coordinates 2.9 s, 12 13 s
        build = 2.9 * (n / 8) ** 4
    # per time and coordinate: 1.6-2.2 us unforced or with cos(t), 8-10 us with a square
    # wave (one or two masses, 10^5 times)
    return Cost(build, _run(request, 1e-5 if facts.periodic else 2e-6, n))


def _exo_cost(facts: SceneFacts, request: Request) -> Cost:
    """The augmented scene (a few more first-order states per input) decomposed by the
    general modal engine, then one evaluation per switching time (and per period of a
    periodic force, about 50 for 100 times up to t = 100)."""
    order = 2 * facts.n + 4
    repeats = 50 if facts.periodic else 1
    return Cost(2e-3 + 1.5e-8 * order**3, repeats * (2e-4 + _run(request, 1e-8 * order, facts.n)))


def _mp_cost(facts: SceneFacts, request: Request) -> Cost:
    """The exact terms in mpmath: about 2 ms a value up to a few hundred digits, growing
    like digits^1.66 beyond (one mass: 1.6e-4 s a value at 1,000 digits, 6e-3 s at 10,000)."""
    exact = _exact_cost(facts, request)
    digits = request.dps or limits().escalation_digits
    return Cost(exact.build, _run(request, max(2e-3, 6e-3 * (digits / 10_000) ** 1.66), facts.n))


def _ball_cost(facts: SceneFacts, request: Request) -> Cost:
    """Certified poles in ball arithmetic: one mass 9e-5 s a value at 30 digits, 2e-4 at
    1,000, 2.1e-3 at 5,000 (about digits^1.5 beyond 1,000)."""
    certified = _certified_cost(facts, request)
    digits = request.dps or limits().escalation_digits
    growth = max(1.0, (digits / 1000) ** 1.5)
    return Cost(certified.build, _run(request, 2e-4 * facts.n * growth, facts.n))


#: The planner's table. Adding an engine is one module in numeric/, one builder in
#: routes/engines.py and one entry here.
ENGINES: tuple[Engine, ...] = (
    Engine("tiny", 0, "closed-form poles of a small scene in float64 with a residual bound",
           _quoted_refusal("tiny"), _quoted_cost("tiny"), precision=2e-14),
    Engine("certified", 0, "poles and residues certified by python-flint, float64 pole sums",
           _certified_refusal, _certified_cost, precision=2e-15),
    Engine("classical", 0, "real modes of the symmetric eigenproblem of size n",
           _symmetric_refusal, _classical_cost, expectation=_classical_expectation,
           precision=5e-14),
    Engine("chebyshev", 0, "Chebyshev expansion in M⁻¹K with sparse products",
           _chebyshev_refusal, _chebyshev_cost, _chebyshev_horizon, precision=3e-14),
    Engine("modal", 0, "conditioned eigen-decomposition of the 2n x 2n first-order matrix",
           _modal_refusal, _modal_cost, expectation=_modal_expectation, precision=8e-14),
    Engine("krylov", 0, "Taylor steps of the sparse first-order system (leading terms in "
           "double-double), bounded through the energy", _krylov_refusal, _krylov_cost, _krylov_horizon,
           expectation=_krylov_expectation, precision=2e-14),
    Engine("exact", 0, "exact partial fractions, float64 pole sums", _exact_refusal,
           _exact_cost, precision=2e-15),
    Engine("exo", 0, "the inputs' own dynamics joined to the scene, solved by the free-motion "
           "engines", _exo_refusal, _exo_cost, precision=1e-13, defers_to="exact",
           deferral=_exo_deferral),
    Engine("refined", 1, "eigenpairs refined in double-double, phases ωt in double-double",
           _refined_refusal, _refined_cost, precision=1e-15),
    Engine("ball", 2, "certified poles evaluated in ball arithmetic", _certified_refusal,
           _ball_cost, precision=0.0),
    Engine("mp", 2, "the exact terms evaluated in mpmath", _mp_refusal, _mp_cost,
           precision=0.0),
)

#: The engine names: the vocabulary of ``Solution.method`` and of evaluation reports.
ENGINE_NAMES: tuple[str, ...] = tuple(e.name for e in ENGINES)


def engine(name: str) -> Engine:
    """The table's entry for ``name``.

    >>> engine("krylov").tier
    0
    """
    for entry in ENGINES:
        if entry.name == name:
            return entry
    raise KeyError(name)
