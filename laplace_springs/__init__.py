"""laplace_springs: exact Laplace-transform solutions of spring–mass–damper systems.

The data flow is Scene → Resolvent → partial fractions → Solution → outputs; the stages
are the subpackages ``model``, ``exact``, ``numeric``, ``analysis`` and ``output``, and
:mod:`laplace_springs.policy` decides which route solves a scene:

>>> import laplace_springs as ls
>>> scene = ls.Scene.from_normalized(A=[[3, -1], [-2, 2]], x0=[1, 0], v0=[0, 0])
>>> ls.solve(scene).x
Matrix([
[  cos(t)/3 + 2*cos(2*t)/3],
[2*cos(t)/3 - 2*cos(2*t)/3]])
"""

from ._version import __version__
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
from .model.errors import InversionError, SceneError
from .model.forcing import cosine, impulse, ramp, sine, step
from .model.periodic import Periodic, periodic, pulse_train, sawtooth, square_wave
from .model.sampled import Sampled, sampled, sampled_from_csv
from .model.scene import Scene
from .model.scene_files import bundled_scenes, load_scene
from .model.symbols import S as s
from .model.symbols import lam
from .output.drawing import draw_scene
from .output.latex import resolvent_latex
from .output.plots import plot_bode, plot_frequency_response, plot_pole_zero
from .policy import TARGET
from .routes.certified import CertifiedSolution
from .routes.exact import ExactSolution
from .routes.krylov import KrylovSolution
from .routes.modal import ModalSolution
from .routes.sampled import SampledSolution
from .solution import Solution, Verification, t
from .solve import solve
from .sweeps import (
    SweepResult,
    grid,
    peak_amplitude,
    peak_support_force,
    sample_parameters,
    settling_time,
    steady_state_amplitudes,
    summarize,
    support_force,
    sweep,
)

__all__ = [
    "Scene", "SceneError", "InversionError", "load_scene", "bundled_scenes",
    "resolvent", "Resolvent", "resolvent_latex", "lam", "s", "laplace", "partial_fractions", "inverse_laplace",
    "inverse_laplace_terms", "solve", "Solution", "ExactSolution", "ModalSolution",
    "CertifiedSolution", "KrylovSolution", "Verification", "TARGET", "t",
    "cosine", "sine", "step", "impulse", "ramp",
    "periodic", "square_wave", "sawtooth", "pulse_train", "Periodic",
    "sampled", "sampled_from_csv", "Sampled", "SampledSolution",
    "modes", "Mode", "frequency_response", "steady_state_amplitude",
    "plot_frequency_response", "draw_scene", "omega", "__version__",
    "transfer_function", "from_state_space", "plot_bode", "plot_pole_zero",
    "transmissibility", "transmissibility_function",
    "sweep", "grid", "SweepResult", "sample_parameters", "summarize", "peak_amplitude",
    "settling_time", "steady_state_amplitudes", "support_force", "peak_support_force",
]
