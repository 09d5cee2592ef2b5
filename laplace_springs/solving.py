"""``solve``: build the solution on the route the policy chooses.

The decisions and their thresholds are in :mod:`laplace_springs.policy`; this module
gathers the facts it needs about a scene, runs the chosen route and, for ``"auto"``,
asks the policy again once the modal route's own error bound is known.
"""

from __future__ import annotations

import numpy as np

from .exact.assembly import exact_motion
from .limits import limits
from .model.errors import SceneError
from .model.sampled import formula_part
from .model.scene import Scene
from .numeric.certified import certified_poles
from .numeric.chebyshev import chebyshev_motion, rayleigh_coefficients
from .numeric.classical import classical_damping, classical_motion
from .numeric.first_order import has_first_order_form, rational_entries, symbolic_entries
from .numeric.krylov import krylov_refusal
from .numeric.modal import decompose_modal
from .numeric.times import as_times
from .policy import (
    Decision,
    SceneFacts,
    after_modal_probe,
    check_target,
    column_scales,
    route_for,
)
from .routes.certified import CertifiedSolution
from .routes.exact import ExactSolution
from .routes.krylov import krylov_solution
from .routes.modal import ModalSolution
from .routes.sampled import solve_sampled
from .solution import Solution

__all__ = ["solve", "scene_facts"]


def scene_facts(scene: Scene) -> SceneFacts:
    """What :func:`laplace_springs.policy.route_for` needs to know of a scene.

    Examples
    --------
    >>> scene_facts(Scene.from_matrices(M=[[1]], K=[["k"]], x0=[1], v0=[0], parameters=["k"]))
    SceneFacts(n=1, symbolic=True, forced=False, rational=False, first_order=False, classical=False, rayleigh=False, krylov=False)
    """
    rational = all(rational_entries(scene, name) is not None for name in ("M", "C", "K", "x0", "v0"))
    # rational matrices have no symbols (read from their domain: no SymPy walk of every entry)
    symbolic = not (rational and scene.forcing is None and scene.sampled is None) \
        and bool(scene.free_symbols)
    forced = scene.is_forced
    first_order = not symbolic and has_first_order_form(scene)
    unforced = first_order and not forced
    rayleigh = unforced and rayleigh_coefficients(scene) is not None  # O(nnz), implies classical
    classical = rayleigh or (unforced and classical_damping(scene))
    return SceneFacts(n=scene.n, symbolic=symbolic, forced=forced,
                      rational=not symbolic and rational, first_order=first_order,
                      classical=classical, rayleigh=rayleigh,
                      krylov=unforced and rational and krylov_refusal(scene) is None)


def solve(scene: Scene, *, method: str = "auto", target: float | None = None) -> Solution:
    """Solve M x'' + C x' + K x = f(t) with the scene's initial data.

    Parameters
    ----------
    scene : Scene
        The mechanical system.
    method : {"auto", "exact", "modal", "certified", "krylov"}
        "exact": exact partial fractions (symbols, forcing, closed forms). "modal": the
        float64 modes (large numeric scenes): from the symmetric eigenproblem of size n for
        undamped and classically damped scenes (C M⁻¹K = K M⁻¹C, checked exactly) — or,
        for Rayleigh damping C = aK + bM with a diagonal M from
        :attr:`~laplace_springs.limits.Limits.chebyshev_min_coordinates` coordinates, a Chebyshev
        expansion in M⁻¹K (sparse products, no eigenvectors) — else the conditioned
        eigen-decomposition of the 2n x 2n first-order matrix. "certified":
        exact polynomials with certified roots, evaluated in ball arithmetic. "krylov":
        Taylor steps of the sparse first-order system in double-double arithmetic, bounded
        through the energy (large scenes whose damping is not classical). "auto"
        takes the fastest route that meets the contract (see
        :func:`laplace_springs.policy.route_for`). "numeric" is the former name of
        "modal".
    target : float, optional
        The relative accuracy every evaluation aims at (default
        :data:`laplace_springs.policy.TARGET`, 1e-13).

    Returns
    -------
    Solution
        :class:`~laplace_springs.routes.exact.ExactSolution`,
        :class:`~laplace_springs.routes.modal.ModalSolution` or
        :class:`~laplace_springs.routes.certified.CertifiedSolution`: the same interface, with
        ``method`` and ``reason`` saying which route was taken and why.

    Raises
    ------
    SceneError
        When the requested route cannot take the scene (named in the message).

    Examples
    --------
    A critically damped mass, x'' + 2x' + x = 0, x(0) = 1:

    >>> sol = solve(Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0]))
    >>> sol.method, sol.x[0]
    ('certified', t*exp(-t) + exp(-t))
    >>> sol.evaluate([0.0, 1.0]).round(12)
    array([[1.        , 0.73575888]])
    """
    target = check_target(target)
    if scene.sampled is not None:  # measured histories: the rest by `method`, then their response
        base = solve(formula_part(scene), method=method, target=target)
        return solve_sampled(scene, target, base=base)
    facts = scene_facts(scene)
    if facts.symbolic and method in ("modal", "numeric", "certified", "krylov"):
        raise SceneError(f"the {method} route needs numbers, but these entries are symbolic: "
                         + ", ".join(symbolic_entries(scene)) + "; use method='exact'")
    decision = route_for(method, facts)
    if decision.route == "exact":
        return ExactSolution(exact_motion(scene), reason=decision.reason, target=target)
    if decision.route == "certified":
        return _certified(scene, decision, target)
    if decision.route == "krylov":
        return krylov_solution(scene, reason=decision.reason, target=target)
    if facts.modal_kind == "chebyshev":
        return ModalSolution(scene, chebyshev_motion(scene), reason=decision.reason, target=target)
    if facts.classical:
        classical = classical_motion(scene)  # decomposed on first use beyond the general route's size
        if scene.n > limits().general_modal_max_coordinates or not classical.has_zero_frequency:
            return ModalSolution(scene, classical, reason=decision.reason, target=target)
        decision = Decision("modal", decision.reason.split(":")[0] + ": a zero frequency (rigid-"
                            "body motion): the general modal route splits it off exactly")
    try:
        motion = _modal_motion(scene)
    except SceneError:
        if method != "auto" or scene.n > limits().general_modal_max_coordinates:
            raise  # a size refusal: the exact route would refuse too, for a worse reason
        fallback = Decision("certified" if facts.certified_ok else "exact",
                            "auto: the modal route cannot hold this scene in float64")
        return (_certified(scene, fallback, target) if fallback.route == "certified"
                else ExactSolution(exact_motion(scene), reason=fallback.reason, target=target))
    warnings = "".join(f"; warning: {w}" for w in motion.modes.warnings)
    solution = ModalSolution(scene, motion, reason=decision.reason + warnings, target=target)
    if method == "auto" and facts.certified_ok:  # only the certified route can do better
        better = after_modal_probe(facts, _probe(solution), target)
        if better is not None:
            return _certified(scene, better, target)
    return solution


def _modal_motion(scene: Scene):
    """The modal route's decomposition; a failed float64 eigen-solver is a SceneError."""
    try:
        return decompose_modal(scene)
    except np.linalg.LinAlgError as exc:
        raise SceneError(f"the modal route's float64 eigen-decomposition failed ({exc}); the "
                         "scene's scales are too far apart for float64: use method='certified'") from None


def _certified(scene: Scene, decision: Decision, target: float) -> CertifiedSolution:
    poles = certified_poles(scene)
    if poles is None:  # route_for has checked the facts; this is a safeguard
        raise SceneError("the certified route cannot take this scene")
    return CertifiedSolution(scene, poles, reason=decision.reason, target=target)


def _probe(solution: ModalSolution) -> float:
    """The modal route's largest bound relative to the contract's scale at Limits.probe_times."""
    times = as_times(np.array(limits().probe_times))
    values, bounds = solution._float(times, 0)
    scale = column_scales(values, solution._floor(0))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.max(bounds / np.where(scale > 0, scale, np.inf)[None, :])
    return float(ratio) if np.isfinite(ratio) else float("inf")
