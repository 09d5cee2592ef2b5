"""The certified route (exact polynomials, certified roots, ball arithmetic) and the
escalation of the modal route to it.

References: python-flint's certified arb matrix exponential of the first-order system
(reference_motion_arb, no roots and no eigen-decomposition) and textbook closed forms.
"""

from __future__ import annotations

from itertools import pairwise

import mpmath
import numpy as np
import pytest

from laplace_springs import CertifiedSolution, ModalSolution, Scene, SceneError, solve
from laplace_springs.bench.reference import reference_motion_arb, relative_error
from laplace_springs.numeric.certified import certified_poles


def chain(n: int, *, stiff: str = "1", light: str = "1", damping: str = "1/100",
          ends=("wall", "wall")) -> Scene:
    """n masses between the ends; odd springs have stiffness ``stiff``, odd masses ``light``."""
    masses = {f"m{i + 1}": (light if i % 2 else "1") for i in range(n)}
    nodes = [ends[0], *masses, ends[1]]
    links = [(a, b) for a, b in pairwise(nodes) if "free" not in (a, b)]
    springs = {f"k{i + 1}": (a, b, stiff if i % 2 else "1") for i, (a, b) in enumerate(links)}
    dashpots = {f"c{i + 1}": (a, b, damping) for i, (a, b) in enumerate(links)}
    return Scene.from_components(masses=masses, springs=springs, dashpots=dashpots,
                                 x0=[1] + [0] * (n - 1), v0=[0] * (n - 1) + ["1/2"])


def _check(scene, times, bound=1e-14, sol=None):
    """``sol`` (auto by default) within ``bound`` of the arb reference and within its bounds."""
    sol = solve(scene) if sol is None else sol
    values, errors = sol.evaluate(times, return_error=True)
    reference = reference_motion_arb(scene, list(times), digits=25)
    actual = np.abs(values - reference.astype(float))
    assert relative_error(values, reference) < bound
    assert np.all(actual <= errors)
    return sol


def test_auto_certifies_a_stiff_twenty_mass_chain():
    # springs 1 and 1e8 alternate: float64 eigenvectors lose digits, the bound says so
    scene = chain(20, stiff="100000000")
    sol = _check(scene, np.linspace(0, 20, 12))
    assert isinstance(sol, CertifiedSolution) and sol.method == "certified"
    assert sol.escalation == "ball"  # times whose float64 bound misses go to ball arithmetic


def test_mass_ratio_one_in_a_million_over_a_long_horizon():
    _check(chain(10, light="1/1000000"), np.array([0.0, 0.5, 3.0, 100.0, 2500.0]))


def test_massless_node_held_by_a_dashpot():
    # a Maxwell element (spring in series with a dashpot) between two stiff-coupled masses
    scene = Scene.from_components(
        masses={"m1": 1, "m2": "1/1000", "n": 0},
        springs={"k1": ("wall", "m1", 1), "k2": ("m1", "m2", 10**8), "k3": ("m2", "n", 3)},
        dashpots={"c1": ("n", "wall", "1/2")}, x0=[1, 0, 0], v0=[0, 1, 0])
    _check(scene, np.array([0.0, 0.25, 2.0, 9.0]), 1e-14, solve(scene, method="certified"))


def test_verify_passes():
    assert solve(chain(6, stiff="1000000"), method="certified").verify()


def test_critical_damping_is_a_double_pole_with_its_t_term():
    # x'' + 2x' + x = 0, x(0) = 1, x'(0) = -3: x = (1 - 2t) e^{-t} (textbook)
    scene = Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[-3])
    assert certified_poles(scene).factors[0][1] == 2
    sol = solve(scene, method="certified")
    times = ["0", "0.5", "3", "40"]
    values, errors = sol.evaluate(times, dps=40, return_error=True)
    with mpmath.workdps(60):
        for value, error, tv in zip(values[0], errors[0], times):
            exact = (1 - 2 * mpmath.mpf(tv)) * mpmath.exp(-mpmath.mpf(tv))
            assert abs(value - exact) <= error <= mpmath.mpf(10) ** -39


def test_repeated_frequencies_of_two_identical_chains():
    # block-diagonal copies: every nonzero eigenvalue is double but semisimple, so the
    # common factor of Δ and the numerators cancels and no t-terms appear
    one = chain(3, damping="0")
    M, K = one.M, one.K
    n = one.n
    def big(A):
        return [[A[i % n, j % n] if i // n == j // n else 0 for j in range(2 * n)]
                         for i in range(2 * n)]
    scene = Scene.from_matrices(M=big(M), K=big(K), x0=[1, 0, 0, 0, "1/2", 0], v0=[0] * 6)
    data = certified_poles(scene)
    assert all(multiplicity == 1 for _, multiplicity in data.factors)
    _check(scene, np.array([0.0, 1.0, 10.0, 1000.0]), 1e-14, solve(scene, method="certified"))


def test_free_free_stiff_chain_has_its_rigid_drift():
    # springs 1 and 1e8 alternate, no walls: λ = 0 is a double pole (drift offset + slope·t)
    scene = chain(20, stiff="100000000", ends=("free", "free"))
    sol = _check(scene, np.array([0.0, 0.3, 2.0, 7.5, 40.0]), sol=solve(scene, method="certified"))
    assert np.sum(np.abs(sol.poles) < 1e-12) == 1  # one node: the double pole at 0


def test_two_free_masses_joined_by_a_dashpot_only():
    scene = Scene.from_matrices(M=[[1, 0], [0, 3]], C=[["1/2", "-1/2"], ["-1/2", "1/2"]],
                                x0=[1, -1], v0=[2, 0])
    sol = _check(scene, np.array([0.0, 1.0, 10.0, 100.0]), 1e-15, solve(scene, method="certified"))
    assert sol.verify()


def test_huge_phases_are_computed_at_the_precision_they_need():
    # x'' + 2x = 0: cos(√2 t) at t = 1e30 needs 100 + 53 bits of √2
    sol = solve(Scene.from_matrices(M=[[1]], K=[[2]], x0=[1], v0=[0]), method="certified")
    times = [1e20, 1e25, 1e30]
    values, errors = sol.evaluate(times, return_error=True)
    with mpmath.workdps(120):
        exact = [float(mpmath.cos(mpmath.sqrt(2) * mpmath.mpf(tv))) for tv in times]
    assert np.all(np.abs(values[0] - exact) <= errors[0])
    assert errors.max() <= 1e-14  # a float64 bound never claims more than 14 digits


@pytest.mark.parametrize("exponent", [160, 300])
def test_stiffness_beyond_float64_is_exact(exponent):
    # K = 10^e: ω = 10^(e/2); x(0) = 1 and x(1) = cos ω to the last bit
    scene = Scene.from_matrices(M=[[1]], K=[[f"1e{exponent}"]], x0=[1], v0=[0])
    values = solve(scene, method="certified").evaluate([0.0, 1.0])
    with mpmath.workdps(exponent // 2 + 40):
        exact = float(mpmath.cos(mpmath.mpf(10) ** (exponent // 2)))
    assert values[0, 0] == 1.0 and abs(values[0, 1] - exact) <= 1e-15


def test_forced_and_symbolic_scenes_are_refused_by_name():
    scene = Scene.from_matrices(M=[[1]], K=[[4]], x0=[0], v0=[0], forcing=["cos(t)"])
    with pytest.raises(SceneError, match="certified route cannot take this scene: the scene is forced"):
        solve(scene, method="certified")
    with pytest.raises(SceneError, match=r"K\[0,0\] = k"):
        solve(Scene.from_matrices(M=[[1]], K=[["k"]], x0=[1], v0=[0], parameters=["k"]), method="certified")


# ----------------------------------------------------------------------------- escalation


def test_well_conditioned_large_scenes_stay_on_a_float64_engine():
    sol = solve(chain(12))
    assert isinstance(sol, ModalSolution) and sol.method in ("classical", "chebyshev", "modal")
    assert "certified" in sol.plan([0.0, 1.0]).chain  # a time whose bound misses goes there


def test_modal_escalates_a_long_horizon_to_certified():
    # a lightly damped 20-mass chain: float64 rates drift by ~1e-15·t; at t = 1e5 the
    # modal bound misses the target and those times are certified, alone
    scene = chain(20, damping="1/1000")
    sol = solve(scene, method="modal")
    assert isinstance(sol, ModalSolution)
    times = np.array([0.0, 1.0, 3.0e4, 1.0e5])
    _check(scene, times, 1e-13, sol)
    engines = sol.evaluate(times, return_report=True)[1].engines
    assert engines[0] == sol.method and engines[-1] != sol.method  # t = 1e5 was recomputed
    alone = sol.evaluate(times[-1:])[0, 0]  # the same value, whatever else is asked
    assert abs(alone - sol.evaluate(times)[0, -1]) <= 4 * np.finfo(float).eps * abs(alone)


def test_modal_block_spanning_decades_stays_finite():
    # mass ratio 1e-6 in a 20-mass chain: one block holds poles from -2e4 to ~0; its
    # exponential is taken relative to its rightmost rate (it used to overflow to NaN)
    scene = chain(20, light="1/1000000")
    times = np.linspace(0.0, 20.0, 9)
    motion = solve(scene, method="modal").motion
    values, bounds = motion.values(times), motion.bound(times)
    reference = reference_motion_arb(scene, list(times), digits=20).astype(float)
    assert np.all(np.isfinite(values)) and np.all(np.abs(values - reference) <= bounds)


@pytest.mark.parametrize("method", ["auto", "certified"])
def test_a_residue_that_underflows_keeps_its_error_in_the_derivatives(method) -> None:
    """x'' + 1e300 x' + x = 0, x(0) = 1: the fast pole's residue is −1e-600 (its ball holds
    0), and its x' coefficient λ·residue = 1e-300 was taken as exactly 0 with a bound of
    1e-314 at t = 0, where x'(0) = v0 = 0 and the engine gave −1e-300. The reference: the
    roots of λ² + 1e300 λ + 1 at 700 digits, by hand."""
    scene = Scene.from_matrices(M=[[1]], C=[["1e300"]], K=[[1]], x0=[1], v0=[0])
    times = [0.0, 1e-300, 1.0]
    values, bounds = solve(scene, method=method).evaluate(times, derivative=1, return_error=True)
    with mpmath.workdps(700):
        c = mpmath.mpf(10) ** 300
        root = mpmath.sqrt(c * c - 4)
        fast, slow = (-c - root) / 2, (-c + root) / 2
        B = fast / (fast - slow)          # A + B = 1, A·fast + B·slow = 0
        A = 1 - B
        exact = [A * fast * mpmath.exp(fast * t) + B * slow * mpmath.exp(slow * t)
                 for t in map(mpmath.mpf, times)]
        errors = [abs(mpmath.mpf(float(v)) - e) for v, e in zip(values[0], exact)]
    assert all(error <= bound for error, bound in zip(errors, bounds[0])), (errors, bounds)
