"""``solve``: execute the planner's choice of engine for a scene.

The decision is made by :func:`laplace_springs.planning.plan` from the scene's facts and a
default request (100 times on [0, 100]); this module builds the solution of the plan's
first engine that can hold the scene, and records the plan's reason. Each later
``evaluate`` plans again for its own times (:meth:`Solution.evaluate`).
"""

from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from .limits import limits
from .model.errors import (
    FloatRangeError,
    InitialDataWarning,
    InversionError,
    LimitError,
    SceneError,
)
from .model.sampled import formula_part
from .model.scene import Scene
from .numeric.first_order import massless_nodes, symbolic_entries
from .numeric.modal import ModalMotion
from .numeric.times import as_times, check_dps
from .planning.engines import Refusal, engine
from .planning.execute import BUILDERS, relative_bounds
from .planning.facts import scene_facts
from .planning.plan import FAMILIES, METHODS, Plan, plan
from .planning.request import DEFAULT_REQUEST, request_for
from .planning.standing import standing_engine
from .policy import check_target
from .routes.engines import solution_for
from .routes.sampled import solve_sampled
from .solution import Solution

__all__ = ["solve", "plan_for"]


def solve(scene: Scene, *, method: str = "auto", target: float | None = None) -> Solution:
    """Solve M x'' + C x' + K x = f(t) with the scene's initial data.

    Parameters
    ----------
    scene : Scene
        The mechanical system.
    method : str
        "auto" (default): the planner takes the cheapest engine that meets the target
        (see :mod:`laplace_springs.planning`). An engine name restricts the first engine:
        "exact" (exact partial fractions: symbols, forcing, closed forms), "certified"
        (poles certified by python-flint), "classical" (the symmetric eigenproblem of
        undamped and classically damped scenes), "chebyshev" (expansion in M⁻¹K, Rayleigh
        damping), "modal" (the float64 eigen family: classical, chebyshev or the general
        2n x 2n eigenproblem, as the structure allows; "numeric" is its former name),
        "krylov" (double-double Taylor steps of large sparse networks), and the engines
        "tiny" and "refined" where they are installed; "ball" and "mp", the
        arbitrary-precision escalations of "certified" and "exact", are served by those
        (their ``dps=`` digits and recomputed times come from them). Times whose bound misses the target
        are still recomputed by the plan's escalation engines.
    target : float, optional
        The relative accuracy every evaluation aims at (default
        :attr:`~laplace_springs.limits.Limits.target`, 1e-13).

    Returns
    -------
    Solution
        The same interface whatever the engine; ``method`` names the engine and
        ``reason`` says why (``sol.plan(times)`` shows the plan for a request).

    Raises
    ------
    SceneError
        When the requested engine cannot take the scene for a property of the scene (named
        in the message), e.g. symbols for a numeric engine.
    LimitError
        When no engine can serve the scene within the package's limits.

    Examples
    --------
    A critically damped mass, x'' + 2x' + x = 0, x(0) = 1:

    >>> sol = solve(Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0]))
    >>> sol.x[0]
    t*exp(-t) + exp(-t)
    >>> sol.evaluate([0.0, 1.0]).round(12)
    array([[1.        , 0.73575888]])
    """
    target = check_target(target)
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    if scene.sampled is not None:  # measured histories: the rest by `method`, then their response
        base = solve(formula_part(scene), method=method, target=target)
        return solve_sampled(scene, target, base=base)
    if (standing := _standing_solution(scene, method, target)) is not None:
        return standing
    facts = scene_facts(scene, method)
    if facts.symbolic and method not in ("auto", "exact", "mp"):
        raise SceneError(f"the {method} route needs numbers, but these entries are symbolic: "
                         + ", ".join(symbolic_entries(scene)) + "; use method='exact'")
    # an engine's overflow is its refusal or an infinite bound, never a NumPy warning
    with np.errstate(all="ignore"):
        return _planned_solution(scene, facts, method, target)


def _standing_solution(scene: Scene, method: str, target: float) -> Solution | None:
    """The solution of the standing plan's engine (:mod:`laplace_springs.planning.standing`)
    when it holds for the scene and the engine's bound meets the target at the probe times,
    as the plan's first engine would be taken; else None (the plan decides). Its reason is
    the default plan's, made when first asked."""
    name = standing_engine(scene, method)
    if name is None:
        return None
    with np.errstate(all="ignore"):
        solution = _build(name, scene, None, target)
        if isinstance(solution, Refusal) or not _probe(solution, target) <= target:
            return None
    solution.requested = method
    solution._standing = True
    return solution


def _planned_solution(scene: Scene, facts: Any, method: str, target: float) -> Solution:
    """The solution of the plan's first engine that takes the scene and, for "auto", meets
    the target at the probe times (else the tightest that was built)."""
    available = set(BUILDERS)
    refusals: list[Refusal] = []
    probed: list[tuple[float, Solution, Plan]] = []  # engines whose own bound missed
    solution: Solution | Refusal
    while True:
        chosen = plan(facts, DEFAULT_REQUEST, method=method, available=available)
        if not chosen.chain:
            if probed:  # every engine misses the target at the probe: the tightest serves
                _, best, chosen = min(probed, key=lambda entry: entry[0])
                return _finish(best, chosen, method, refusals, set(BUILDERS) - available)
            raise _no_engine(chosen, method, refusals, facts, scene, target)
        name = chosen.chain[0]
        solution = _build(name, scene, chosen, target, method)
        if isinstance(solution, Refusal):
            refusals.append(solution)
        elif method == "auto" and engine(name).tier == 0 and name != "exact" \
                and (worst := _probe(solution, target)) > target:
            refusals.append(Refusal(name, f"its own bound ({worst:.1e} of the scale) misses "
                                    "the target at Limits.probe_times"))
            probed.append((worst, solution, chosen))
        else:
            return _finish(solution, chosen, method, refusals, set(BUILDERS) - available)
        available -= _hosted_by(name) if isinstance(solution, Refusal) else {name}


def _hosted_by(name: str) -> set[str]:
    """``name`` and the engines its solution hosts (the arbitrary-precision escalations:
    "mp" of "exact", "ball" of "certified"): when it cannot be built, neither can they.

    >>> sorted(_hosted_by("exact"))
    ['exact', 'mp']
    """
    return {name, *(family for family, members in FAMILIES.items() if members == (name,))}


def _finish(solution: Solution, chosen: Plan, method: str, refusals: list[Refusal],
            excluded: set[str]) -> Solution:
    """``solution`` with the request, the engines its plans leave out (those that refused
    or missed the target while solving) and its reason."""
    solution.requested = method
    solution.excluded = frozenset(excluded - {solution.method})
    others = [r for r in refusals if r.engine != solution.method]
    notes = _dropped_initial_data(solution)
    solution.reason = chosen.reason + "".join(f"; {r}" for r in others) + _warnings(solution) \
        + "".join(f"; note: {note}" for note in notes)
    for note in notes:
        warnings.warn(note, InitialDataWarning, stacklevel=3)
    return solution


def _dropped_initial_data(solution: Solution) -> list[str]:
    """Sentences for the entries of x0 (and nonzero entries of v0) at massless nodes that
    the motion does not start from: on the exact route from its ``initial_jump`` (the only
    route that takes a massless node without a dashpot); on the others, whose massless
    nodes keep x0, the nonzero entries of v0 (nothing is computed)."""
    scene = solution.scene
    massless = massless_nodes(scene)
    if not massless:
        return []
    names, notes = scene.names, []
    if solution.method not in ("exact", "mp"):  # x0 kept (a dashpot holds the node)
        return [f"v0[{names[i]}] = {scene.v0[i]} is not kept: {names[i]} has no mass, its "
                "velocity follows from its equation" for i in massless if scene.v0[i] != 0]
    jump = solution.initial_jump
    for i in massless:
        if jump.position[i] != 0:
            notes.append(f"x0[{names[i]}] = {scene.x0[i]} is not kept: {names[i]} has no mass "
                         f"and its springs set {names[i]}(0⁺) = {jump.x_plus[i]} (a jump at t = 0)")
        if scene.v0[i] != 0 and jump.velocity[i] != 0:
            notes.append(f"v0[{names[i]}] = {scene.v0[i]} is not kept: {names[i]} has no mass, "
                         f"its equation sets {names[i]}'(0⁺) = {jump.v_plus[i]}")
    return notes


def _build(name: str, scene: Scene, chosen: Plan | None, target: float,
           method: str = "auto") -> Solution | Refusal:
    """The solution whose own engine is ``name``, or why float64 cannot hold the scene (or,
    for "auto", why the exact route cannot: the plan's next engine may serve). Without a
    plan, its reason is made when first asked."""
    try:
        return solution_for(name, scene, reason=None if chosen is None else chosen.reason,
                            target=target)
    except (FloatRangeError, np.linalg.LinAlgError) as exc:
        return Refusal(name, f"cannot hold the scene in float64: {exc}")
    except InversionError as exc:  # the exact route's own limits (a factor's degree)
        if name not in ("exact", "mp") or method != "auto":
            raise
        return Refusal(name, str(exc), "max_exact_factor_degree")


def _probe(solution: Solution, target: float) -> float:
    """The engine's own largest bound at Limits.probe_times, relative to the scale (a scene
    whose scales float64 cannot separate: the next engine of the plan may do better).

    An engine whose motion gives its bounds alone (the tiny engine) is first judged against
    the floor S₀ of the scale, which is at most max(‖x(t)‖∞, S₀): a bound that meets the
    target there meets it at the probe, and no value is formed. Its ``bound_until`` (an
    upper bound of every bound up to the last probe time, from the decomposition's
    constants alone) is asked first, then ``largest_bound`` at the probe times."""
    given = limits().probe_times
    times = _PROBES.get(given)
    if times is None:
        times = _PROBES[given] = as_times(np.array(given))
    motion: Any = getattr(solution, "motion", None)
    if hasattr(motion, "largest_bound"):
        floor = solution._floor(0)
        quick = motion.bound_until(max(given, default=0.0)) / floor if floor > 0 else math.inf
        if quick > target and floor > 0:
            quick = motion.largest_bound(times.hi) / floor
        if quick <= target:
            return quick
    values, bounds = solution._float(times, 0)
    return float(np.max(relative_bounds(values, bounds, solution._floor(0)), initial=0.0))


#: Limits.probe_times -> their Times (read once).
_PROBES: dict[tuple[float, ...], Any] = {}


def _warnings(solution: Solution) -> str:
    """The general modal engine's warnings (clusters it could not separate)."""
    motion = getattr(solution, "motion", None)
    found = motion.modes.warnings if isinstance(motion, ModalMotion) else ()
    return "".join(f"; warning: {w}" for w in found)


def _no_engine(chosen: Plan, method: str, refusals: list[Refusal], facts: Any, scene: Scene,
               target: float) -> ValueError:
    """The error when no engine of ``method`` can take the scene: the refusals of the
    engines asked for, and the way out (the first other engine of the plan that builds)."""
    reasons = [*chosen.refusals, *refusals]
    if method == "auto":
        return LimitError(chosen.reason + "".join(f"; {r}" for r in refusals))
    members = FAMILIES.get(method, (method,))
    mine = [r for r in reasons if r.engine in members]
    text = "; ".join(r.reason if len(members) == 1 else str(r) for r in mine) or chosen.reason
    others = plan(facts, DEFAULT_REQUEST, available=set(BUILDERS) - set(members))
    serving = next((name for name in others.chain if _builds(name, scene, others, target)),
                   None)
    way_out = (f"; use method={serving!r} (or 'auto')" if serving is not None
               else "; no engine of the package takes it")
    error = LimitError if any(r.limit for r in mine) else SceneError
    return error(f"the {method} route cannot take this scene: {text}{way_out}")


def _builds(name: str, scene: Scene, chosen: Plan, target: float) -> bool:
    """Whether engine ``name`` takes the scene (it is built to find out)."""
    try:
        return not isinstance(_build(name, scene, chosen, target), Refusal)
    except (SceneError, LimitError, ValueError):
        return False


def plan_for(scene: Scene, times: Any = None, *, method: str = "auto", target: float | None = None,
             dps: int | None = None, derivative: int = 0) -> Plan:
    """The plan ``solve(scene, method=method).evaluate(times, ...)`` would execute (``ls.plan``).

    Nothing is decomposed or evaluated: the plan is made from the scene's facts (without
    ``times``, for the default request of ``solve``: 100 times on [0, 100]).

    Examples
    --------
    A 200-mass undamped chain at t = 10⁶: the float64 engines lose the phase ωt there, so
    the refined engine (eigenpairs and phases in double-double) serves it:

    >>> import laplace_springs as ls
    >>> chain = ls.Scene.from_components(
    ...     masses={f"m{i}": 1 for i in range(200)},
    ...     springs={"k0": ("wall", "m0", 1), **{f"k{i}": (f"m{i-1}", f"m{i}", 1)
    ...                                          for i in range(1, 200)}},
    ...     x0=[1] + [0] * 199, v0=[0] * 200)
    >>> ls.plan(chain, [0.0, 1.0]).primary
    'chebyshev'
    """
    request = DEFAULT_REQUEST if times is None else request_for(
        as_times(times), target=check_target(target),
        dps=None if dps is None else check_dps(dps), order=derivative)
    return plan(scene_facts(scene, method), request, method=method, available=set(BUILDERS))
