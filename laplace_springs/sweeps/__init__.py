"""Parameter sweeps and uncertainty: many parameter sets, each as solving it alone would.

:func:`sweep` evaluates a scene with declared parameters for thousands to millions of
parameter sets, on one machine or a Dask cluster, each set meeting the accuracy contract
of ``ls.solve(scene.subs(set)).evaluate(times)``. The route depends on the scene
(:mod:`~laplace_springs.sweeps.paths`): a symbolic solve compiled once for small scenes,
batched eigen-decompositions with a rigorous bound for unforced scenes of any size, and
each set solved alone for everything else (periodic, sampled or delayed forcing).
:func:`grid` builds Cartesian products; :mod:`~laplace_springs.sweeps.derived` has the
quantities users sweep for (peak amplitude, RMS, settling time, steady-state amplitude,
transmissibility, modal quantities, support force), :mod:`~laplace_springs.sweeps.reduce`
the same reduced chunk by chunk, and :mod:`~laplace_springs.sweeps.uncertainty` sampling
and summaries.
"""

from .compile import CompiledScene, compile_scene
from .derived import (
    ModalQuantities,
    modal_quantities,
    peak_amplitude,
    peak_support_force,
    rms_amplitude,
    settling_time,
    steady_state_amplitudes,
    support_force,
    sweep_transmissibility,
)
from .paths import SweepPlan
from .run import ParameterGrid, SweepResult, grid, plan_sweep, sweep
from .uncertainty import Summary, sample_parameters, summarize

__all__ = [
    "sweep", "grid", "plan_sweep", "SweepResult", "SweepPlan", "ParameterGrid", "CompiledScene",
    "compile_scene", "peak_amplitude", "rms_amplitude", "settling_time",
    "steady_state_amplitudes", "sweep_transmissibility", "modal_quantities", "ModalQuantities",
    "support_force", "peak_support_force", "sample_parameters", "summarize", "Summary",
]
