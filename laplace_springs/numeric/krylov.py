"""Large sparse scenes with non-classical damping: Taylor steps of the first-order system,
bounded through the energy (the ``krylov`` engine).

The state z = (x, v) obeys z' = A z, A = [[0, I], [−M⁻¹K, −M⁻¹C]], held sparse. Time is cut
into steps of length H (θ = H·ν ≤ Limits.krylov_step_norm, ν below); each step sums m
terms of the Taylor series of exp(HA), one sparse product each, the large ones formed to
about 2^-70 and the rest in float64 (:mod:`.krylov_steps`, :mod:`.krylov_data`). The cost
is about 12 sparse products per unit of t·ν at θ = 5 (a double-double term counting 2.5),
independent of the number of output times, which each cost one float64 sum of the step's
terms.

Scenes held by the ground (compliance √R finite) whose damping is light against ν take
long Chebyshev (Bessel) steps instead, X = ν_c·H up to Limits.krylov_bessel_norm = 64,
about two products per unit of t·ν_c with the values cut per time
(:mod:`.krylov_bessel`: the bound from the motion's defect, carried from step to step the
same way as below).

The error bound (:meth:`KrylovMotion.evaluate`)
-----------------------------------------------
It rests on the energy seminorm N(z)² = vᵀMv + xᵀKx, which the exact motion never
increases when M is diagonal positive, K symmetric positive semidefinite and C + Cᵀ
positive semidefinite (dN²/dt = −vᵀ(C + Cᵀ)v). :func:`krylov_refusal` checks this
exactly (symmetric, diagonally dominant matrices with a non-negative diagonal: every
spring and dashpot network). In energy coordinates A is [[0, P], [−Pᵀ, −D]] with
‖P‖₂² = λ_max(M⁻¹K) and D = M^{−1/2}CM^{−1/2}, so N(Az) ≤ ν N(z) with
ν = √(p² + d²/4) + d/2 for p ≥ ‖P‖₂, d ≥ ‖D‖₂ bounded by Collatz–Wielandt or Gershgorin
sums (:func:`.krylov_entries.spectral_bound`). A step from the computed state ẑ_j commits a local error δ_j
(truncation after m terms, at most θ·N(s_m)/(m + 1)! from the last computed term
s_m = (H·U_{m−1}, U_m), an a posteriori bound; the terms' rounding; the rounding of their
sum, bounded per coordinate and carried into N through xᵀKx ≤ Σ_i s_i x_i² and
vᵀMv ≤ Σ_i m_i v_i², s_i = Σ_j |K_ij|: :mod:`.krylov_steps`), and the error
e_j = ẑ_j − z(jH) obeys e_{j+1} = exp(HA)e_j + δ_j, so

* E_{j+1} = E_j + N(δ_j) bounds N(e_{j+1}): errors add, never grow;
* the x part, X_{j+1} = min(X_j + H·E_j/√m_min, √R·E_j) + ‖(δ_j)_x‖∞: x(t) = x(b) + ∫v
  with |v_i| ≤ N/√m_i (rigid-body motion allowed), or |x_i| ≤ √R·√(xᵀKx) with R the
  compliance bound of :mod:`.krylov_data` where every part of the scene is held;
* a value at b + s inside step j adds the propagated error (the same min at s), the
  truncation and rounding of the terms, the float64 rounding of its own sum
  (Σ_k (3k + 4)u·|ω_k|·‖U_{k−1}‖∞) and u·s of the time's own rounding times the speed bound.

The bound is the same for every coordinate; x'' comes from the equation M x'' = −Kx − Cx'
with the rounding of that product added.
"""

from __future__ import annotations

import math

from ..limits import limits
from ..model.scene import Scene
from .first_order import rational_entries
from .krylov_bessel import BesselMotion, bessel_data
from .krylov_data import KrylovData, krylov_data, scene_refusal, spectral_bound, step_length
from .krylov_march import KrylovMotion

__all__ = ["KrylovData", "KrylovMotion", "krylov_refusal", "krylov_cost", "krylov_data",
           "krylov_motion"]

# ----------------------------------------------------------------------------- planning


def _steps(scene: Scene, t_max: float) -> float:
    return math.floor(max(t_max, 0.0) / step_length(spectral_bound(scene))) + 1


def krylov_refusal(scene: Scene, *, t_max: float = 0.0, count: int = 0,
                   order: int = 0) -> str | None:
    """None when the engine can serve this request, else why not (one sentence).

    It needs rational entries, no forcing, a diagonal positive M, a symmetric K and K, C
    whose symmetric parts are diagonally dominant with a non-negative diagonal (K ⪰ 0,
    C + Cᵀ ⪰ 0, proved exactly): the energy then never grows. A last time beyond
    Limits.krylov_max_steps steps is refused (``count`` does not matter: the cost per time
    is one float64 sum).

    Examples
    --------
    >>> ok = Scene.from_matrices(M=[[1, 0], [0, 2]], C=[[1, 0], [0, 0]], K=[[2, -1], [-1, 1]],
    ...                          x0=[1, 0], v0=[0, 0])
    >>> krylov_refusal(ok) is None
    True
    >>> krylov_refusal(ok, t_max=1e9).endswith("Taylor steps > Limits.krylov_max_steps = 200,000")
    True
    >>> krylov_refusal(Scene.from_matrices(M=[[1]], C=[[-1]], K=[[1]], x0=[1], v0=[0]))
    'C + Cᵀ is not diagonally dominant with a non-negative diagonal (C + Cᵀ ⪰ 0 is not proved)'
    """
    why = scene_refusal(scene)
    if why is not None:
        return why
    if order > 2:
        return f"derivative order {order} > 2"
    steps = _steps(scene, t_max)
    if steps > limits().krylov_max_steps:
        return (f"t = {t_max:g} needs {steps:,.0f} Taylor steps > Limits.krylov_max_steps = "
                f"{limits().krylov_max_steps:,}")
    return None


#: Cost constants (seconds, one core of the development machine; see krylov_cost).
_BUILD = (1e-3, 5e-6)              # fixed, per nonzero of M, C, K (reading and checks)
_STEP = (3e-4, 2.5e-9, 2e-8)       # per step: fixed, per term·nonzero, per term·coordinate
_TIME = (2e-5, 2.5e-9)             # per time: fixed, per term·coordinate


def krylov_cost(scene: Scene, *, t_max: float = 100.0, count: int = 100, order: int = 0) -> float:
    """Estimated seconds of building the engine and evaluating ``count`` times up to
    ``t_max`` (cheap: reads the entries once).

    The model (the planner's, :mod:`laplace_springs.planning.engines`), measured on chains
    and meshes of 1,000 to 10,000 masses (one core): building 1 ms + 5 µs per nonzero of
    M, C, K; then t_max/H + 1 steps of about 60 sparse-product equivalents each (m ≈ 37
    terms at θ = 5, a third of them double-double at 2.5 products), a step costing
    0.3 ms + 60·(2.5 ns·nnz + 20 ns·n); and per time 20 µs + 2.5 ns·m·n (a third more
    per derivative order).

    >>> scene = Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[1], v0=[0])
    >>> 0 < krylov_cost(scene, t_max=10.0, count=100) < 0.1
    True
    """
    n = scene.n
    nnz = sum(len(rational_entries(scene, name) or {}) for name in ("M", "C", "K"))
    products, terms = 60.0, 37.0
    step = _STEP[0] + products * (_STEP[1] * nnz + _STEP[2] * n)
    per_time = (_TIME[0] + _TIME[1] * terms * n) * (1 + order / 3)
    return _BUILD[0] + _BUILD[1] * nnz + _steps(scene, t_max) * step + count * per_time


def krylov_motion(scene: Scene) -> KrylovMotion:
    """The motion of a scene :func:`krylov_refusal` accepts (SceneError if not): long
    Bessel steps (:mod:`.krylov_bessel`) where the scene is held by the ground and lightly
    damped, else Taylor steps.

    >>> krylov_motion(Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[1], v0=[0])).m > 4
    True
    """
    if limits().krylov_bessel_norm > 0:
        data = bessel_data(scene)
        if data is not None:
            return BesselMotion(data)
    return KrylovMotion(krylov_data(scene))
