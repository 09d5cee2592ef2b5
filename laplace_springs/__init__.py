"""laplace_springs: exact Laplace-transform solutions of spring–mass–damper systems.

The data flow is Scene → Resolvent → partial fractions → Solution → outputs:

>>> import laplace_springs as ls
>>> scene = ls.Scene.from_normalized(A=[[3, -1], [-2, 2]], x0=[1, 0], v0=[0, 0])
>>> ls.solve(scene).x
Matrix([
[  cos(t)/3 + 2*cos(2*t)/3],
[2*cos(t)/3 - 2*cos(2*t)/3]])
"""

from .errors import InversionError, SceneError
from .forcing import cosine, impulse, ramp, sine, step
from .frequency import frequency_response, omega, plot_frequency_response, steady_state_amplitude
from .inverse import inverse_laplace, inverse_laplace_terms
from .modes import Mode, modes
from .partial_fractions import partial_fractions
from .resolvent import Resolvent, lam, resolvent
from .scene import Scene
from .scene_files import bundled_scenes, load_scene
from .solution import Solution, solve, t

__all__ = [
    "Scene", "SceneError", "InversionError", "load_scene", "bundled_scenes",
    "resolvent", "Resolvent", "lam", "partial_fractions", "inverse_laplace",
    "inverse_laplace_terms", "solve", "Solution", "t",
    "cosine", "sine", "step", "impulse", "ramp",
    "modes", "Mode", "frequency_response", "steady_state_amplitude",
    "plot_frequency_response", "omega",
]
__version__ = "0.1.0"
