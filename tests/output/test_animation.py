"""Animations: every frame shows the solution's own values (read back from the artists)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import importlib.util
import shutil

import numpy as np
import pytest
from PIL import Image

import laplace_springs as ls
from laplace_springs.output.animation import animate, frame_times


def _read_back(movie):
    """x of each animated mass, from the blocks' rectangles, in the scene's units."""
    return movie.diagram.block_positions() / movie.scale


@pytest.mark.parametrize("name", sorted(ls.bundled_scenes()))
def test_frames_show_evaluate_at_the_frame_times(name, tmp_path):
    scene = ls.load_scene(name)
    movie = animate(ls.solve(scene), duration=1.0, fps=4)
    with Image.open(movie.save(tmp_path / f"{name}.gif", dpi=30)) as image:  # saved, every frame
        assert image.n_frames == len(movie)
    reference = ls.solve(scene)  # a separate solution, one time per call
    assert len(movie) == 5
    for k in range(len(movie)):
        movie.frame(k)
        expected = np.asarray(reference.evaluate([movie.times[k]]), dtype=float)[:, 0]
        size = max(1e-300, float(np.max(np.abs(movie.positions))))
        assert np.allclose(_read_back(movie), expected, rtol=0, atol=1e-12 * size)
        dots = [line for line in movie.figure.axes[1].lines if line.get_marker() == "o"]
        assert np.allclose([dot.get_ydata()[0] for dot in dots], expected, rtol=0, atol=1e-12 * size)
        assert movie._readout.get_text() == f"t = {movie.times[k]:.2f} s"


def test_a_large_chain_animates_a_subset():
    n = 30
    masses = {f"m{i}": 1 for i in range(1, n + 1)}
    springs = {"k0": ("wall", "m1", 1), f"k{n}": (f"m{n}", "wall", 1)}
    springs.update({f"k{i}": (f"m{i}", f"m{i + 1}", 1) for i in range(1, n)})
    x0 = [0] * n
    x0[0] = 1
    scene = ls.Scene.from_components(masses=masses, springs=springs, x0=x0, v0=[0] * n)
    solution = ls.solve(scene)
    movie = animate(solution, duration=0.5, fps=4, curves=False)
    assert len(movie.masses) == ls.limits().animation_max_masses and movie.masses[0] == 0
    assert movie.masses[-1] == n - 1 and "of 30" in movie.diagram.ax.get_title()
    chosen = animate(solution, duration=0.5, fps=4, masses=["x2", 10])
    assert chosen.masses == [1, 9]
    chosen.frame(2)
    expected = np.asarray(solution.evaluate([chosen.times[2]]), dtype=float)[[1, 9], 0]
    assert np.allclose(_read_back(chosen), expected, atol=1e-12)
    with pytest.raises(ls.SceneError, match="masses must"):
        animate(solution, masses=["m99"])


def test_a_moving_floor_moves_with_u():
    scene = ls.Scene.from_components(masses={"m": 1}, springs={"k": ("floor", "m", 4)},
                                     dashpots={"c": ("floor", "m", "0.4")},
                                     support_motion={"floor": "sin(3*t)/100"})
    movie = animate(ls.solve(scene), duration=1.0, fps=4)
    assert np.allclose(movie.supports["floor"], np.sin(3 * movie.times) / 100, atol=1e-15)
    floor = max((line for line in movie.diagram.ax.lines if np.ptp(line.get_ydata()) == 0),
                key=lambda line: line.get_linewidth())
    rest = floor.get_ydata().copy()
    movie.frame(3)
    assert np.allclose(floor.get_ydata(), rest + movie.scale * np.sin(3 * movie.times[3]) / 100)


def test_gif_and_inline_html(tmp_path):
    movie = animate(ls.solve(ls.load_scene("wall-pair")), duration=0.5, fps=6, curves=False)
    path = movie.save(tmp_path / "pair.gif", dpi=40)
    with Image.open(path) as image:
        assert image.n_frames == len(movie) == 4
    html = movie.to_jshtml()
    assert "<script" in html and html.count("data:image/png;base64") >= 1


@pytest.mark.skipif(shutil.which("ffmpeg") is None and importlib.util.find_spec("imageio_ffmpeg") is None,
                    reason="no ffmpeg: neither on the PATH nor imageio-ffmpeg installed")
def test_mp4(tmp_path):
    movie = animate(ls.solve(ls.load_scene("wall-pair")), duration=0.5, fps=6, curves=False)
    path = movie.save(tmp_path / "pair.mp4", dpi=40)
    assert path.stat().st_size > 1000 and path.read_bytes()[4:8] == b"ftyp"


def test_timing_options():
    solution = ls.solve(ls.load_scene("wall-pair"))
    times = frame_times(solution, t_end=10, speed=5, fps=10)  # 2 s of clip
    assert len(times) == 21 and times[-1] == 10
    with pytest.raises(ls.SceneError, match="duration or speed"):
        frame_times(solution, duration=1, speed=1)
    with pytest.raises(ls.SceneError, match="animation_max_frames"):
        frame_times(solution, duration=1000, fps=25)
    with pytest.raises(ls.SceneError, match="t_end must be a positive"):
        frame_times(solution, t_end=float("nan"))
    with pytest.raises(ls.SceneError, match="the file name must end"):
        animate(solution, duration=0.2, fps=5).save("movie.avi")


def test_a_scene_with_parameters_is_refused():
    scene = ls.Scene.from_matrices(M=[[1]], K=[["k"]], x0=[1], v0=[0], parameters=["k"])
    with pytest.raises(ls.SceneError, match="parameters \\(k\\)"):
        animate(ls.solve(scene))
