"""Sweeps of scenes under any forcing the solver takes: periodic, sampled, delayed formula
forcing and moving supports. Each swept set against the same set solved alone and against
independent references: the exact propagation of the state over the pieces on which the
force is a constant or a straight line, in 40-digit mpmath (matrix exponentials of the
augmented first-order system), sharing no code with the package."""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

import laplace_springs as ls

DPS = 40


def _propagate(M, C, K, z0, pieces, times):
    """x(t) of M x'' + C x' + K x = f(t) by exact propagation over ``pieces``: a list of
    (start, f(start), slope) with f linear on [start, next start); 40 digits."""
    n = len(M)
    with mpmath.workdps(DPS):
        Mi = mpmath.matrix(M) ** -1
        A = mpmath.zeros(2 * n + 2 * n)
        for i in range(n):
            A[i, n + i] = 1
        MK, MC = -Mi * mpmath.matrix(K), -Mi * mpmath.matrix(C)
        for i in range(n):
            for j in range(n):
                A[n + i, j], A[n + i, n + j] = MK[i, j], MC[i, j]
            for j in range(n):  # the force vector and its slope as extra states
                A[n + i, 2 * n + j] = Mi[i, j]
                A[2 * n + j, 3 * n + j] = 1
        out = np.zeros((n, len(times)))
        starts = [mpmath.mpf(p[0]) for p in pieces] + [mpmath.inf]
        state = _reset(mpmath.matrix([*z0, *([0] * 2 * n)]), pieces[0], n)
        k = 0
        order = np.argsort(times)
        clock = mpmath.mpf(0)
        for index in order:
            t = mpmath.mpf(float(times[index]))
            while starts[k + 1] <= t:
                state = mpmath.expm(A * (starts[k + 1] - clock)) * state
                clock = starts[k + 1]
                k += 1
                state = _reset(state, pieces[k], n)
            value = mpmath.expm(A * (t - clock)) * state
            out[:, index] = [float(value[i]) for i in range(n)]
        return out


def _reset(state, piece, n):
    """At the start of a piece the force takes its value there and its new slope."""
    _, value, slope = piece
    for j in range(n):
        state[2 * n + j] = mpmath.mpf(value[j])
        state[3 * n + j] = mpmath.mpf(slope[j])
    return state


def _check(result, scene, sets, times, references):
    for b, reference in references.items():
        alone, bound = ls.solve(scene.subs(sets[b])).evaluate(times, return_error=True)
        scale = max(float(np.max(np.abs(reference))), 1e-300)
        assert np.max(np.abs(result.values[b] - reference)) <= 1e-10 * scale, b
        assert np.all(np.abs(result.values[b] - reference) <= result.error[b] + 1e-15 * scale), b
        assert np.max(np.abs(result.values[b] - alone)) <= 1e-12 * scale, b


def test_square_wave_sets_are_solved_not_zeros():
    """The square wave once came back as zeros: each set now equals the exact piecewise
    propagation (a mass on k = 4 with dashpot c, amplitude 1 on the first half of each
    period 2)."""
    scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[[4]], x0=[0], v0=[0],
                                   parameters=["c"], forcing=[ls.square_wave(1, 2)])
    c = [0.5, 1.0, 3.0]
    times = np.array([0.3, 1.0, 2.5, 7.25, 20.0])
    result = ls.sweep(scene, {"c": c}, times, return_error=True)
    assert result.route == "alone" and "periodic" in result.reason
    assert np.all(np.max(np.abs(result.values), axis=(1, 2)) > 0.05)
    pieces = [(k, [1 if k % 2 == 0 else 0], [0]) for k in range(21)]
    references = {b: _propagate([[1]], [[c[b]]], [[4]], [0, 0], pieces, times) for b in range(3)}
    _check(result, scene, [{"c": value} for value in c], times, references)


def test_sampled_force_histories():
    """A measured force (linear interpolation on a non-uniform grid) on a two-mass scene
    with swept stiffness: each set against the exact piecewise-linear propagation."""
    rng = np.random.default_rng(4)
    stamps = np.concatenate([[0.0], np.sort(rng.uniform(0, 6, 14)), [6.0]])
    force = np.sin(stamps) + 0.5
    scene = ls.Scene.from_components(
        masses={"m1": 1, "m2": 2}, springs={"k1": ("wall", "m1", "k"), "k2": ("m1", "m2", 1)},
        dashpots={"c1": ("wall", "m1", "1/5")}, x0=[0, 0], v0=[0, 0], parameters=["k"],
        forcing={"m2": ls.sampled(stamps, force)})
    k = [1.0, 2.5]
    times = np.array([0.5, 3.3, 6.0, 9.0])
    result = ls.sweep(scene, {"k": k}, times, return_error=True)
    assert result.route == "alone" and "sampled" in result.reason
    slopes = np.diff(force) / np.diff(stamps)
    pieces = [(stamps[i], [0, force[i]], [0, slopes[i]]) for i in range(stamps.size - 1)]
    pieces.append((stamps[-1], [0, 0], [0, 0]))  # the history ends: no force after it
    references = {}
    for b, value in enumerate(k):
        K = [[value + 1, -1], [-1, 1]]
        references[b] = _propagate([[1, 0], [0, 2]], [[0.2, 0], [0, 0]], K, [0, 0, 0, 0], pieces, times)
    _check(result, scene, [{"k": value} for value in k], times, references)


def test_delayed_step_and_moving_support():
    """A force switched on at t = 1 (a delay the symbolic compile does not take) on a mass
    whose support also moves: both routes give the per-set solution."""
    scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[[2]], x0=[1], v0=[0], parameters=["c"],
                                   forcing=["Heaviside(t - 1)"])
    c = [0.25, 2.0]
    times = np.array([0.5, 1.0, 1.5, 4.0, 9.0])
    result = ls.sweep(scene, {"c": c}, times, return_error=True)
    pieces = [(0, [0], [0]), (1, [1], [0])]
    references = {b: _propagate([[1]], [[c[b]]], [[2]], [1, 0], pieces, times) for b in range(2)}
    _check(result, scene, [{"c": value} for value in c], times, references)
    shaken = ls.Scene.from_components(masses={"m": 1}, springs={"k": ("floor", "m", "k")},
                                      dashpots={"c": ("floor", "m", "1/2")},
                                      support_motion={"floor": "t/10"}, parameters=["k"])
    k = [1.0, 3.0]
    moved = ls.sweep(shaken, {"k": k}, times, return_error=True)
    assert moved.route == "compiled"
    for b, value in enumerate(k):  # the support moves as t/10: force k t/10 + c/10
        pieces = [(0, [0.05], [value / 10])]
        reference = _propagate([[1]], [[0.5]], [[value]], [0, 0], pieces, times)
        assert np.all(np.abs(moved.values[b] - reference) <= moved.error[b] + 1e-15)


def test_a_set_the_solver_refuses_is_named_or_marked():
    """A square wave from rest at t = 0 is a time the solver cannot bound (scale 0): the
    sweep raises naming the set, or marks it with on_error="nan" (never zeros)."""
    scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[[4]], x0=[0], v0=[0],
                                   parameters=["c"], forcing=[ls.square_wave(1, 2)])
    try:
        ls.solve(scene.subs({"c": 0.5})).evaluate([0.0])
    except ValueError:
        with pytest.raises(ValueError, match="set 0"):
            ls.sweep(scene, {"c": [0.5]}, [0.0, 1.0])
        result = ls.sweep(scene, {"c": [0.5]}, [0.0, 1.0], on_error="nan", return_error=True)
        assert 0 in result.failures and np.all(np.isnan(result.values[0]))
    else:  # the solver takes it now: the sweep agrees with it
        values = ls.sweep(scene, {"c": [0.5]}, [0.0, 1.0])
        assert np.allclose(values[0], ls.solve(scene.subs({"c": 0.5})).evaluate([0.0, 1.0]))
