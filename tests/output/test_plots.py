"""Plots and the numbers behind them, checked against independent routes.

Velocities are checked against the mpmath matrix exponential (laplace_springs.bench.reference)
of the same scene started from (v0, a0), a0 = M⁻¹(−C v0 − K x0): the velocity obeys the
same equation. Energies are checked against the initial energy computed exactly from the
scene's data, and against the physics (damping only removes energy).
"""

from __future__ import annotations

import io

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest
import sympy as sp
from matplotlib.figure import Figure

import laplace_springs as ls
from laplace_springs.bench.reference import reference_motion, relative_error
from laplace_springs.cli import main as cli_main
from laplace_springs.output.plots import (
    default_t_end,
    energy,
    motion,
    overview_figure,
    plot_energy,
    plot_frequency_response,
    plot_motion,
    plot_phase,
    time_grid,
)

SCENES = sorted(ls.bundled_scenes())


def _axes():
    return Figure().subplots()


def _velocity_scene(scene):
    """The scene started from (v0, a0): its motion is the original velocity."""
    a0 = scene.M.inv() * (-scene.C * scene.v0 - scene.K * scene.x0)
    return scene.with_initial(x0=list(scene.v0), v0=list(a0))


@pytest.mark.parametrize("name", SCENES)
def test_velocities_match_the_matrix_exponential(name):
    scene = ls.load_scene(name)
    times = [0.0, 0.3, 1.7, 4.25]
    _, v = motion(ls.solve(scene), times)
    assert relative_error(v, reference_motion(_velocity_scene(scene), times, dps=30)) < 1e-12


@pytest.mark.parametrize("name", SCENES)
def test_energy_is_conserved_and_damping_only_removes_it(name):
    scene = ls.load_scene(name)
    sol = ls.solve(scene)
    times = np.linspace(0.0, default_t_end(sol), 1500)
    e = energy(sol, times)
    initial = (scene.v0.T * scene.M * scene.v0 + scene.x0.T * scene.K * scene.x0)[0] / 2
    assert e.total[0] == pytest.approx(float(initial), rel=1e-13)
    assert np.abs(e.total - float(initial)).max() <= 1e-9 * float(initial)
    scale = 1e-12 * float(initial)
    assert np.all(np.diff(e.mechanical) <= scale)  # never gains energy
    assert np.all(np.diff(e.dissipated) >= -scale)
    if not scene.is_damped:
        assert np.all(e.dissipated == 0)
        assert np.ptp(e.mechanical) <= 1e-12 * float(initial)
    else:
        assert e.dissipated[-1] > 0.1 * float(initial)


def test_energy_of_the_normalised_seed_example_1_uses_physical_masses():
    # A = [[3, -1], [-2, 2]]: ½xᵀAx is no energy (A is not symmetric), ½xᵀ(DA)x is.
    scene = ls.Scene.from_normalized(A=[[3, -1], [-2, 2]], x0=[1, 0], v0=[0, 1])
    e = energy(ls.solve(scene), np.linspace(0, 20, 801))
    assert np.ptp(e.total) <= 1e-12 * e.total[0]
    assert e.total[0] == pytest.approx(0.5 * 3 * 1 + 0.5 * 0.5 * 1)  # ½x0ᵀKx0 + ½v0ᵀMv0


@pytest.mark.parametrize("name", SCENES)
def test_motion_plot_lines_match_the_reference(name):
    scene = ls.load_scene(name)
    ax = plot_motion(ls.solve(scene), _axes())
    lines = [line for line in ax.get_lines() if line.get_label().startswith("Mass")]
    assert len(lines) == scene.n
    times = lines[0].get_xdata()[::97]
    values = np.array([line.get_ydata()[::97] for line in lines])
    assert relative_error(values, reference_motion(scene, list(times), dps=30)) < 1e-12
    # a scene with units says them (the seed's "Time (s)", "Position (m)"); bare numbers claim none
    expected = ("Time (s)", "Position (m)") if scene.units is not None else ("Time", "Position")
    assert (ax.get_xlabel(), ax.get_ylabel()) == expected
    assert ax.get_title().startswith("Mass Position vs. Time")


def test_default_span_of_example_5_is_close_to_the_seeds_4_seconds():
    assert default_t_end(ls.solve(ls.load_scene("three-dashpots"))) == 5.0
    # undamped: four periods of the slowest mode (4·2π ≈ 25.1 for the vertical pair), rounded
    assert default_t_end(ls.solve(ls.load_scene("vertical-pair"))) == 30.0


def test_phase_portrait_starts_at_the_initial_data():
    scene = ls.load_scene("wall-pair-dashpot")
    ax = plot_phase(ls.solve(scene), _axes())
    dots = [line for line in ax.get_lines() if line.get_marker() == "o"]
    starts = sorted((line.get_xdata()[0], line.get_ydata()[0]) for line in dots)
    expected = sorted((float(x), float(v)) for x, v in zip(scene.x0, scene.v0))
    assert np.allclose(starts, expected)


def test_energy_plot_total_is_flat():
    ax = plot_energy(ls.solve(ls.load_scene("three-dashpots")), _axes())
    total = next(line for line in ax.get_lines() if line.get_label() == "total").get_ydata()
    assert np.ptp(total) < 1e-9 * total[0]


def _lines(ax, label):
    return [line for line in ax.get_lines() if line.get_label() == label]


def test_frequency_response_of_one_mass_is_the_textbook_receptance():
    # m x'' + c x' + k x = F cos ωt: |X/F| = 1/sqrt((k − mω²)² + (cω)²), phase −atan2(cω, k − mω²)
    m, c, k = 2.0, 0.5, 8.0
    scene = ls.Scene.from_matrices(M=[[2]], C=[["0.5"]], K=[[8]], x0=[0], v0=[0])
    omegas = np.array([0.25, 1.0, 1.9, 2.0, 2.1, 3.5, 40.0])
    figure = Figure()
    amp_ax, phase_ax = figure.subplots(2, 1)
    assert plot_frequency_response(scene, omegas, ax=(amp_ax, phase_ax)) is figure
    (amplitude,) = _lines(amp_ax, "|x1| / F")
    assert np.array_equal(amplitude.get_xdata(), omegas)
    expected = 1 / np.sqrt((k - m * omegas**2) ** 2 + (c * omegas) ** 2)
    np.testing.assert_allclose(amplitude.get_ydata(), expected, rtol=1e-13)
    (phase,) = _lines(phase_ax, "x1")
    np.testing.assert_allclose(phase.get_ydata(),
                               -np.degrees(np.arctan2(c * omegas, k - m * omegas**2)), rtol=1e-13)
    # the one resonance is marked at the damped frequency sqrt(k/m − (c/2m)²), with |H| there
    damped = np.sqrt(k / m - (c / (2 * m)) ** 2)
    peaks = [line.get_xdata()[0] for line in amp_ax.get_lines() if line.get_linestyle() == "--"]
    assert peaks == pytest.approx([damped], rel=1e-14)
    (dot,) = [line for line in amp_ax.get_lines() if line.get_marker() == "o"]
    at_peak = 1 / np.sqrt((k - m * damped**2) ** 2 + (c * damped) ** 2)
    assert dot.get_ydata()[0] == pytest.approx(at_peak, rel=1e-13)


def test_frequency_response_default_frequencies_span_the_modes():
    # vertical-pair-damped: ω_n = 1 and 2 (the seed's Example 2), default span 0.1 to 20
    fig = plot_frequency_response(ls.load_scene("vertical-pair-damped"), force=1, outputs=[0])
    amp_ax, _ = fig.axes
    (line,) = [line for line in amp_ax.get_lines() if line.get_label().startswith("|")]
    assert line.get_label() == "|x1| / F"
    assert line.get_xdata()[0] == pytest.approx(0.1) and line.get_xdata()[-1] == pytest.approx(20.0)
    assert amp_ax.get_title() == "Frequency response, unit force on x2"
    plt.close(fig)


@pytest.mark.parametrize("kwargs, message", [
    ({"omegas": [0.0, 1.0]}, "positive"),
    ({"omegas": [1.0, np.inf]}, "positive"),
    ({"force": 2}, "coordinate 2 is out of range"),
    ({"outputs": [-1]}, "coordinate -1 is out of range"),
])
def test_frequency_response_refuses_bad_input(kwargs, message):
    with pytest.raises(ValueError, match=message):
        plot_frequency_response(ls.load_scene("wall-pair"), **kwargs)


def test_frequency_response_of_a_symbolic_scene_is_refused():
    k = sp.Symbol("k", positive=True)
    with pytest.raises(ls.SceneError, match="symbols k"):
        plot_frequency_response(ls.Scene.from_matrices(M=[[1]], K=[[k]], x0=[1], v0=[0]))


@pytest.mark.parametrize("method", ["modal", "certified"])
def test_plots_take_modal_and_certified_solutions(method):
    # The same plots from the float64 modal route and the certified route, checked against
    # the matrix exponential of the scene (positions) and of its velocity scene (velocities).
    scene = ls.load_scene("wall-pair-dashpot")
    sol = ls.solve(scene, method=method)
    assert sol.method == method or method == "modal"  # "modal": the float64 eigen family
    times = time_grid(sol)
    every = slice(None, None, 97)
    x_ref = reference_motion(scene, list(times[every]), dps=30)
    v_ref = reference_motion(_velocity_scene(scene), list(times[every]), dps=30)

    ax = plot_motion(sol, _axes())
    lines = [line for line in ax.get_lines() if line.get_label().startswith("Mass")]
    assert np.array_equal(lines[0].get_xdata(), times)
    assert relative_error(np.array([line.get_ydata()[every] for line in lines]), x_ref) < 1e-12

    ax = plot_phase(sol, _axes())
    lines = [line for line in ax.get_lines() if line.get_label().startswith("Mass")]
    assert len(lines) == scene.n
    assert relative_error(np.array([line.get_xdata()[every] for line in lines]), x_ref) < 1e-12
    assert relative_error(np.array([line.get_ydata()[every] for line in lines]), v_ref) < 1e-12

    ax = plot_energy(sol, _axes())
    (total,) = _lines(ax, "total")
    initial = float((scene.v0.T * scene.M * scene.v0 + scene.x0.T * scene.K * scene.x0)[0] / 2)
    assert np.abs(total.get_ydata() - initial).max() <= 1e-9 * initial


def test_overview_figure_saves_a_png():
    figure = overview_figure(ls.solve(ls.load_scene("vertical-pair-damped")))
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=50)
    assert buffer.getvalue()[:8] == b"\x89PNG\r\n\x1a\n"


def test_symbolic_scene_cannot_be_plotted():
    k = sp.Symbol("k", positive=True)
    sol = ls.solve(ls.Scene.from_matrices(M=[[1]], K=[[k]], x0=[1], v0=[0]))
    with pytest.raises(ls.SceneError, match="symbols k"):
        plot_motion(sol, _axes())


def test_cli_plot_writes_a_png(tmp_path, capsys):
    path = tmp_path / "motion.png"
    assert cli_main(["solve", "wall-pair", "--plot", str(path)]) == 0
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "x1(t) =" in capsys.readouterr().out  # the formula is still printed
    assert cli_main(["solve", "wall-pair", "--plot", str(tmp_path / "missing" / "x.png")]) == 2
    assert "the folder" in (err := capsys.readouterr().err) and "does not exist" in err


def test_energy_balance_of_a_driven_damped_pair():
    # E(t) = E0 + ∫fᵀv dt − ∫vᵀCv dt: the work of the force is integrated independently
    # from f(t) itself (lambdify) and the exact velocity.
    scene = ls.load_scene("wall-pair-dashpot").with_forcing(["cos(t)", "Heaviside(t - 2)/2"])
    sol = ls.solve(scene)
    e = energy(sol, np.linspace(0.0, 30.0, 3001))
    initial = float((scene.v0.T * scene.M * scene.v0 + scene.x0.T * scene.K * scene.x0)[0] / 2)
    assert np.abs(e.total - initial).max() <= 1e-9 * max(1.0, np.abs(e.work).max())
    assert np.any(e.work != 0)
    ax = plot_energy(sol, _axes())
    assert "work of the forces ∫fᵀv dt" in [t.get_text() for t in ax.get_legend().texts]


def test_frequency_response_plot_of_an_undamped_scene_leaves_gaps_at_resonance():
    # |H| = 1/|k - m w^2| (textbook); at w = 2 = sqrt(k/m) there is no finite value
    scene = ls.Scene.from_matrices(M=[[1]], C=[[0]], K=[[4]], x0=[1], v0=[0])
    fig = ls.plot_frequency_response(scene, [1.0, 2.0, 3.0])
    line = next(c for c in fig.axes[0].get_lines() if c.get_label().startswith("|"))
    amplitude = np.asarray(line.get_ydata(), dtype=float)
    assert np.isnan(amplitude[1])
    assert np.allclose(amplitude[[0, 2]], [1 / 3, 1 / 5], rtol=1e-15)
