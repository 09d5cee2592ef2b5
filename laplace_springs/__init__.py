"""laplace_springs: exact Laplace-transform solutions of spring–mass–damper systems.

The data flow is Scene → Resolvent → partial fractions → Solution → outputs; the stages
are the subpackages ``model``, ``exact``, ``numeric``, ``analysis`` and ``output``, and
:mod:`laplace_springs.planning` chooses the engine that serves a scene and a request:

>>> import laplace_springs as ls
>>> scene = ls.Scene.from_normalized(A=[[3, -1], [-2, 2]], x0=[1, 0], v0=[0, 0])
>>> ls.solve(scene).x
Matrix([
[  cos(t)/3 + 2*cos(2*t)/3],
[2*cos(t)/3 - 2*cos(2*t)/3]])

The public names are loaded when first used (``import laplace_springs`` itself imports
neither SymPy nor NumPy), so the command line and scripts that need one corner of the
package start fast.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from ._version import __version__
from .limits import DEFAULT_LIMITS as _DEFAULTS
from .limits import Limits, limits, using_limits  # eager (stdlib only): the names shadow the module

#: Public name -> (module, attribute) it is loaded from on first use.
_PUBLIC: dict[str, tuple[str, str]] = {
    # model: scenes and their inputs
    "Scene": ("model.scene", "Scene"),
    "SceneError": ("model.errors", "SceneError"),
    "LimitError": ("model.errors", "LimitError"),
    "InternalError": ("model.errors", "InternalError"),
    "InversionError": ("model.errors", "InversionError"),
    "InitialDataWarning": ("model.errors", "InitialDataWarning"),
    "load_scene": ("model.scene_files", "load_scene"),
    "bundled_scenes": ("model.scene_files", "bundled_scenes"),
    "cosine": ("model.forcing", "cosine"),
    "sine": ("model.forcing", "sine"),
    "step": ("model.forcing", "step"),
    "impulse": ("model.forcing", "impulse"),
    "ramp": ("model.forcing", "ramp"),
    "periodic": ("model.periodic", "periodic"),
    "square_wave": ("model.periodic", "square_wave"),
    "sawtooth": ("model.periodic", "sawtooth"),
    "pulse_train": ("model.periodic", "pulse_train"),
    "Periodic": ("model.periodic", "Periodic"),
    "sampled": ("model.sampled", "sampled"),
    "sampled_from_csv": ("model.sampled", "sampled_from_csv"),
    "Sampled": ("model.sampled", "Sampled"),
    "s": ("model.symbols", "S"),
    "lam": ("model.symbols", "lam"),
    "t": ("model.symbols", "TIME"),
    # exact: transforms and the resolvent
    "resolvent": ("exact.resolvent", "resolvent"),
    "Resolvent": ("exact.resolvent", "Resolvent"),
    "laplace": ("exact.laplace", "laplace"),
    "partial_fractions": ("exact.partial_fractions", "partial_fractions"),
    "inverse_laplace": ("exact.inverse", "inverse_laplace"),
    "inverse_laplace_terms": ("exact.inverse", "inverse_laplace_terms"),
    # analysis
    "modes": ("analysis.modes", "modes"),
    "Mode": ("analysis.modes", "Mode"),
    "frequency_response": ("analysis.frequency", "frequency_response"),
    "steady_state_amplitude": ("analysis.frequency", "steady_state_amplitude"),
    "transmissibility": ("analysis.frequency", "transmissibility"),
    "transmissibility_function": ("analysis.frequency", "transmissibility_function"),
    "omega": ("analysis.frequency", "omega"),
    "transfer_function": ("analysis.interop", "transfer_function"),
    # units (pint, the optional extra [units])
    "SceneUnits": ("model.units", "SceneUnits"),
    "spring_constant": ("model.units", "spring_constant"),
    "natural_frequency": ("model.units", "natural_frequency"),
    "damping_ratio": ("model.units", "damping_ratio"),
    "in_length_unit": ("model.units", "in_length_unit"),
    "from_state_space": ("analysis.interop", "from_state_space"),
    # output
    "draw_scene": ("output.drawing", "draw_scene"),
    "animate": ("output.animation", "animate"),
    "SceneAnimation": ("output.animation", "SceneAnimation"),
    "resolvent_latex": ("output.latex", "resolvent_latex"),
    "plot_bode": ("output.plots", "plot_bode"),
    "plot_frequency_response": ("output.plots", "plot_frequency_response"),
    "plot_pole_zero": ("output.plots", "plot_pole_zero"),
    # solving: the planner and the solutions
    "solve": ("solving", "solve"),
    "plan": ("solving", "plan_for"),
    "Plan": ("planning", "Plan"),
    "Solution": ("solution", "Solution"),
    "Verification": ("solution", "Verification"),
    "EvaluationReport": ("solution", "EvaluationReport"),
    "ExactSolution": ("routes.exact", "ExactSolution"),
    "ModalSolution": ("routes.modal", "ModalSolution"),
    "CertifiedSolution": ("routes.certified", "CertifiedSolution"),
    "KrylovSolution": ("routes.krylov", "KrylovSolution"),
    "SampledSolution": ("routes.sampled", "SampledSolution"),
    # sweeps
    "sweep": ("sweeps.run", "sweep"),
    "grid": ("sweeps.run", "grid"),
    "SweepResult": ("sweeps.run", "SweepResult"),
    "sample_parameters": ("sweeps.uncertainty", "sample_parameters"),
    "summarize": ("sweeps.uncertainty", "summarize"),
    # publish: pages, the explorer
    "worked_example": ("publish.page", "worked_example"),
    "WorkedExample": ("publish.page", "WorkedExample"),
    "explore": ("publish.explore", "explore"),
    "Explorer": ("publish.explore", "Explorer"),
    "peak_amplitude": ("sweeps.derived", "peak_amplitude"),
    "settling_time": ("sweeps.derived", "settling_time"),
    "steady_state_amplitudes": ("sweeps.derived", "steady_state_amplitudes"),
    "support_force": ("sweeps.derived", "support_force"),
    "peak_support_force": ("sweeps.derived", "peak_support_force"),
    "rms_amplitude": ("sweeps.derived", "rms_amplitude"),
    "sweep_transmissibility": ("sweeps.derived", "sweep_transmissibility"),
    "modal_quantities": ("sweeps.derived", "modal_quantities"),
}

#: The default relative accuracy of every evaluation (``ls.limits().target``).
TARGET = _DEFAULTS.target

__all__ = [
    "Explorer", "SceneAnimation", "WorkedExample", "animate", "explore", "worked_example",
    "CertifiedSolution", "EvaluationReport", "ExactSolution", "InitialDataWarning",
    "InternalError", "InversionError",
    "KrylovSolution", "LimitError", "Limits", "ModalSolution", "Mode", "Periodic", "Plan",
    "Resolvent", "Sampled", "SampledSolution", "Scene", "SceneError", "SceneUnits", "Solution",
    "SweepResult", "TARGET", "Verification", "__version__", "bundled_scenes", "cosine",
    "damping_ratio", "draw_scene", "in_length_unit", "natural_frequency", "spring_constant",
    "frequency_response", "from_state_space", "grid", "impulse", "inverse_laplace",
    "inverse_laplace_terms", "lam", "laplace", "limits", "load_scene", "modes", "omega",
    "partial_fractions", "peak_amplitude", "peak_support_force", "periodic", "plan", "plot_bode",
    "plot_frequency_response", "plot_pole_zero", "pulse_train", "ramp", "resolvent",
    "resolvent_latex", "s", "sample_parameters", "sampled", "sampled_from_csv", "sawtooth",
    "settling_time", "sine", "solve", "square_wave", "steady_state_amplitude",
    "steady_state_amplitudes", "step", "summarize", "support_force", "sweep", "t",
    "rms_amplitude", "sweep_transmissibility", "modal_quantities",
    "transfer_function", "transmissibility", "transmissibility_function", "using_limits",
]


def __getattr__(name: str) -> Any:
    """Load a public name on first use (PEP 562)."""
    try:
        module, attribute = _PUBLIC[name]
    except KeyError:
        raise AttributeError(f"module 'laplace_springs' has no attribute {name!r}") from None
    value = getattr(importlib.import_module(f".{module}", __name__), attribute)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_PUBLIC))


if TYPE_CHECKING:  # the same names, for type checkers and IDEs
    from .analysis.frequency import (
        frequency_response,
        omega,
        steady_state_amplitude,
        transmissibility,
        transmissibility_function,
    )
    from .analysis.interop import from_state_space, transfer_function
    from .analysis.modes import Mode, modes
    from .exact.inverse import inverse_laplace, inverse_laplace_terms
    from .exact.laplace import laplace
    from .exact.partial_fractions import partial_fractions
    from .exact.resolvent import Resolvent, resolvent
    from .model.errors import (
        InitialDataWarning,
        InternalError,
        InversionError,
        LimitError,
        SceneError,
    )
    from .model.forcing import cosine, impulse, ramp, sine, step
    from .model.periodic import Periodic, periodic, pulse_train, sawtooth, square_wave
    from .model.sampled import Sampled, sampled, sampled_from_csv
    from .model.scene import Scene
    from .model.scene_files import bundled_scenes, load_scene
    from .model.symbols import TIME as t
    from .model.symbols import S as s
    from .model.symbols import lam
    from .model.units import (
        SceneUnits,
        damping_ratio,
        in_length_unit,
        natural_frequency,
        spring_constant,
    )
    from .output.animation import SceneAnimation, animate
    from .output.drawing import draw_scene
    from .output.latex import resolvent_latex
    from .output.plots import plot_bode, plot_frequency_response, plot_pole_zero
    from .planning import Plan
    from .publish.explore import Explorer, explore
    from .publish.page import WorkedExample, worked_example
    from .routes.certified import CertifiedSolution
    from .routes.exact import ExactSolution
    from .routes.krylov import KrylovSolution
    from .routes.modal import ModalSolution
    from .routes.sampled import SampledSolution
    from .solution import EvaluationReport, Solution, Verification
    from .solving import plan_for as plan
    from .solving import solve
    from .sweeps.derived import (
        modal_quantities,
        peak_amplitude,
        peak_support_force,
        rms_amplitude,
        settling_time,
        steady_state_amplitudes,
        support_force,
        sweep_transmissibility,
    )
    from .sweeps.run import SweepResult, grid, sweep
    from .sweeps.uncertainty import sample_parameters, summarize
