"""Bode and pole-zero plots against textbook values and python-control.

A single mass-spring-damper m x'' + c x' + k x = f has |G(iω)| = 1/√((k − mω²)² + (cω)²):
1/k at low frequency, 1/(c ω_n) at ω_n = √(k/m) where the phase is −90°, and a phase that
falls from 0° to −180°. Its poles are −ζω_n ± iω_n√(1 − ζ²).
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

import laplace_springs as ls
from laplace_springs.output.plots import bode_data, plot_bode, plot_pole_zero


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


M_, C_, K_ = 2.0, 0.6, 18.0  # ω_n = 3, ζ = c/(2√(km)) = 0.05
OMEGA_N = 3.0


def single():
    return ls.Scene.from_matrices(M=[[2]], C=[["0.6"]], K=[[18]], x0=[0], v0=[0])


def two_mass_chain():
    return ls.Scene.from_components(masses={"m1": 2, "m2": 3},
                                    springs={"k1": ("wall", "m1", 5), "k2": ("m1", "m2", 12)},
                                    dashpots={"c": ("m1", "m2", "1/10")}, x0=[0, 0], v0=[0, 0])


def _line(ax, label):
    (line,) = [line for line in ax.get_lines() if line.get_label() == label]
    return line


def test_bode_of_a_single_mass_spring_damper_is_the_textbook_one():
    omegas = np.array([0.01, 1.0, OMEGA_N, 10.0, 1000.0])
    fig = plot_bode(single(), omegas)
    mag_ax, phase_ax = fig.axes[:2]
    assert mag_ax.get_xscale() == "log" and phase_ax.get_xscale() == "log"
    db = _line(mag_ax, "x1 / f_x1").get_ydata()
    phase = _line(phase_ax, "x1 / f_x1").get_ydata()
    textbook = 1 / np.sqrt((K_ - M_ * omegas**2) ** 2 + (C_ * omegas) ** 2)
    assert np.allclose(db, 20 * np.log10(textbook), rtol=0, atol=1e-10)
    assert db[2] == pytest.approx(20 * np.log10(1 / (C_ * OMEGA_N)), abs=1e-10)  # resonance: 1/(c ω_n)
    assert db[0] == pytest.approx(20 * np.log10(1 / K_), abs=1e-3)  # static compliance 1/k
    assert phase[2] == pytest.approx(-90.0, abs=1e-10)
    assert np.allclose(phase, -np.degrees(np.arctan2(C_ * omegas, K_ - M_ * omegas**2)), rtol=0, atol=1e-10)
    assert phase[0] == pytest.approx(0.0, abs=0.05) and phase[-1] == pytest.approx(-180.0, abs=0.05)
    assert "dB" in mag_ax.get_ylabel() and "degrees" in phase_ax.get_ylabel()


def test_default_frequencies_span_the_resonance_and_mark_it():
    fig = plot_bode(single())
    mag_ax = fig.axes[0]
    w = _line(mag_ax, "x1 / f_x1").get_xdata()
    damped = OMEGA_N * np.sqrt(1 - 0.05**2)
    assert w.min() == pytest.approx(OMEGA_N / 10) and w.max() == pytest.approx(OMEGA_N * 10)
    assert np.any(np.isclose(w, damped, rtol=1e-12))
    marks = [line.get_xdata()[0] for line in mag_ax.get_lines() if line.get_linestyle() == "--"]
    assert marks == [pytest.approx(damped, rel=1e-12)]


def test_bode_data_match_python_control():
    control = pytest.importorskip("control")
    from laplace_springs.model.state_space import to_control

    scene = ls.load_scene("three-dashpots")
    w, db, phase = bode_data(scene, force=1)
    system = to_control(scene)
    for i in range(2):
        response = control.frequency_response(system[i, 1], w)
        assert np.max(np.abs(db[i] - 20 * np.log10(response.magnitude.ravel()))) <= 1e-9
        wrapped = np.angle(np.exp(1j * np.radians(phase[i])))  # compare modulo 360°
        assert np.max(np.abs(wrapped - np.angle(response.complex.ravel()))) <= 1e-9
        steps = np.abs(np.diff(phase[i]))
        assert steps.max() < 30.0  # unwrapped: no 360° jumps


def test_phase_of_a_two_mass_chain_runs_past_minus_180():
    """G21 of two masses falls by 180° at each resonance, continuously (unwrapped).

    With the dashpot to the wall, G21 = k2/Δ (relative degree 4): the phase ends at −360°.
    With the dashpot between the masses, G21 = (c s + k2)/Δ has a zero at −k2/c that gives
    back 90°: −270° at high frequency.
    """
    wall = ls.Scene.from_components(masses={"m1": 2, "m2": 3},
                                    springs={"k1": ("wall", "m1", 5), "k2": ("m1", "m2", 12)},
                                    dashpots={"c": ("wall", "m1", "1/10")}, x0=[0, 0], v0=[0, 0])
    omegas = np.geomspace(0.05, 1e6, 8000)
    for scene, end in ((wall, -360.0), (two_mass_chain(), -270.0)):
        _, _, phase = bode_data(scene, omegas, outputs=[1])
        assert phase[0, 0] == pytest.approx(0.0, abs=0.1)
        assert phase[0, -1] == pytest.approx(end, abs=0.1)
        assert np.abs(np.diff(phase[0])).max() < 180.0  # no 360° wraps


def test_bode_draws_on_given_axes_and_checks_its_input():
    fig, axes = plt.subplots(2, 1)
    assert plot_bode(two_mass_chain(), ax=tuple(axes), outputs=[0]) is fig
    assert [line.get_label() for line in axes[0].get_lines() if not line.get_label().startswith("_")] \
        == ["x1 / f_x1"]
    with pytest.raises(ValueError, match="out of range"):
        plot_bode(two_mass_chain(), force=2)
    with pytest.raises(ValueError, match="positive"):
        plot_bode(single(), [0.0, 1.0])
    symbolic = ls.Scene.from_matrices(M=[[1]], C=[["c"]], K=[[1]], x0=[0], v0=[0], parameters=["c"])
    with pytest.raises(ls.SceneError, match="parameters c"):
        plot_bode(symbolic)


def test_pole_zero_of_a_single_mass_are_the_textbook_poles():
    fig = plot_pole_zero(single())
    ax = fig.axes[0]
    poles = _line(ax, "poles")
    zeta = C_ / (2 * np.sqrt(K_ * M_))
    expected = [-zeta * OMEGA_N] * 2, [-OMEGA_N * np.sqrt(1 - zeta**2), OMEGA_N * np.sqrt(1 - zeta**2)]
    assert np.allclose(poles.get_xdata(), expected[0], atol=1e-14)
    assert np.allclose(poles.get_ydata(), expected[1], atol=1e-14)
    assert _line(ax, "zeros").get_xdata().size == 0
    assert ax.get_xlabel().startswith("Re s") and ax.get_ylabel().startswith("Im s")


def test_pole_zero_plot_poles_are_the_roots_of_delta_and_zeros_the_antiresonance():
    scene = two_mass_chain()
    ax = plot_pole_zero(scene, force=0, output=0).axes[0]
    plotted = _line(ax, "poles")
    poles = np.asarray(plotted.get_xdata()) + 1j * np.asarray(plotted.get_ydata())
    # Δ(s) = det(s²M + sC + K) by hand: (2s² + s/10 + 17)(3s² + s/10 + 12) − (s/10 + 12)²
    delta = np.polysub(np.polymul([2, 0.1, 17], [3, 0.1, 12]), np.polymul([0.1, 12], [0.1, 12]))
    assert np.allclose(np.sort_complex(poles), np.sort_complex(np.roots(delta)), rtol=0, atol=1e-12)
    assert np.max(np.abs(np.polyval(delta, poles))) <= 1e-9
    zeros = _line(ax, "zeros")
    # G11 = (3s² + s/10 + 12)/Δ: the antiresonance of m2 on its spring-dashpot
    expected = np.roots([3, 0.1, 12])
    found = np.asarray(zeros.get_xdata()) + 1j * np.asarray(zeros.get_ydata())
    assert np.allclose(np.sort_complex(found), np.sort_complex(expected), atol=1e-13)


def test_pole_zero_marks_repeated_poles():
    scene = ls.Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0])  # critical: −1 twice
    ax = plot_pole_zero(scene).axes[0]
    assert [text.get_text() for text in ax.texts] == ["2"]
    with pytest.raises(ValueError, match="out of range"):
        plot_pole_zero(scene, output=1)
