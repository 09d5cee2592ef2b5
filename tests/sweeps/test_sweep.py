"""ls.sweep against independent routes: the exact solver per set (ls.solve(scene.subs(...)))
and textbook formulas."""

from __future__ import annotations

import numpy as np
import pytest

import laplace_springs as ls
from laplace_springs.model.errors import SceneError
from laplace_springs.sweeps import (
    grid,
    peak_amplitude,
    peak_support_force,
    sample_parameters,
    settling_time,
    steady_state_amplitudes,
    summarize,
    sweep,
)

TIMES = np.linspace(0.0, 12.0, 40)


def _per_set(scene, values, b, times, derivative=0):
    point = {name: float(np.asarray(array)[b]) for name, array in values.items()}
    return ls.solve(scene.subs(point)).evaluate(times, derivative=derivative)


def _relative(values, reference, floor):
    scale = np.maximum(np.max(np.abs(reference), axis=0), floor)
    return float(np.max(np.abs(values - reference) / scale))


@pytest.fixture(scope="module")
def grounded():
    """Masses 1, springs k1 (wall-m1), k2 (m1-m2), one dashpot c (wall-m1)."""
    return ls.Scene.from_components(
        masses={"m1": 1, "m2": 1},
        springs={"k1": ("wall", "m1", "k1"), "k2": ("m1", "m2", "k2")},
        dashpots={"c": ("wall", "m1", "c")},
        x0=[1, 0], v0=[0, 1], parameters=["k1", "k2", "c"])


@pytest.fixture(scope="module")
def symmetric():
    """Masses 1 between two walls (springs k1), coupled by k2 and a dashpot c.

    The out-of-phase mode has λ² + 2cλ + k1 + 2k2: critical exactly when c² = k1 + 2k2.
    """
    return ls.Scene.from_components(
        masses={"m1": 1, "m2": 1},
        springs={"s1": ("wall", "m1", "k1"), "s2": ("m2", "wall", "k1"), "s3": ("m1", "m2", "k2")},
        dashpots={"d": ("m1", "m2", "c")},
        x0=[1, 0], v0=[0, 1], parameters=["k1", "k2", "c"])


CRITICAL = {"k1": [1, 2, 3, 0.25, 4, 0.5], "k2": [1.5, 1, 0.5, 0.375, 2.5, 0.25],
            "c": [2, 2, 2, 1, 3, 1]}


def test_ten_thousand_sets_agree_with_the_exact_solver(symmetric):
    rng = np.random.default_rng(7)
    P = 10_000
    values = {"k1": rng.uniform(0.2, 4, P), "k2": rng.uniform(0.2, 3, P), "c": rng.uniform(0.02, 4, P)}
    critical = np.arange(0, P, P // len(CRITICAL["c"]))[:len(CRITICAL["c"])]
    near = critical[:3] + 1  # just off critical damping: roots 1e-5 apart
    for name, array in values.items():
        array[critical] = CRITICAL[name]
        array[near] = CRITICAL[name][:3]
    values["c"][near] += np.array([1e-10, -1e-10, 3e-9])
    result = sweep(symmetric, values, TIMES, return_error=True)
    assert result.values.shape == (P, 2, TIMES.size)
    assert np.all(np.isfinite(result.values)) and np.all(result.set_error <= 1e-13)
    # every set against the textbook modal split: x1 ± x2 obey 1-DOF equations
    k1, k2, c = (values[name][:, None] for name in ("k1", "k2", "c"))
    t = TIMES[None, :]
    w = np.sqrt(k1)
    plus = np.cos(w * t) + np.sin(w * t) / w            # x1 + x2, x(0) = 1, v(0) = 1
    minus = _one_dof(2 * c, k1 + 2 * k2, 1.0, -1.0, t)   # x1 - x2, x(0) = 1, v(0) = -1
    reference = np.stack([(plus + minus) / 2, (plus - minus) / 2], axis=1)
    far = np.abs(c**2 - k1 - 2 * k2)[:, 0] > 1e-2 * (k1 + 2 * k2)[:, 0]  # where the formula is accurate
    scale = np.maximum(np.max(np.abs(reference), axis=1), 1.0)
    assert np.max(np.abs(result.values - reference)[far] / scale[far][:, None, :]) < 1e-11
    # the exact solver on a random subset and every critical and nearly critical set
    chosen = np.concatenate([rng.choice(P, 30, replace=False), critical, near])
    for b in chosen:
        reference = _per_set(symmetric, values, b, TIMES)
        assert _relative(result.values[b], reference, 1.0) < 1e-12, (b, {k: v[b] for k, v in values.items()})


def _one_dof(c, k, x0, v0, t):
    """x'' + c x' + k x = 0 (textbook; c, k arrays (P, 1))."""
    a = c / 2
    disc = a**2 - k
    with np.errstate(invalid="ignore", divide="ignore"):
        wd = np.sqrt(np.abs(disc))
        under = np.exp(-a * t) * (x0 * np.cos(wd * t) + (v0 + a * x0) / wd * np.sin(wd * t))
        over = np.exp(-a * t) * (x0 * np.cosh(wd * t) + (v0 + a * x0) / wd * np.sinh(wd * t))
    critical = np.exp(-a * t) * (x0 + (v0 + a * x0) * t)
    return np.where(disc < 0, under, np.where(disc > 0, over, critical))


def test_one_mass_against_the_textbook_formula():
    scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=["v"],
                                   parameters=["c", "k", "v"])
    g = grid(k=[0.5, 1.0, 4.0], c=[0.1, 1.0, 2.0, 4.0, 7.0], v=[0.5, 3.0])
    x = sweep(scene, g, TIMES)
    reference = _one_dof(g["c"][:, None], g["k"][:, None], 1.0, g["v"][:, None], TIMES[None, :])
    scale = np.maximum(np.max(np.abs(reference), axis=0), 1.0)
    assert np.max(np.abs(x[:, 0] - reference) / scale) < 1e-12
    assert x.reshape(*g.shape, 1, TIMES.size).shape == (3, 5, 2, 1, TIMES.size)
    velocity = sweep(scene, {"c": [2.0], "k": [1.0], "v": [1.0]}, TIMES, derivative=1)
    assert np.allclose(velocity[0, 0], (1 - 2 * TIMES) * np.exp(-TIMES), rtol=0, atol=1e-14)


def test_random_two_mass_sets_and_derivatives_match_the_exact_solver(grounded):
    rng = np.random.default_rng(3)
    values = {"k1": rng.uniform(0.5, 3, 200), "k2": rng.uniform(0.5, 3, 200), "c": rng.uniform(0.01, 4, 200)}
    for derivative in (0, 1):
        x = sweep(grounded, values, TIMES, derivative=derivative, outputs=["x2"])
        for b in (0, 17, 101):
            reference = _per_set(grounded, values, b, TIMES, derivative)[1:]
            assert _relative(x[b], reference, 1.0) < 1e-12


def test_forced_scene_matches_the_exact_solver():
    scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[0], v0=[0],
                                   forcing=["cos(2*t)"], parameters=["c", "k"])
    values = {"c": [0.3, 1.0, 0.05], "k": [4.0, 2.0, 4.0]}  # the first and last at resonance
    x = sweep(scene, values, TIMES)
    for b in range(3):
        reference = _per_set(scene, values, b, TIMES)
        scale = np.max(np.abs(reference))
        assert np.max(np.abs(x[b] - reference)) < 1e-12 * scale


def test_steady_state_amplitude_against_the_textbook_and_the_exact_route(grounded):
    scene = ls.Scene.from_matrices(M=[[2]], C=[["c"]], K=[["k"]], x0=[0], v0=[0], parameters=["c", "k"])
    c, k, w = np.array([0.1, 1.0, 3.0]), np.array([8.0, 2.0, 5.0]), np.array([1.0, 2.0, 2.5])
    amplitude = steady_state_amplitudes(scene, {"c": c, "k": k}, [3], w[:, None])[:, 0, 0]
    assert np.allclose(amplitude, 3 / np.sqrt((k - 2 * w**2) ** 2 + (c * w) ** 2), rtol=1e-13, atol=0)
    values = {"k1": [2.0], "k2": [1.0], "c": [0.5]}
    mine = steady_state_amplitudes(grounded, values, [1, 0], 1.3)[0]
    exact, _ = ls.steady_state_amplitude(grounded.subs({"k1": 2, "k2": 1, "c": "1/2"}), [1, 0], "1.3")
    assert np.allclose(mine, [float(a) for a in exact], rtol=1e-13, atol=0)


def test_derived_quantities(grounded):
    t = np.linspace(0, 30, 301)
    x = sweep(grounded, {"k1": [1.0, 1.0], "k2": [1.0, 1.0], "c": [0.5, 2.0]}, t)
    peaks = peak_amplitude(x)
    values = {"k1": [1.0, 1.0], "k2": [1.0, 1.0], "c": [0.5, 2.0]}
    exact = np.array([np.max(np.abs(_per_set(grounded, values, b, t)), axis=1) for b in range(2)])
    assert peaks.shape == (2, 2) and np.allclose(peaks, exact, rtol=1e-12, atol=0)
    settled = settling_time(x, t, 0.05)
    assert settled.shape == (2, 2) and np.all(settled > 0)
    # support force of one mass on a spring: k x, peak k x0 (textbook)
    one = ls.Scene.from_components(masses={"m": 1}, springs={"k": ("wall", "m", "k")},
                                   x0=[1], v0=[0], parameters=["k"])
    assert np.allclose(peak_support_force(one, {"k": [2.0, 5.0]}, np.linspace(0, 10, 1001)),
                       [2.0, 5.0], rtol=1e-12)


def test_derived_quantities_refuse_what_they_cannot_read(grounded):
    """No times, times that do not increase: a SceneError naming the function and the entry
    (numpy's zero-size reduction error, or a settling time read out of order, before)."""
    with pytest.raises(SceneError, match="peak_amplitude: expected values at one time"):
        peak_amplitude(np.zeros((2, 0)))
    x = np.array([[[1.0, 0.5, 0.01]]])
    with pytest.raises(SceneError, match=r"times\[1\] = 1.0 follows times\[0\] = 2.0"):
        settling_time(x, [2.0, 1.0, 0.0], 0.1)
    with pytest.raises(SceneError, match="settling_time: times must increase"):
        sweep(grounded, {"k1": [1.0], "k2": [1.0], "c": [0.5]}, [3.0, 1.0, 2.0],
              quantities={"settling_time": 0.05})


def test_a_settling_time_through_a_nan_value_is_nan():
    """A NaN value (a set the sweep could not serve) is not read as settled."""
    x = np.array([[[1.0, np.nan, 0.0], [1.0, 0.0, 0.0]]])
    settled = settling_time(x, [0.0, 1.0, 2.0], 0.1)
    assert np.isnan(settled[0, 0]) and settled[0, 1] == 0.0


def test_sampling_and_summary_are_reproducible():
    a = sample_parameters({"k": ("normal", 1, 0.05), "c": ("uniform", 0.1, 0.2),
                           "m": ("lognormal", 1, 0.1), "x": 3}, 2000, seed=5)
    b = sample_parameters({"k": ("normal", 1, 0.05), "c": ("uniform", 0.1, 0.2),
                           "m": ("lognormal", 1, 0.1), "x": 3}, 2000, seed=5)
    assert all(np.array_equal(a[name], b[name]) for name in a)
    assert abs(a["k"].mean() - 1) < 0.01 and a["c"].min() >= 0.1 and a["c"].max() <= 0.2
    assert abs(np.median(a["m"]) - 1) < 0.02 and np.all(a["x"] == 3)
    summary = summarize(np.arange(101.0).reshape(101, 1, 1))
    low, high = summary.band(0.05, 0.95)
    assert (low.item(), summary.mean.item(), high.item()) == (5.0, 50.0, 95.0)
    with pytest.raises(SceneError, match="'k'"):
        sample_parameters({"k": ("gamma", 1, 2)}, 3)


def test_bad_input_is_a_scene_error(grounded):
    with pytest.raises(SceneError, match="no values for parameter"):
        sweep(grounded, {"k1": [1.0], "k2": [1.0]}, TIMES)
    with pytest.raises(SceneError, match="'q' is not a parameter"):
        sweep(grounded, {"k1": [1.0], "k2": [1.0], "c": [1.0], "q": [1.0]}, TIMES)
    with pytest.raises(SceneError, match="set 1 has c = -1.0"):
        sweep(grounded, {"k1": [1.0, 1.0], "k2": [1.0, 1.0], "c": [1.0, -1.0]}, TIMES)
    with pytest.raises(SceneError, match="one length"):
        sweep(grounded, {"k1": [1.0, 2.0], "k2": [1.0], "c": [1.0, 1.0, 1.0]}, TIMES)
    with pytest.raises(SceneError, match="outputs"):
        sweep(grounded, {"k1": 1.0, "k2": 1.0, "c": 1.0}, TIMES, outputs=["x9"])
    with pytest.raises(ValueError, match="times"):
        sweep(grounded, {"k1": 1.0, "k2": 1.0, "c": 1.0}, [-1.0])


@pytest.mark.parametrize("value", [1e-320, 1e305, -1e-310])
def test_float_values_beyond_the_magnitude_limit_are_refused_as_subs_refuses_them(value):
    """Found by an attack: a subnormal k = 1e-320 in a float array was swept while
    ``scene.subs({"k": 1e-320})`` refuses it."""
    scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0],
                                   parameters={"c": "real", "k": "real"})
    with pytest.raises(SceneError, match="1e-300 <= \\|value\\| <= 1e300"):
        scene.subs({"k": value, "c": 1})
    with pytest.raises(SceneError, match=r"sweep: value 1 of parameter 'k': .* 1e-300 <= \|value\| <= 1e300"):
        ls.sweep(scene, {"k": np.array([1.0, value]), "c": [1.0, 1.0]}, [1.0])
