"""Building the planner's engines for a solution: one builder per engine name.

A builder takes the solution being evaluated and returns an evaluator
``(times, order, target) -> (values, bounds)``, or a
:class:`~laplace_springs.planning.engines.Refusal` when the engine finds, while building,
that it cannot hold the scene (an eigen-solver failure, a scale beyond float64: a
:class:`~laplace_springs.model.errors.FloatRangeError`). The data an engine builds is kept
by the solution (its ``_evaluators``), so a scene is decomposed at most once per engine.
Importing this module registers the builders with the executor
(:data:`laplace_springs.planning.execute.BUILDERS`).
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any

import numpy as np

from ..exact.assembly import exact_motion
from ..exact.screening import exact_refusal
from ..limits import limits
from ..model.errors import FloatRangeError, InversionError, LimitError
from ..numeric.certified import certified_poles
from ..numeric.chebyshev import chebyshev_motion
from ..numeric.classical import classical_motion
from ..numeric.krylov import krylov_motion
from ..numeric.modal import decompose_modal
from ..numeric.refined import refined_motion
from ..numeric.tiny import tiny_motion
from ..planning.engines import Refusal
from ..planning.execute import Evaluator, register_engine
from ..solution import Solution
from . import exo
from .certified import CertifiedSolution
from .exact import ExactSolution
from .krylov import KrylovSolution
from .modal import ModalSolution

__all__ = ["host", "solution_for"]


def _float_of(solution: Solution) -> Evaluator:
    return lambda times, order, target: solution._float(times, order)


def _escalation_of(solution: Solution) -> Evaluator:
    return solution._escalate


def _exact_host(solution: Solution) -> ExactSolution | Refusal:
    if isinstance(solution, ExactSolution):
        return solution
    found = solution.__dict__.get("_exact_host")
    if found is None:
        why = exact_refusal(solution.scene)
        try:
            found = Refusal("exact", why) if why is not None else _exact_form(solution)
        except InversionError as exc:  # found while building (irrational coefficients)
            found = Refusal("exact", str(exc), "max_exact_factor_degree")
        solution.__dict__["_exact_host"] = found
    return found


def _exact_form(solution: Solution) -> ExactSolution:
    """The exact terms of ``solution``'s scene (its own exact form where it keeps one)."""
    form = solution._exact_form
    if isinstance(form, ExactSolution):
        return form
    why = getattr(solution, "inexact_reason", None)  # its own attempt refused: not again
    if why is not None:
        raise InversionError(why)
    return ExactSolution(exact_motion(solution.scene), reason="exact terms for the plan",
                         target=solution.target)


def _certified_host(solution: Solution) -> CertifiedSolution | Refusal:
    if isinstance(solution, CertifiedSolution):
        return solution
    found = solution.__dict__.get("_certified_host")
    if found is None:
        poles = certified_poles(solution.scene)
        found = (Refusal("certified", "the scene has no exact first-order form") if poles is None
                 else CertifiedSolution(solution.scene, poles, reason="certified poles for the plan",
                                        target=solution.target))
        solution.__dict__["_certified_host"] = found
    return found


#: The float64 engines hosted by a solution class of their own:
#: name -> (scene, reason, target) -> Solution.
def _classical(scene: Any, reason: str | None, target: float) -> Solution | Refusal:
    """The symmetric eigen engine; rigid-body motion (a zero frequency) goes to the general
    modal engine, which splits it off exactly, where that engine takes the scene."""
    motion = classical_motion(scene)
    if scene.n <= limits().general_modal_max_coordinates and motion.has_zero_frequency:
        theta = motion.decomposition.theta
        if float(np.min(theta)) < -1e-8 * float(np.max(np.abs(theta))):  # a growing mode
            return Refusal("classical", "a negative modal stiffness (K is not positive "
                           "semidefinite: unstable motion): the general modal engine serves it")
        return Refusal("classical", "a zero frequency (rigid-body motion): the general modal "
                       "engine splits it off exactly")
    return ModalSolution(scene, motion, reason=reason, target=target)


_FLOAT_SOLUTIONS: dict[str, Callable[[Any, str | None, float], Solution | Refusal]] = {
    "classical": _classical,
    "chebyshev": lambda scene, reason, target: ModalSolution(
        scene, chebyshev_motion(scene), reason=reason, target=target),
    "modal": lambda scene, reason, target: ModalSolution(
        scene, decompose_modal(scene), reason=reason, target=target),
    "krylov": lambda scene, reason, target: KrylovSolution(
        scene, krylov_motion(scene), reason=reason, target=target),
    "refined": lambda scene, reason, target: ModalSolution(
        scene, refined_motion(scene), reason=reason, target=target),
    "tiny": lambda scene, reason, target: ModalSolution(
        scene, tiny_motion(scene), reason=reason, target=target),
    "exo": lambda scene, reason, target: _exo(scene, target),
}


def _exo(scene: Any, target: float) -> Solution | Refusal:
    """The exo engine, or its refusal where no engine serves one of its pieces' unforced
    scenes (that LimitError names the limits; the plan's next engine may serve)."""
    try:
        return exo.solve_exo(scene, _solver(), target=target)
    except FloatRangeError:
        raise
    except LimitError as exc:
        return Refusal.from_text("exo", f"a piece's unforced scene is not served: {exc}")


def _solver() -> Callable[..., Solution]:
    """``laplace_springs.solve`` (the exo engine solves its augmented scenes with it; the
    module imports this one, so it is looked up when first needed)."""
    solve: Callable[..., Solution] = sys.modules["laplace_springs.solving"].solve
    return solve


def _numeric_host(name: str) -> Callable[[Solution], Any]:
    """The builder of a float64 engine: a Refusal when float64 cannot hold the scene."""
    def build(solution: Solution) -> Solution | Refusal:
        try:
            return _FLOAT_SOLUTIONS[name](solution.scene, f"{name} engine for the plan",
                                          solution.target)
        except (FloatRangeError, np.linalg.LinAlgError) as exc:
            return Refusal(name, f"cannot hold the scene in float64: {exc}")
    return build


_HOSTS: dict[str, Callable[[Solution], Any]] = {
    "exact": _exact_host,
    "mp": _exact_host,
    "certified": _certified_host,
    "ball": _certified_host,
    **{name: _numeric_host(name) for name in _FLOAT_SOLUTIONS},
}
#: Engines whose evaluator is the host's escalation (arbitrary precision) rather than its
#: float64 pass.
_ESCALATIONS = ("mp", "ball")


def host(solution: Solution, name: str) -> Any:
    """The solution object that evaluates engine ``name`` for ``solution``'s scene (or a
    Refusal). Float64 hosts are kept by the caller's evaluator cache."""
    return _HOSTS[name](solution)


def _builder(name: str) -> Callable[[Solution], Evaluator | Refusal]:
    def build(solution: Solution) -> Evaluator | Refusal:
        found = host(solution, name)
        if isinstance(found, Refusal):
            return found
        return _escalation_of(found) if name in _ESCALATIONS else _float_of(found)
    return build


def solution_for(name: str, scene: Any, *, reason: str | None, target: float) -> Solution | Refusal:
    """A new solution whose own engine is ``name``, or the engine's refusal found while
    building (raises what building raises: FloatRangeError, LinAlgError)."""
    if name in ("exact", "mp"):
        return ExactSolution(exact_motion(scene), reason=reason, target=target)
    if name in ("certified", "ball"):
        poles = certified_poles(scene)
        if poles is None:
            raise FloatRangeError("the certified route needs rational entries and a first-order "
                                  "form")
        return CertifiedSolution(scene, poles, reason=reason, target=target)
    return _FLOAT_SOLUTIONS[name](scene, reason, target)


def _digits_host(name: str) -> Callable[[Solution], Any]:
    return lambda solution: host(solution, name)


for _name in _HOSTS:
    register_engine(_name, _builder(_name), _digits_host(_name) if _name in _ESCALATIONS else None)
