"""The sweep's error estimates bound the true error: every value of the vectorised kernel
(both the cheap and the refined estimate, isolated roots and clusters) against a 40-digit
mpmath evaluation of the residue formula, and against the per-set exact solver
``ls.solve(scene.subs(...)).evaluate(...)`` with its own bound."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.sweeps import sweep
from laplace_springs.sweeps.chunks import evaluate_rows
from laplace_springs.sweeps.compile import compile_scene, parameter_rows
from laplace_springs.sweeps.kernels import UNIT, UNIT_EXTENDED, evaluate_block

TIMES = np.linspace(0.0, 15.0, 31)
DPS = 40


def _grounded():
    return ls.Scene.from_components(
        masses={"m1": 1, "m2": 1},
        springs={"k1": ("wall", "m1", "k1"), "k2": ("m1", "m2", "k2")},
        dashpots={"c": ("wall", "m1", "c")},
        x0=[1, 0], v0=[0, 1], parameters=["k1", "k2", "c"])


def _symmetric():
    """Out-of-phase mode λ² + 2cλ + k1 + 2k2: critical exactly when c² = k1 + 2k2."""
    return ls.Scene.from_components(
        masses={"m1": 1, "m2": 1},
        springs={"s1": ("wall", "m1", "k1"), "s2": ("m2", "wall", "k1"), "s3": ("m1", "m2", "k2")},
        dashpots={"d": ("m1", "m2", "c")},
        x0=[1, 0], v0=[0, 1], parameters=["k1", "k2", "c"])


def _mp_residues(compiled, row, times, derivative=0):
    """x (or x^(derivative)) by the residue formula in 40-digit arithmetic, from the exact
    coefficients at the parameters' binary values (roots by mpmath.polyroots)."""
    with mpmath.workdps(DPS):
        args = [mpmath.mpf(float(v)) for v in row]
        den_f = sp.lambdify(list(compiled.symbols), list(compiled.denominator), modules="mpmath")
        den = [mpmath.mpf(c) for c in den_f(*args)]
        nums = []
        for coefficients in compiled.numerators:
            f = sp.lambdify(list(compiled.symbols), list(coefficients), modules="mpmath")
            nums.append([mpmath.mpf(c) for c in f(*args)] + [mpmath.mpf(0)] * derivative)
        roots = mpmath.polyroots(den, maxsteps=400, extraprec=4 * DPS * 3.33)
        out = np.zeros((len(nums), len(times)))
        for i, num in enumerate(nums):
            residues = [mpmath.polyval(num, r) / (den[0] * mpmath.fprod(r - q for k, q in enumerate(roots)
                                                                         if k != j))
                        for j, r in enumerate(roots)]
            for m, t in enumerate(times):
                tt = mpmath.mpf(float(t))
                out[i, m] = float(mpmath.re(mpmath.fsum(c * mpmath.exp(r * tt)
                                                        for c, r in zip(residues, roots))))
        return out


def _sets(kind, rng, P):
    if kind == "forced":  # cos(3t/2) on a mass from rest: k near 2.25 is resonance, c down to 1e-6
        scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[0], v0=[0],
                                       forcing=["cos(3*t/2)"], parameters=["k", "c"])
        half = P // 2
        near = 10.0 ** rng.uniform(-9, -1, P - half) * rng.choice([-1, 1], P - half)
        k = 2.25 * (1 + np.concatenate([rng.uniform(-0.2, 0.2, half), near]))
        c = np.where(np.arange(P) % 3 == 0, 10.0 ** rng.uniform(-6, -2, P), rng.uniform(0.01, 0.5, P))
        return scene, {"k": k, "c": c}
    if kind == "grounded":
        values = {"k1": rng.uniform(0.5, 3, P), "k2": rng.uniform(0.5, 3, P), "c": rng.uniform(0.01, 4, P)}
        return _grounded(), values
    k1, k2 = rng.uniform(0.2, 4, P), rng.uniform(0.2, 3, P)
    # relative distances from critical damping: exact, tiny (clusters), near the
    # cluster/isolated boundary (close isolated pairs) and far
    offsets = np.array([0, 1e-12, 1e-9, 1e-6, 1e-4, 1e-3, 1e-2, 3e-2, 6e-2, 0.1, 0.3, -1e-6, -1e-3, -0.05])
    c = np.sqrt(k1 + 2 * k2) * (1 + offsets[np.arange(P) % offsets.size])
    c[::3] = rng.uniform(0.02, 4, c[::3].size)
    return _symmetric(), {"k1": k1, "k2": k2, "c": c}


@pytest.mark.parametrize("kind", ["grounded", "symmetric", "forced"])
def test_estimates_bound_the_40_digit_residue_formula(kind):
    rng = np.random.default_rng({"grounded": 21, "symmetric": 22, "forced": 23}[kind])
    scene, values = _sets(kind, rng, 84 if kind != "forced" else 42)
    compiled = compile_scene(scene)
    rows = parameter_rows(compiled, values)
    den, num, den_abs, num_abs = compiled.coefficients(rows)
    counts = compiled.rounding_counts()
    wide = compiled.coefficients_extended(rows)
    assert wide is not None
    derivatives = (0, 1) if kind != "forced" else (0, 2)
    # float64 coefficients (as for scenes with irrational constants), and extended ones
    for derivative, extended in [(d, e) for d in derivatives for e in (None, wide)]:
        unit = UNIT if extended is None else UNIT_EXTENDED
        rounding = (unit * counts[0] * den_abs, unit * counts[1] * num_abs)
        cheap = evaluate_block(den, num, den_abs, num_abs, TIMES, derivative, coefficient_error=rounding,
                               extended=extended)
        fine = evaluate_block(den, num, den_abs, num_abs, TIMES, derivative, coefficient_error=rounding,
                              refine=True, extended=extended)
        assert not cheap.suspect.any()
        ratios = []
        for b in range(len(rows)):
            reference = _mp_residues(compiled, rows[b], TIMES, derivative)
            true = np.abs(fine.values[b] - reference)
            slack = UNIT * np.abs(reference)  # the reference's own rounding to float64
            assert np.all(true <= fine.error[b] + slack), (kind, derivative, extended is None, b, rows[b])
            assert np.all(np.abs(cheap.values[b] - reference) <= cheap.error[b] + slack), (b, rows[b])
            assert np.all(fine.error[b] <= cheap.error[b] * (1 + 1e-12))
            scale = max(np.max(np.abs(reference)), 1.0)
            ratios.append(np.max(fine.error[b]) / max(np.max(true), UNIT * scale))
        # honest, but not absurdly cautious: the refined estimate within ~10^3 of the truth
        assert np.median(ratios) < 300 and np.max(ratios) < 1e4, np.max(ratios)


def test_swept_values_agree_with_the_exact_solver_within_both_bounds():
    rng = np.random.default_rng(5)
    scene, values = _sets("symmetric", rng, 28)
    result = sweep(scene, values, TIMES, return_error=True)
    assert result.exact_sets.size == 0
    for b in range(len(values["c"])):
        point = {name: float(array[b]) for name, array in values.items()}
        exact, bound = ls.solve(scene.subs(point)).evaluate(TIMES, return_error=True)
        difference = np.abs(result.values[b] - exact)
        assert np.all(difference <= result.error[b] + bound + UNIT * np.abs(exact)), (b, point)


def test_close_pairs_need_no_exact_solver():
    """Random two-mass sets: the refined estimate accepts the sets whose cheap estimate
    counts the 1/gap terms of a close pair (the former fallbacks), and the estimates
    still bound the error (checked above)."""
    rng = np.random.default_rng(0)
    scene, values = _sets("grounded", rng, 4000)
    compiled = compile_scene(scene)
    rows = parameter_rows(compiled, values)
    _, _, exact_mask, _, set_error = evaluate_rows(compiled, rows, np.linspace(0, 20, 100))
    assert exact_mask.sum() <= 2 and np.all(set_error <= 1e-13)


@pytest.mark.parametrize("start", [(1, 0), (0, 1), (1, -1)])
def test_bounds_hold_at_tiny_values_near_critical_damping(start):
    """Issue 21: x'' + c x' + x = 0 with c just above critical (2.0008 … 2.01), values
    decayed to 1e-22 … 1e-54: every entry's bound is above its true error. The set means
    the decimal value of c (as Scene.subs reads a float), so the reference is the closed
    form at that decimal in 40 digits; x, x' and x''."""
    x0, v0 = start
    scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[[1]], x0=[x0], v0=[v0], parameters=["c"])
    cs = np.array([2.0008, 2.0033, 2.0051, 2.0077, 2.0094, 2.01])
    times = np.linspace(0, 130, 1301)
    for order in (0, 1, 2):
        result = sweep(scene, {"c": cs}, times, return_error=True, derivative=order)
        with mpmath.workdps(DPS):
            for b, c in enumerate(cs):
                C = mpmath.mpf(repr(float(c)))
                d = mpmath.sqrt(C * C / 4 - 1)
                r1, r2 = -C / 2 + d, -C / 2 - d
                A, B = (v0 - r2 * x0) / (r1 - r2), (r1 * x0 - v0) / (r1 - r2)
                reference = np.array([float(A * r1**order * mpmath.exp(r1 * t) + B * r2**order
                                            * mpmath.exp(r2 * t)) for t in map(mpmath.mpf, times)])
                true = np.abs(result.values[b, 0] - reference)
                assert np.all(true <= result.error[b, 0] + UNIT * np.abs(reference)), (c, order)
