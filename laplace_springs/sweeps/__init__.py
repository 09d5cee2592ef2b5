"""Parameter sweeps and uncertainty: one symbolic solve, many parameter sets.

:func:`sweep` evaluates a symbolic scene for thousands to millions of parameter sets in
vectorised NumPy (or on a Dask cluster), each set meeting the accuracy contract of
``ls.solve(scene.subs(set)).evaluate(times)``; :func:`grid` builds Cartesian products;
:mod:`~laplace_springs.sweeps.derived` has the quantities users sweep for (peak
amplitude, settling time, steady-state amplitude, support force) and
:mod:`~laplace_springs.sweeps.uncertainty` sampling and summaries.
"""

from .compile import CompiledScene, compile_scene
from .derived import (
    peak_amplitude,
    peak_support_force,
    settling_time,
    steady_state_amplitudes,
    support_force,
)
from .run import ParameterGrid, SweepResult, grid, sweep
from .uncertainty import sample_parameters, summarize

__all__ = [
    "sweep", "grid", "SweepResult", "ParameterGrid", "CompiledScene", "compile_scene",
    "peak_amplitude", "settling_time", "steady_state_amplitudes", "support_force",
    "peak_support_force", "sample_parameters", "summarize",
]
