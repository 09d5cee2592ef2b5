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

import numpy as np  # noqa: E402
import pytest  # noqa: E402
import sympy as sp  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

import laplace_springs as ls  # noqa: E402
from laplace_springs.output.plots import (  # noqa: E402
    default_t_end, energy, motion, overview_figure, plot_energy, plot_frequency_response,
    plot_motion, plot_phase,
)
from laplace_springs.bench.reference import reference_motion, relative_error  # noqa: E402

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
    assert ax.get_xlabel() == "Time (s)" and ax.get_ylabel() == "Position (m)"
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


def test_frequency_response_of_one_mass_is_the_textbook_receptance():
    # |X/F| = 1/sqrt((k − mω²)² + (cω)²) for m x'' + c x' + k x = F cos ωt.
    scene = ls.Scene.from_matrices(M=[[2]], C=[["0.5"]], K=[[8]], x0=[0], v0=[0])
    omegas = np.array([0.0, 1.0, 2.0, 3.5])
    ax = plot_frequency_response(scene, _axes(), omega=omegas)
    (line,) = [line for line in ax.get_lines() if line.get_label().startswith("Mass")]
    expected = 1 / np.sqrt((8 - 2 * omegas**2) ** 2 + (0.5 * omegas) ** 2)
    assert np.allclose(line.get_ydata(), expected, rtol=1e-13)
    verticals = [line for line in ax.get_lines() if line.get_linestyle() == ":"]
    assert [line.get_xdata()[0] for line in verticals] == pytest.approx([2.0])


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
    from laplace_springs.cli import main

    path = tmp_path / "motion.png"
    assert main(["solve", "wall-pair", "--plot", str(path)]) == 0
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "x1(t) =" in capsys.readouterr().out  # the formula is still printed
    assert main(["solve", "wall-pair", "--plot", str(tmp_path / "missing" / "x.png")]) == 2
    assert "No such file" in capsys.readouterr().err


@pytest.mark.skipif(not hasattr(ls.Scene, "with_forcing"), reason="forcing not available")
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
