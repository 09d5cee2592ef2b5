"""The planner: one pure function from a scene's facts and a request to a :class:`Plan`.

:func:`plan` takes the cheapest float64 engine that serves the request (its primary), the
engines that serve the times beyond the primary's horizon, and the escalation chain for
the times whose bound misses the target: the engines that reach a tighter bound and are
expected to meet the target, cheapest first (by their costs for the default request, so that
a time's engine does not depend on the other times of a call), then the others. A time beyond
the default request's last time escalates through the same engines in the order of their
costs for its own dyadic band (:meth:`Plan.chain_for`): a function of that time alone. ``solve`` and ``Solution.evaluate`` only
execute plans (:mod:`laplace_springs.planning.execute`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..limits import limits
from .engines import ENGINE_NAMES, ENGINES, Cost, Engine, Refusal, engine
from .facts import SceneFacts
from .request import DEFAULT_REQUEST, Request

__all__ = ["Plan", "plan", "METHODS", "FAMILIES"]

#: Requested methods that name a family of engines rather than one engine: "modal" (and
#: its former name "numeric") is the float64 eigen family, whose member the structure
#: decides (symmetric eigenproblem, Chebyshev expansion, or the general 2n x 2n one).
FAMILIES: dict[str, tuple[str, ...]] = {
    "modal": ("classical", "chebyshev", "modal"),
    "numeric": ("classical", "chebyshev", "modal"),
    # the arbitrary-precision engines have no float64 values of their own: asked for, their
    # host serves (whose escalation and dps= they are)
    "ball": ("certified",),
    "mp": ("exact",),
}
#: What ``solve(method=...)`` accepts.
METHODS: tuple[str, ...] = tuple(dict.fromkeys(("auto", *ENGINE_NAMES, *FAMILIES)))
#: An escalation engine that is itself expected to miss the target is kept in the chain
#: only when it costs at most this many times the primary (a 100-mass non-classical chain
#: at t = 1e4: krylov would take 53 s to reach 3.8e-13 where the general modal engine gives
#: about 2e-13 in 0.12 s).
_ESCALATION_BUDGET = 20.0



@dataclass(frozen=True)
class Plan:
    """Which engines serve a request, in which order, and why.

    Attributes
    ----------
    request : Request
    method : str
        What was asked ("auto", an engine, or a family).
    chain : tuple of str
        The engines in the order they are tried: the primary first, then the engines for
        times beyond its horizon, then the escalation for times whose bound misses the
        target. Empty when no engine serves.
    horizons : dict
        engine -> the largest time it serves for this request.
    costs : dict
        engine -> estimated :class:`~laplace_springs.planning.engines.Cost`.
    refusals : tuple of Refusal
        The engines that declined, and why.
    reason : str
        One sentence: the primary engine and why it was chosen.
    """

    request: Request
    method: str
    chain: tuple[str, ...]
    horizons: dict[str, float] = field(default_factory=dict)
    costs: dict[str, Cost] = field(default_factory=dict)
    refusals: tuple[Refusal, ...] = ()
    reason: str = ""
    #: band exponent e -> the chain for times in (2^(e-1), 2^e] beyond the default horizon
    #: (None: every time follows ``chain``)
    retimed: Callable[[int], tuple[str, ...]] | None = field(default=None, compare=False,
                                                               repr=False)

    def chain_for(self, t: float) -> tuple[str, ...]:
        """The chain that serves time ``t``: :attr:`chain` up to the default request's last
        time; beyond it the same engines, with the escalation ordered by their costs for a
        request up to t's dyadic band (so an engine whose cost grows with t, such as a
        stepping one, moves behind one that does not). A function of t alone.

        >>> from laplace_springs.planning.facts import Quote, SceneFacts
        >>> facts = SceneFacts(n=4, symbolic=False, forced=False, rational=True,
        ...                    first_order=True, classical=True, rayleigh=False, krylov=True,
        ...                    nnz=16, diagonal_mass=True, stiffness_bound=4.0, pole_bound=2.0)
        >>> made = plan(facts, Request(count=1, t_max=1e6), method="modal")
        >>> made.chain_for(1.0) == made.chain
        True
        """
        if self.retimed is None or not t > DEFAULT_REQUEST.t_max:
            return self.chain
        return self.retimed(min(math.frexp(t)[1], 1023))

    def groups(self, t: np.ndarray, last: float) -> list[tuple[np.ndarray | None, tuple[str, ...]]]:
        """The times ``t`` (the largest ``last``) grouped by :meth:`chain_for`: (mask of the
        group's columns, its chain); one group ``(None, chain)`` when every time follows
        :attr:`chain`."""
        if self.retimed is None or not last > DEFAULT_REQUEST.t_max:
            return [(None, self.chain)]
        late = t > DEFAULT_REQUEST.t_max
        bands = np.where(late, np.minimum(np.frexp(t)[1], 1023), 0)
        chains: dict[tuple[str, ...], list[int]] = {self.chain: [0]}
        for band in np.unique(bands[late]).tolist():
            chains.setdefault(self.retimed(band), []).append(band)
        if len(chains) == 1:
            return [(None, self.chain)]
        return [(np.isin(bands, members), chain) for chain, members in chains.items()]

    @property
    def primary(self) -> str | None:
        """The engine tried first (None when no engine serves the request)."""
        return self.chain[0] if self.chain else None

    @property
    def seconds(self) -> float:
        """Estimated seconds of the primary engine."""
        return self.costs[self.chain[0]].seconds if self.chain else 0.0

    def __str__(self) -> str:
        lines = [f"plan for {self.request} (method={self.method!r}): {self.reason}"]
        for name in self.chain:
            cost, horizon = self.costs[name], self.horizons.get(name, math.inf)
            until = "" if math.isinf(horizon) else f", times up to {horizon:.3g}"
            lines.append(f"  {name:10s} ~{cost.seconds:.2g} s{until}: {_summary(name)}")
        last = self.chain_for(self.request.t_max) if self.chain else self.chain
        if last != self.chain:
            lines.append(f"  times near t = {self.request.t_max:g} escalate in the order of "
                         f"their own band: {', '.join(last)}")
        lines += [f"  declined   {refusal}" for refusal in self.refusals]
        return "\n".join(lines)


def _summary(name: str) -> str:
    """What engine ``name`` does: the table's summary, or for a sampled scene's own engine
    (``"exact+sampled"``) its base's and the sampled responses.

    >>> _summary("exact+sampled")
    'exact (exact partial fractions, float64 pole sums) for the rest of the scene, plus the responses to its sampled forces'
    """
    base, plus, own = name.partition("+")
    if plus and own == "sampled":
        return f"{base} ({_summary(base)}) for the rest of the scene, plus the responses to its sampled forces"
    try:
        return engine(name).summary
    except KeyError:
        return "an engine of the solution's own"


def plan(facts: SceneFacts, request: Request, *, method: str = "auto",
         built: Iterable[str] = (), available: Iterable[str] | None = None) -> Plan:
    """The plan for ``request`` on a scene with ``facts``.

    The primary is the cheapest engine of the first tier that serves every time of the
    request and is not expected to miss the target (or the cheapest that serves, when
    none is expected to meet it); engines with a longer horizon follow for the times
    beyond it; then, for times whose bound misses the target, every engine that reaches a
    tighter bound than the primary and is expected to meet the target (cheapest for the
    default request first), then the
    others (a primary that misses badly is recovered by any engine that does better).

    Parameters
    ----------
    facts : SceneFacts
    request : Request
    method : str
        "auto", an engine name, or a family ("modal"): a named engine or family restricts
        the primary; escalation stays open.
    built : iterable of str
        Engines whose data a solution already holds (their build cost is not counted).
    available : iterable of str, optional
        The engines that can be built here (all by default).

    Examples
    --------
    >>> from laplace_springs.planning.facts import Quote, SceneFacts
    >>> facts = SceneFacts(n=200, symbolic=False, forced=False, rational=True, first_order=True,
    ...                    classical=True, rayleigh=True, krylov=True, nnz=800,
    ...                    diagonal_mass=True, stiffness_bound=4.0, pole_bound=2.0,
    ...                    quotes=(Quote("refined", None, 0.05, 2e-4),))
    >>> plan(facts, Request(count=10, t_max=50.0)).chain[:3]
    ('chebyshev', 'krylov', 'refined')
    >>> plan(facts, Request(count=2, t_max=1e6)).primary
    'refined'
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    names = frozenset(ENGINE_NAMES if available is None else available)
    key = (facts, request, method, frozenset(built), names)
    current = limits()
    found = _MEMO.get(key)
    if found is not None and found[0] is current:
        return found[1]
    made = _plan(facts, request, method, key[3], names)
    if len(_MEMO) >= _MEMO_SIZE:
        _MEMO.clear()  # one atomic step (sweeps plan from several threads)
    _MEMO[key] = (current, made)
    return made


#: Plans already made: (facts, request, method, built, available) -> (limits, plan). The
#: plan is a pure function of these and of the limits in force; a loop over scenes of the
#: same data (a notebook run again, a battery timing its cases) plans once.
_MEMO: dict[tuple[Any, ...], tuple[Any, Plan]] = {}
_MEMO_SIZE = 512


def _plan(facts: SceneFacts, request: Request, method: str, built: frozenset[str],
          names: frozenset[str]) -> Plan:
    facts = facts.knowing(built)
    serving, refusals = _serving(facts, request, method, names, built)
    costs = {e.name: _cost(e, facts, request, built) for e in serving}
    horizons = {e.name: e.horizon(facts, request) for e in serving}
    # a named engine or family restricts the float64 primary; digits come from tier 2
    wanted = FAMILIES.get(method, (method,)) if method != "auto" and request.dps is None else None
    # the escalation order is the scene's, not the request's (costs for the default
    # request): a time's engine then never depends on the other times of a call
    scene_order = _default_order(facts, built)
    order = {e.name: scene_order(e)[0] for e in serving}
    chain, head = _chain(serving, costs, horizons, facts, request, wanted, order,
                         lambda e: scene_order(e)[1])
    retimed = _Retimed(facts, built, chain, head) if len(chain) > head + 1 else None
    return Plan(request, method, chain, horizons, costs, tuple(refusals),
                _reason(chain, costs, method, facts, request, refusals), retimed)


def _serving(facts: SceneFacts, request: Request, method: str, names: frozenset[str],
             built: frozenset[str]) -> tuple[list[Engine], list[Refusal]]:
    """The engines of ``names`` that serve the request, and the refusals of the others. An
    engine that defers to another (``Engine.defers_to``) declines only where that one
    serves, and never when it is asked for by name or its data is built."""
    serving: list[Engine] = []
    refusals: list[Refusal] = []
    for entry in ENGINES:
        if entry.name not in names:
            continue
        refusal = entry.refuses(facts, request)
        if refusal is None:
            serving.append(entry)
        else:
            refusals.append(refusal)
    taken = {e.name for e in serving}
    deferring = [e for e in serving
                 if e.defers_to in taken and e.name != method and e.name not in built]
    for entry in deferring:
        if (refusal := entry.defers(facts, request)) is not None:
            serving.remove(entry)
            refusals.append(refusal)
    return serving, refusals


def _default_order(facts: SceneFacts, built: frozenset[str]
                   ) -> Callable[[Engine], tuple[float, bool]]:
    """engine -> (its seconds for the default request, whether it is expected to miss the
    target there): the escalation order of the scene, the same for every request, so
    worked out once per scene's facts and built engines (and the limits in force)."""
    key = (facts, built)
    current = limits()
    found = _ORDERS.get(key)
    if found is None or found[0] is not current:
        if len(_ORDERS) >= _MEMO_SIZE:
            _ORDERS.clear()
        found = _ORDERS[key] = (current, {})
    table = found[1]

    def of(entry: Engine) -> tuple[float, bool]:
        known = table.get(entry.name)
        if known is None:
            known = table[entry.name] = (
                _cost(entry, facts, DEFAULT_REQUEST, built).seconds,
                entry.expectation(facts, DEFAULT_REQUEST) is not None)
        return known
    return of


#: (facts, built) -> (limits, {engine: (seconds, misses)}) for the default request.
_ORDERS: dict[tuple[Any, ...], tuple[Any, dict[str, tuple[float, bool]]]] = {}


class _Retimed:
    """The chain for the times of one dyadic band beyond the default request's horizon: the
    same primary and engines beyond its horizon, the same escalation engines, ordered by
    their costs and expectations for the default request stretched to the band's last time
    (memoised per band)."""

    def __init__(self, facts: SceneFacts, built: frozenset[str], chain: tuple[str, ...],
                 head: int) -> None:
        self.facts, self.built, self.chain, self.head = facts, built, chain, head
        self.found: dict[int, tuple[str, ...]] = {}

    def __call__(self, band: int) -> tuple[str, ...]:
        found = self.found.get(band)
        if found is None:
            found = self.found[band] = self._order(band)
        return found

    def _order(self, band: int) -> tuple[str, ...]:
        request = replace(DEFAULT_REQUEST, t_max=math.ldexp(1.0, band))
        primary = engine(self.chain[0])
        tail = [engine(name) for name in self.chain[self.head:]]
        key = {e.name: (e.precision >= primary.precision,
                        e.expectation(self.facts, request) is not None,
                        _cost(e, self.facts, request, self.built).seconds) for e in tail}
        return self.chain[:self.head] + tuple(sorted(self.chain[self.head:], key=key.__getitem__))


def _cost(entry: Engine, facts: SceneFacts, request: Request, built: frozenset[str]) -> Cost:
    cost = entry.cost(facts, request)
    return Cost(0.0, cost.run, cost.memory) if entry.name in built else cost


def _chain(serving: list[Engine], costs: dict[str, Cost], horizons: dict[str, float],
           facts: SceneFacts, request: Request, wanted: tuple[str, ...] | None,
           order: dict[str, float], misses: Callable[[Engine], bool]
           ) -> tuple[tuple[str, ...], int]:
    """Primary, then cover of the times beyond its horizon, then escalation (ordered by
    ``order``, the engines' costs for the default request, and ``misses``, whether an
    engine is expected to miss the target there); and the number of engines before the
    escalation."""
    def key(e: Engine) -> float:
        return costs[e.name].seconds

    float_engines = request.dps is None
    primaries = [e for e in serving if (e.tier < 2 if float_engines else e.tier == 2)
                 and (wanted is None or e.name in wanted)]
    if not primaries:
        if wanted is not None:
            return (), 0
        primaries = [e for e in serving if e.tier == min((x.tier for x in serving), default=0)]
    covering = [e for e in primaries if horizons[e.name] >= request.t_max]
    confident = [e for e in covering or primaries if wanted is not None
                 or e.expectation(facts, request) is None]
    # a refined (tier 1) engine is a primary only where no float64 engine is expected to do
    ordinary = [e for e in confident if e.tier == 0]
    primary = min(ordinary or confident or covering or primaries, key=key, default=None)
    if primary is None:
        return (), 0
    rest = [e for e in serving if e is not primary]
    beyond = sorted((e for e in rest if e.tier == primary.tier
                     and horizons[primary.name] < request.t_max < math.inf
                     and horizons[e.name] > horizons[primary.name]), key=key)
    # the engines that reach further than the primary and are expected to meet the target,
    # cheapest first, then the rest; an engine expected to miss the target too is worth
    # trying only when it is cheap. Judged for the default request, not this one: the
    # order is the scene's, so a time's engine does not depend on the other times of a call
    budget = _ESCALATION_BUDGET * max(order[primary.name], 1e-3)
    escalation = sorted((e for e in rest if e not in beyond
                         and (not misses(e) or order[e.name] <= budget)),
                        key=lambda e: (e.precision >= primary.precision, misses(e), order[e.name]))
    return tuple(e.name for e in [primary, *beyond, *escalation]), 1 + len(beyond)


def _reason(chain: tuple[str, ...], costs: dict[str, Cost], method: str, facts: SceneFacts,
            request: Request, refusals: list[Refusal]) -> str:
    size = f"{facts.n:,} coordinate{'s' if facts.n != 1 else ''}"
    if not chain:
        declined = "; ".join(str(r) for r in refusals) or "no engine is available"
        return f"no engine serves {size} and {request} with method={method!r}: {declined}"
    primary = chain[0]
    how = (f"method={method!r} was requested" if method != "auto"
           else "the cheapest engine that serves the request")
    others = ", ".join(f"{name} ~{costs[name].seconds:.2g} s" for name in chain[1:4])
    # an engine that serves where the one it defers to declined says why that one did
    preferred = engine(primary).defers_to
    declined = "".join(f"; {r}" for r in refusals if r.engine == preferred)
    return (f"{primary} ({engine(primary).summary}): {how} for {size} and {request}, "
            f"~{costs[primary].seconds:.2g} s" + (f"; then {others}" if others else "")
            + declined)
