"""Derived quantities at size: per-set peak, RMS, final value and settling time reduced
chunk by chunk (against the full motions and their bounds), transmissibility, steady-state
amplitudes and modal quantities of a 12-mass chain per set (against the package's exact
analysis of each set alone, ls.transmissibility and the solver's poles, and a textbook
formula), and
percentiles over Monte Carlo samples."""

from __future__ import annotations

import numpy as np

import laplace_springs as ls


def _chain(n=12, ground=False):
    masses = {f"m{i}": 1 for i in range(n)}
    base = "ground" if ground else "wall"
    springs = {"k0": (base, "m0", "k"), **{f"k{i}": (f"m{i-1}", f"m{i}", 1) for i in range(1, n)}}
    return ls.Scene.from_components(masses=masses, springs=springs, dashpots={"c": (base, "m0", "c")},
                                    x0=[1] + [0] * (n - 1), v0=[0] * n,
                                    parameters={"k": "positive", "c": "nonnegative"})


def test_quantities_reduced_per_chunk_match_the_motions_within_their_bounds():
    scene = _chain()
    rng = np.random.default_rng(3)
    values = {"k": rng.uniform(0.5, 2, 30), "c": rng.uniform(0.1, 1, 30)}
    times = np.linspace(0, 40, 161)
    full = ls.sweep(scene, values, times, return_error=True)
    reduced = ls.sweep(scene, values, times, chunk=7,
                       quantities={"peak": None, "rms": None, "final": None, "settling_time": 0.05})
    assert reduced.values is None
    assert np.array_equal(reduced.quantities["peak"], ls.peak_amplitude(full.values))
    assert np.allclose(reduced.quantities["rms"], ls.rms_amplitude(full.values), rtol=1e-15, atol=0)
    assert np.array_equal(reduced.quantities["final"], full.values[:, :, -1])
    assert np.array_equal(reduced.quantities["settling_time"], ls.settling_time(full.values, times, 0.05))
    assert np.all(reduced.quantity_error["peak"] >= np.max(full.error, axis=2))
    for b in (0, 11):  # each set alone: its peak within the two bounds
        alone, bound = ls.solve(scene.subs({"k": values["k"][b], "c": values["c"][b]})).evaluate(
            times, return_error=True)
        peak = np.max(np.abs(alone), axis=1)
        assert np.all(np.abs(reduced.quantities["peak"][b] - peak)
                      <= reduced.quantity_error["peak"][b] + np.max(bound, axis=1))


def test_transmissibility_and_modes_of_a_twelve_mass_chain_per_set():
    scene = _chain(ground=True)
    values = {"k": [0.5, 2.0, 4.0], "c": [0.05, 0.3, 1.0]}
    omegas = np.array([0.1, 0.9, 1.7])
    swept = ls.sweep_transmissibility(scene, values, omegas, outputs=["m0", "m11"])
    modal = ls.modal_quantities(scene, values)
    for b in range(3):
        numeric = scene.subs({"k": values["k"][b], "c": values["c"][b]})
        exact = np.asarray(ls.transmissibility(numeric, omegas), dtype=float)
        exact = exact.T if exact.shape[0] == omegas.size else exact  # (coordinates, frequencies)
        assert np.allclose(swept[b], exact[[0, 11]], rtol=1e-10, atol=0)
        poles = np.asarray(ls.solve(numeric).poles, dtype=complex)  # the engine's own poles
        natural = np.sort(np.abs(poles[poles.imag >= 0]))
        assert np.allclose(np.sort(modal.natural_frequency[b][np.isfinite(modal.natural_frequency[b])]),
                           natural, rtol=1e-10)
    one = ls.Scene.from_components(masses={"m": 1}, springs={"k": ("ground", "m", "k")},
                                   dashpots={"c": ("ground", "m", "c")}, parameters=["k", "c"])
    k, c = np.array([4.0, 9.0]), np.array([0.4, 6.0])  # the second overdamped
    q = ls.modal_quantities(one, {"k": k, "c": c})
    assert np.allclose(q.natural_frequency[0, 0], 2.0) and np.allclose(q.damping_ratio[0, 0], 0.1)
    slow, fast = (6 - np.sqrt(36 - 36)) / 2, (6 + np.sqrt(0)) / 2  # critical at c = 6, k = 9
    assert np.allclose(np.sort(q.natural_frequency[1]), [slow, fast], rtol=1e-6)


def test_steady_state_amplitudes_beyond_the_symbolic_limit():
    scene = _chain()
    values = {"k": [1.0, 3.0], "c": [0.2, 0.5]}
    force = [0] * 11 + [1]
    amplitude = ls.steady_state_amplitudes(scene, values, force, 0.8)
    for b in range(2):
        exact, _ = ls.steady_state_amplitude(scene.subs({"k": values["k"][b], "c": values["c"][b]}),
                                             force, "0.8")
        assert np.allclose(amplitude[b], [float(a) for a in exact], rtol=1e-10, atol=0)


def test_percentiles_over_monte_carlo_samples():
    """A mass with uncertain stiffness and damping: percentiles of the peak of each sample,
    against numpy's percentiles of the peaks of the sets solved one by one (40 samples)."""
    scene = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[["k"]], x0=[1], v0=[0], parameters=["c", "k"])
    samples = ls.sample_parameters({"k": ("lognormal", 4, 0.2), "c": ("uniform", 0.1, 0.5)}, 40, seed=9)
    times = np.linspace(0.5, 10, 96)
    result = ls.sweep(scene, samples, times, quantities=["rms"])
    summary = ls.summarize(result.quantities["rms"], levels=(0.1, 0.5, 0.9))
    alone = [np.sqrt(np.mean(ls.solve(scene.subs({"k": samples["k"][b], "c": samples["c"][b]})).evaluate(
        times)[0] ** 2)) for b in range(40)]
    assert np.allclose(summary.percentile(90), np.percentile(alone, 90), rtol=1e-12)
    assert np.allclose(summary.percentile(10), np.percentile(alone, 10), rtol=1e-12)
    assert summary.count == 40
