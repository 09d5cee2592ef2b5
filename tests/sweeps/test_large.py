"""Sweeps beyond the symbolic limit (the batched route): every value against a 40-digit
mpmath matrix exponential of the set's first-order system (no code shared with the
package), every bound above the true error, every set equal to solving it alone; sets the
batched engine cannot bound (rigid-body motion, nearly defective modes) solved alone."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

import laplace_springs as ls
from laplace_springs.model.errors import SceneError

DPS = 40


def _reference(M, C, K, x0, v0, times, order=0):
    """x^(order)(t) from exp(tA) z0 with A = [[0, I], [-M⁻¹K, -M⁻¹C]] in 40 digits."""
    n = len(M)
    with mpmath.workdps(DPS):
        Mi = mpmath.matrix([[mpmath.mpf(str(v)) for v in row] for row in M]) ** -1
        A = mpmath.zeros(2 * n)
        Kq = mpmath.matrix([[mpmath.mpf(str(v)) for v in row] for row in K])
        Cq = mpmath.matrix([[mpmath.mpf(str(v)) for v in row] for row in C])
        MK, MC = -Mi * Kq, -Mi * Cq
        for i in range(n):
            A[i, n + i] = 1
            for j in range(n):
                A[n + i, j], A[n + i, n + j] = MK[i, j], MC[i, j]
        z0 = mpmath.matrix([mpmath.mpf(str(v)) for v in [*x0, *v0]])
        out = np.zeros((n, len(times)))
        for k, t in enumerate(times):
            z = mpmath.expm(A * mpmath.mpf(float(t))) * z0
            for _ in range(order):  # A^order z = (x^(order), x^(order+1))
                z = A * z
            out[:, k] = [float(z[i]) for i in range(n)]
        return out


def _matrices(scene):
    return [[[float(v) for v in row] for row in getattr(scene, name).tolist()] for name in "MCK"]


def _chain(n, free=False):
    masses = {f"m{i}": 1 for i in range(n)}
    springs = {**({} if free else {"k0": ("wall", "m0", "k")}),
               **{f"k{i}": (f"m{i-1}", f"m{i}", 1 if i > 1 or not free else "k") for i in range(1, n)}}
    return ls.Scene.from_components(masses=masses, springs=springs, dashpots={"c": ("wall", "m0", "c")},
                                    x0=[1] + [0] * (n - 1), v0=[0] * n,
                                    parameters={"k": "positive", "c": "nonnegative"})


def _check_against_reference(scene, values, times, result, sets, order=0):
    for b in sets:
        point = {name: array[b] for name, array in values.items()}
        numeric = scene.subs(point)
        M, C, K = _matrices(numeric)
        x0 = [float(v) for v in numeric.x0]
        v0 = [float(v) for v in numeric.v0]
        reference = _reference(M, C, K, x0, v0, times, order)
        true = np.abs(result.values[b] - reference)
        slack = 2.0**-53 * np.abs(reference)  # the reference's own rounding to float64
        assert np.all(true <= result.error[b] + slack), (b, point, float(np.max(true / result.error[b])))
        scale = max(float(np.max(np.abs(reference))), 1.0)
        assert np.max(true) <= 1e-13 * scale, b
        alone = ls.solve(numeric).evaluate(times, derivative=order)
        assert np.max(np.abs(result.values[b] - alone)) <= 1e-12 * scale, b


def test_twelve_mass_chain_against_40_digit_exponentials():
    scene = _chain(12)
    rng = np.random.default_rng(7)
    P = 60
    values = {"k": rng.uniform(0.2, 5, P), "c": rng.uniform(0, 2, P)}
    values["c"][3] = 0.0  # undamped: purely imaginary modes
    times = np.array([0.0, 0.7, 5.0, 30.0, 150.0])
    result = ls.sweep(scene, values, times, return_error=True)
    assert result.route == "batched" and result.exact_sets.size <= 2
    assert np.all(result.set_error <= 1e-13)
    _check_against_reference(scene, values, times, result, [0, 3, 17, 41])


def test_a_network_with_parametric_masses_and_derivatives():
    """A 15-mass network (springs to the wall and between neighbours two apart, three
    dashpots, a tuned mass on the last node): masses, stiffness and damping swept."""
    n = 15
    masses = {f"m{i}": ("m" if i == n - 1 else 1 + i % 3) for i in range(n)}
    springs = {f"w{i}": ("wall", f"m{i}", 2) for i in range(0, n, 4)}
    springs.update({f"a{i}": (f"m{i}", f"m{i+1}", "k") for i in range(n - 1)})
    springs.update({f"b{i}": (f"m{i}", f"m{i+2}", "1/2") for i in range(0, n - 2, 3)})
    dashpots = {"d0": ("wall", "m0", "c"), "d1": (f"m{n-2}", f"m{n-1}", "c/4"), "d2": ("m5", "m7", "1/10")}
    scene = ls.Scene.from_components(masses=masses, springs=springs, dashpots=dashpots,
                                     x0=[0] * (n - 1) + [1], v0=[1] + [0] * (n - 1),
                                     parameters={"m": "positive", "k": "positive", "c": "nonnegative"})
    rng = np.random.default_rng(8)
    P = 12
    values = {"m": rng.uniform(0.05, 0.3, P), "k": rng.uniform(0.5, 3, P), "c": rng.uniform(0.05, 1, P)}
    times = np.array([0.0, 2.0, 25.0])
    for order in (0, 1, 2):
        result = ls.sweep(scene, values, times, return_error=True, derivative=order)
        assert result.route == "batched"
        _check_against_reference(scene, values, times, result, [0, 5], order)


def test_nearly_defective_and_rigid_sets_are_solved_alone_or_bounded():
    """One mass on a spring and dashpot at the wall of a 10-mass chain: c near the value
    that makes a mode critical, and a free-free chain (a rigid-body mode: a defective
    double eigenvalue 0): every bound holds, and sets the engine cannot bound are solved
    alone."""
    scene = _chain(10)
    c = np.array([1e-9, 1.0, 2.0, 1.999999, 2.000001, 50.0, 1e3])
    values = {"k": np.full(c.size, 1.0), "c": c}
    times = np.array([0.0, 1.0, 8.0, 60.0])
    result = ls.sweep(scene, values, times, return_error=True)
    _check_against_reference(scene, values, times, result, range(c.size))
    free = _chain(9, free=True)  # no spring to the wall: with c = 0 a free rigid-body drift
    loose = {"k": np.array([0.5, 2.0]), "c": np.array([0.3, 0.0])}
    result = ls.sweep(free, loose, times, return_error=True)
    assert result.route == "batched" and 1 in result.exact_sets
    for b in range(2):
        alone, bound = ls.solve(free.subs({"k": loose["k"][b], "c": loose["c"][b]})).evaluate(
            times, return_error=True)
        assert np.all(np.abs(result.values[b] - alone) <= result.error[b] + bound)


def test_two_hundred_masses_equal_the_sets_solved_alone():
    scene = _chain(200)
    values = {"k": [0.7, 3.0], "c": [0.05, 1.5]}
    times = np.array([0.0, 3.0, 40.0])
    result = ls.sweep(scene, values, times, return_error=True, outputs=["x1", "x100", "x200"])
    assert result.route == "batched"
    for b in range(2):
        alone, bound = ls.solve(scene.subs({"k": values["k"][b], "c": values["c"][b]})).evaluate(
            times, return_error=True)
        rows = [0, 99, 199]
        assert np.all(np.abs(result.values[b] - alone[rows]) <= result.error[b] + bound[rows])
        assert np.max(np.abs(result.values[b] - alone[rows])) <= 1e-12
        assert np.max(result.error[b]) <= 1e-13


def test_every_set_is_held_to_the_checks_of_subs():
    """Issue 22: a negative mass declared real is refused, as Scene.subs refuses it; a
    spring that becomes negative too; a mass that vanishes (a massless node) is checked
    exactly."""
    scene = ls.Scene.from_matrices(M=[["m", 0], [0, 1]], C=[[0, 0], [0, 1]], K=[[2, -1], [-1, 1]],
                                   x0=[1, 0], v0=[0, 0], parameters={"m": "real"})
    with pytest.raises(SceneError, match="subs|positive"):
        scene.subs({"m": -1})
    with pytest.raises(SceneError, match=r"set 2 \(m = -1.0\): mass M\[0,0\] must be positive"):
        ls.sweep(scene, {"m": [1.0, 2.0, -1.0]}, [0.0, 1.0])
    springs = ls.Scene.from_components(masses={"a": 1}, springs={"s": ("wall", "a", "k - 1")},
                                       x0=[1], v0=[0], parameters={"k": "real"})
    with pytest.raises(SceneError, match=r"set 1 \(k = 0.5\).*spring 's' becomes"):
        ls.sweep(springs, {"k": [2.0, 0.5]}, [1.0])
    zero = ls.sweep(scene, {"m": [0.0, 1.0]}, [0.5, 1.0], return_error=True)  # massless node
    for b, m in enumerate((0, 1)):
        alone = ls.solve(scene.subs({"m": m})).evaluate([0.5, 1.0])
        assert np.allclose(zero.values[b], alone, rtol=0, atol=1e-13)
