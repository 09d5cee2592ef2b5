"""Animations: the seed-style diagram moving along the solution, with its x(t) curves.

:func:`animate` draws the scene once (:func:`~laplace_springs.output.diagram.build_diagram`)
and moves the same artists frame by frame (``Line2D.set_data``, ``Rectangle.set_xy``):
blocks slide, springs stretch, pistons open and close, moving supports follow u(t), a time
readout counts, and beside the diagram the x(t) curves are drawn up to the current time.
Every frame's positions come from one vectorised ``solution.evaluate(times)`` call, so the
animation shows the solution's own values (within its accuracy contract), scaled by one
factor so that the largest displacement is :data:`~laplace_springs.output.diagram.MAX_SHIFT`
block lengths.

In a notebook the animation shows itself inline (``_repr_html_``, matplotlib's
``to_jshtml``); :meth:`SceneAnimation.save` writes a GIF (pillow), an MP4 (ffmpeg: on the
PATH, or the binary of the optional ``imageio-ffmpeg`` package) or an HTML file, chosen by
the file's suffix.

Large scenes
------------
A scene of more than :attr:`~laplace_springs.limits.Limits.animation_max_masses` masses
animates a subset (``masses=[...]``, by default that many evenly spaced): the diagram
shows those masses, the components among them and to supports; the springs and dashpots to
masses not shown are left out, and the title says so.
"""

from __future__ import annotations

import math
import re
import shutil
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import sympy as sp

from ..limits import limits
from ..model.errors import SceneError
from ..model.names import coordinate_index
from ..model.scene import Scene
from ..model.symbols import TIME
from ..model.units import axis_label
from .chain import Chain, chain_of, math_label
from .diagram import MAX_SHIFT, Diagram, build_diagram, orientation_of
from .plots import Motion, default_t_end

if TYPE_CHECKING:
    from matplotlib.animation import FuncAnimation
    from matplotlib.figure import Figure

__all__ = ["SceneAnimation", "animate", "frame_times", "offline_player"]

#: Frames per clip-second by default.
FPS = 20
#: Frames per period of the fastest oscillation the default speed aims at.
FRAMES_PER_PERIOD = 12


def frame_times(solution: Motion, *, t_end: float | None = None, duration: float | None = None,
                speed: float | None = None, fps: float = FPS) -> np.ndarray:
    """The solution's times shown by each frame: from 0 to ``t_end``, one per 1/fps of clip.

    ``speed`` is simulated seconds per second of clip; ``duration`` the clip's length in
    seconds (give one of them). By default the clip shows the fastest oscillation with
    about twelve frames per period, in 4 s at least and in at most
    :attr:`~laplace_springs.limits.Limits.animation_max_frames` frames.

    Examples
    --------
    >>> import laplace_springs as ls
    >>> times = frame_times(ls.solve(ls.load_scene("wall-pair")), t_end=10, duration=2, fps=10)
    >>> len(times), float(times[-1])
    (21, 10.0)
    """
    t_end = default_t_end(solution) if t_end is None else float(t_end)
    if not (math.isfinite(t_end) and t_end > 0):
        raise SceneError(f"animate: t_end must be a positive number, got {t_end}")
    if not (math.isfinite(fps) and fps > 0):
        raise SceneError(f"animate: fps must be a positive number, got {fps}")
    if duration is not None and speed is not None:
        raise SceneError(f"animate: give duration or speed, not both (got {duration} and {speed})")
    most = limits().animation_max_frames
    if speed is not None:
        if not (math.isfinite(speed) and speed > 0):
            raise SceneError(f"animate: speed must be a positive number, got {speed}")
        duration = t_end / speed
    elif duration is None:
        poles = np.asarray(solution.poles, dtype=complex)
        fastest = float(np.max(np.abs(poles.imag), initial=0.0))
        periods = t_end * fastest / (2 * math.pi)
        duration = min(max(4.0, periods * FRAMES_PER_PERIOD / fps), most / fps)
    if not (math.isfinite(duration) and duration > 0):
        raise SceneError(f"animate: duration must be a positive number, got {duration}")
    frames = int(round(duration * fps)) + 1
    if frames > most:
        raise SceneError(f"animate: {frames} frames ({duration:g} s at {fps:g} frames per second) "
                         f"is more than Limits.animation_max_frames = {most}; shorten the clip "
                         "or lower fps")
    return np.linspace(0.0, t_end, max(frames, 2))


def _chosen_masses(scene: Scene, masses: Sequence[Any] | None) -> list[int]:
    """Indices of the masses to animate: all (small scenes), the chosen ones, or evenly spaced."""
    n, most = scene.n, limits().animation_max_masses
    if masses is None:
        if n <= most:
            return list(range(n))
        return sorted({int(round(k * (n - 1) / (most - 1))) for k in range(most)})
    chosen = []
    for item in masses:
        if isinstance(item, str) and item in (*scene.names, *scene.mass_names):
            index = coordinate_index(item, "animate: masses", names=scene.names,
                                     mass_names=scene.mass_names)  # a mass name first, as everywhere
        elif isinstance(item, (int, np.integer)) and 1 <= int(item) <= n:
            index = int(item) - 1
        else:
            raise SceneError(f"animate: masses must name coordinates ({', '.join(scene.names[:4])}, ...) "
                             f"or be numbers from 1 to {n}; got {item!r}")
        chosen.append(index)
    if not chosen or len(set(chosen)) != len(chosen):
        raise SceneError(f"animate: masses must be distinct and at least one, got {list(masses)!r}")
    if len(chosen) > most:
        raise SceneError(f"animate: {len(chosen)} masses is more than Limits.animation_max_masses = "
                         f"{most}; choose fewer")
    return sorted(chosen)


def _sub_chain(scene: Scene, chosen: list[int]) -> Chain:
    """The chain of the chosen masses: components among them and to supports (see the notes)."""
    chain = chain_of(scene)
    if len(chosen) == scene.n:
        return chain
    keep = {chain.masses[i] for i in chosen}
    masses = set(chain.masses)
    components = tuple(c for c in chain.components
                       if all(node in keep or node not in masses for node in (c.a, c.b)))
    return Chain(tuple(chain.masses[i] for i in chosen), tuple(chain.mass_values[i] for i in chosen),
                 tuple(chain.coordinates[i] for i in chosen), components, chain.layout, chain.inferred)


def _support_motion(scene: Scene, times: np.ndarray) -> dict[str, np.ndarray]:
    """Each moving support's displacement u(t) at the frame times."""
    out = {}
    for name, expr in scene.support_motion:
        function = sp.lambdify(TIME, expr, modules=["numpy", {"Heaviside": _heaviside}])
        out[name] = np.broadcast_to(np.asarray(function(times), dtype=float), times.shape).copy()
    return out


def _heaviside(x: Any, at_zero: Any = 1.0) -> Any:
    return np.heaviside(x, 1.0)


class SceneAnimation:
    """An animation of a solution (see :func:`animate`).

    Attributes
    ----------
    figure : matplotlib.figure.Figure
    diagram : Diagram
        The moving diagram.
    times : numpy.ndarray
        The solution's time at each frame.
    positions : numpy.ndarray
        x(t) of the animated masses at each frame, shape (masses, frames), in the scene's
        length unit: ``solution.evaluate(times)`` (rows :attr:`masses`).
    supports : dict of str to numpy.ndarray
        Each moving support's u(t) at each frame.
    masses : list of int
        The animated coordinates (0-based).
    scale : float
        Drawing units per unit of length: a displacement x is drawn as ``scale * x``.
    fps : int
    """

    def __init__(self, figure: Figure, diagram: Diagram, times: np.ndarray, positions: np.ndarray,
                 supports: dict[str, np.ndarray], masses: list[int], scale: float, fps: int,
                 curves: tuple[np.ndarray, int, list[Any]], readout: Any, fine_values: np.ndarray) -> None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        self.figure, self.diagram = figure, diagram
        self.times, self.positions, self.supports = times, positions, supports
        self.masses, self.scale, self.fps = masses, scale, fps
        self._curves, self._readout, self._fine_values = curves, readout, fine_values
        self._animation: FuncAnimation | None = None
        if not isinstance(figure.canvas, FigureCanvasAgg):
            FigureCanvasAgg(figure)
        figure.canvas.draw()  # lay the figure out once; the frames only move artists
        figure.set_layout_engine("none")

    @property
    def animation(self) -> FuncAnimation:
        """matplotlib's FuncAnimation of the frames (made when first asked for: one that is
        never rendered makes matplotlib warn when it is deleted)."""
        if self._animation is None:
            from matplotlib.animation import FuncAnimation

            self._animation = FuncAnimation(self.figure, self.frame, frames=len(self.times),
                                            interval=1000.0 / self.fps, blit=False, repeat=True)
        return self._animation

    def __len__(self) -> int:
        return len(self.times)

    def frame(self, k: int) -> list[Any]:
        """Move every artist to frame ``k``; the artists changed."""
        k = int(k)
        shifts = self.scale * self.positions[:, k]
        moved = {name: self.scale * float(values[k]) for name, values in self.supports.items()}
        self.diagram.move(shifts, moved)
        self._readout.set_text(f"t = {self.times[k]:.2f} s")
        changed = [self._readout]
        fine, step, lines = self._curves
        for (line, dot), row in zip(lines, self._fine_values):
            line.set_data(fine[:k * step + 1], row[:k * step + 1])
            dot.set_data([fine[k * step]], [row[k * step]])
            changed += [line, dot]
        return changed

    def to_jshtml(self, *, dpi: float | None = None, default_mode: str = "loop",
                  frame_format: str = "png") -> str:
        """The animation as HTML with JavaScript controls (matplotlib's player; frames
        inline, as PNG or, smaller, JPEG, at ``dpi``, default the figure's). The player's
        buttons are drawn with Unicode symbols: it loads nothing from the network (see
        :func:`offline_player`)."""
        from matplotlib.animation import HTMLWriter

        writer = HTMLWriter(fps=self.fps, embed_frames=True, default_mode=default_mode)
        writer.frame_format = frame_format
        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / "animation.html"
            self._write(writer, path, dpi)
            return offline_player(path.read_text(encoding="utf-8"))

    def _repr_html_(self) -> str:
        return self.to_jshtml()

    def _write(self, writer: Any, path: Path, dpi: float | None) -> None:
        """Render every frame once into ``writer`` (no FuncAnimation event loop)."""
        with writer.saving(self.figure, str(path), self._dpi(dpi)):
            for k in range(len(self.times)):
                self.frame(k)
                writer.grab_frame()
        self.frame(0)

    def _dpi(self, dpi: object) -> float:
        """``dpi`` (the figure's when None) if it is a finite positive number giving frames
        of at most Limits.animation_max_frame_pixels pixels, else a SceneError."""
        if dpi is None:
            dpi = float(self.figure.dpi)
        if isinstance(dpi, bool) or not isinstance(dpi, (int, float, np.integer, np.floating)) \
                or not math.isfinite(dpi) or dpi <= 0:
            raise SceneError(f"animation: dpi must be a positive number, got {dpi!r}")
        _check_frame(self.figure, float(dpi))
        return float(dpi)

    def save(self, path: str | Path, *, dpi: float | None = None) -> Path:
        """Write the animation: ``.gif`` (pillow), ``.mp4`` (ffmpeg) or ``.html`` (to_jshtml).

        Raises
        ------
        SceneError
            For another suffix, or an MP4 without ffmpeg (on the PATH or from the optional
            ``imageio-ffmpeg`` package: ``pip install "laplace_springs[video]"``).
        """
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix == ".html":
            path.write_text(self.to_jshtml(dpi=dpi), encoding="utf-8")
            return path
        if suffix == ".gif":
            from matplotlib.animation import PillowWriter

            writer: Any = PillowWriter(fps=self.fps)
        elif suffix == ".mp4":
            writer = _ffmpeg_writer(self.fps)
        else:
            raise SceneError(f"animation: cannot write {str(path)!r}: the file name must end in "
                             ".gif, .mp4 or .html")
        self._write(writer, path, dpi)
        return path


#: matplotlib's player draws its buttons with Font Awesome icons from a CDN; these symbols
#: need no network.
_BUTTONS = {"fa fa-minus": "\u2212", "fa fa-fast-backward": "\u21e4", "fa fa-step-backward": "\u2190",
            "fa fa-play fa-flip-horizontal": "\u25c0", "fa fa-pause": "\u25ae\u25ae", "fa fa-play": "\u25b6",
            "fa fa-step-forward": "\u2192", "fa fa-fast-forward": "\u21e5", "fa fa-plus": "+"}
_STYLESHEET = re.compile(r"<link[^>]*font-awesome[^>]*>", re.IGNORECASE)


def offline_player(html: str) -> str:
    """matplotlib's ``to_jshtml`` output without its Font Awesome stylesheet (from a CDN):
    the buttons' icons become Unicode symbols.

    >>> offline_player('<link rel="stylesheet" href="https://x/font-awesome.css"><i class="fa fa-play"></i>')
    '<span aria-hidden="true">▶</span>'
    """
    html = _STYLESHEET.sub("", html)
    for icon, symbol in _BUTTONS.items():
        html = html.replace(f'<i class="{icon}"></i>', f'<span aria-hidden="true">{symbol}</span>')
    return html


def _ffmpeg_writer(fps: int) -> Any:
    """matplotlib's FFMpegWriter, with ffmpeg from the PATH or from imageio-ffmpeg."""
    import matplotlib
    from matplotlib.animation import FFMpegWriter

    if shutil.which(str(matplotlib.rcParams["animation.ffmpeg_path"])) is None:
        try:
            import imageio_ffmpeg
        except ImportError:
            raise SceneError('animation: an .mp4 needs ffmpeg; install it, or pip install '
                             '"laplace_springs[video]" (imageio-ffmpeg), or save a .gif') from None
        matplotlib.rcParams["animation.ffmpeg_path"] = imageio_ffmpeg.get_ffmpeg_exe()
    return FFMpegWriter(fps=fps, codec="libx264", extra_args=["-pix_fmt", "yuv420p"])


def animate(solution: Motion, *, t_end: float | None = None, duration: float | None = None,
            speed: float | None = None, fps: int = FPS, curves: bool = True,
            masses: Sequence[Any] | None = None, show_values: bool = False,
            figsize: tuple[float, float] | None = None, title: str | bool = True) -> SceneAnimation:
    """Animate the scene's diagram along the solution (see the module notes).

    Parameters
    ----------
    solution : Solution
        A solution of a scene that can be drawn (any route; numbers, not parameters).
    t_end : float, optional
        The last time shown; :func:`~laplace_springs.output.plots.default_t_end` by default.
    duration, speed : float, optional
        The clip's length in seconds, or simulated seconds per second of clip (one of
        them; by default about twelve frames per period of the fastest oscillation).
    fps : int
        Frames per second of clip.
    curves : bool
        Draw the x(t) curves beside the diagram, up to the current time.
    masses : sequence of int or str, optional
        The masses to animate (1-based numbers or coordinate names); all of a small scene,
        an evenly spaced subset of a large one.
    show_values : bool
        Write the values beside the labels.
    figsize : (float, float), optional
        Figure size in inches.
    title : str or bool
        The diagram's title (True: the scene's).

    Returns
    -------
    SceneAnimation

    Raises
    ------
    SceneError
        For a scene with free parameters or that cannot be drawn, bad timing options, or
        too many frames or masses (see :class:`~laplace_springs.limits.Limits`).

    Examples
    --------
    >>> import laplace_springs as ls
    >>> movie = animate(ls.solve(ls.load_scene("wall-pair")), duration=1, fps=5)
    >>> len(movie), movie.positions.shape
    (6, (2, 6))
    >>> _ = movie.frame(3)
    >>> bool(np.allclose(movie.diagram.block_positions() / movie.scale, movie.positions[:, 3]))
    True
    """
    scene = solution.scene
    if scene.free_symbols:
        names = ", ".join(sorted(s.name for s in scene.free_symbols))
        raise SceneError(f"animate: the scene has parameters ({names}); give them values with "
                         "scene.subs({...}) first")
    chosen = _chosen_masses(scene, masses)
    chain = _sub_chain(scene, chosen)
    times = frame_times(solution, t_end=t_end, duration=duration, speed=speed, fps=fps)
    fine = _fine_times(solution, times)
    values = np.asarray(solution.evaluate(fine), dtype=float)[chosen]  # one vectorised call
    step = (len(fine) - 1) // (len(times) - 1)
    positions = values[:, ::step]  # the frames' times are every step-th of the curves' times
    supports = _support_motion(scene, times)
    largest = max([float(np.max(np.abs(positions), initial=0.0))]
                  + [float(np.max(np.abs(u), initial=0.0)) for u in supports.values()])
    scale = MAX_SHIFT / largest if largest > 0 else 1.0
    figure, diagram_ax, curve_ax = _figure(orientation_of(chain), curves, figsize)
    if title is True:
        title = scene.title + (f" (masses {', '.join(chain.coordinates)} of {scene.n})"
                               if len(chosen) < scene.n else "")
    diagram = build_diagram(scene, diagram_ax, show_values=show_values, title=title, chain=chain)
    if curve_ax is None:  # room for the readout above the drawing
        low, high = diagram_ax.get_ylim()
        diagram_ax.set_ylim(low, high + 0.5)
    readout = _readout(diagram_ax if curve_ax is None else curve_ax)
    lines = _curves(curve_ax, fine, values, chain, scene) if curve_ax is not None else []
    movie = SceneAnimation(figure, diagram, times, positions, supports, chosen, scale, fps,
                           (fine, step, lines), readout, values)
    movie.frame(0)
    return movie


def _readout(ax: Any) -> Any:
    """The time readout: top left inside the curves' axes (or the diagram's), on white."""
    return ax.text(0.015, 0.97, "t = 0.00 s", transform=ax.transAxes, ha="left", va="top",
                   fontsize=11, family="monospace", zorder=10,
                   bbox={"facecolor": "white", "edgecolor": "0.7", "boxstyle": "round,pad=0.25"})


def _fine_times(solution: Motion, times: np.ndarray) -> np.ndarray:
    """The curves' times: the frames' times and (step - 1) between each two, 40 per fastest
    period and 600 in all at least (the frames' times are exactly every step-th)."""
    poles = np.asarray(solution.poles, dtype=complex)
    fastest = float(np.max(np.abs(poles.imag), initial=0.0))
    wanted = max(600, int(40 * float(times[-1]) * fastest / (2 * math.pi)))
    intervals = len(times) - 1
    step = max(1, min(-(-wanted // intervals), 64))
    fine = np.linspace(0.0, float(times[-1]), intervals * step + 1)
    fine[::step] = times
    return fine


def _check_frame(figure: Any, dpi: float) -> None:
    """Refuse frames of more than Limits.animation_max_frame_pixels pixels at ``dpi``."""
    width, height = (float(v) for v in figure.get_size_inches())
    pixels, most = width * height * dpi**2, limits().animation_max_frame_pixels
    if pixels > most:
        largest = math.sqrt(most / (width * height))
        raise SceneError(f"animation: {width:g} x {height:g} inches at dpi = {dpi:g} gives frames of "
                         f"{pixels:,.0f} pixels, more than Limits.animation_max_frame_pixels = "
                         f"{most:,}; use dpi <= {largest:.3g} or a smaller figsize")


def _figure(orientation: str, curves: bool, figsize: tuple[float, float] | None) -> tuple[Any, Any, Any]:
    """A figure (outside pyplot) with the diagram's axes and, optionally, the curves' axes."""
    from matplotlib.figure import Figure

    if figsize is not None:
        try:
            width, height = (float(v) for v in figsize)
        except (TypeError, ValueError):
            raise SceneError(f"animate: figsize must be (width, height) in inches, got {figsize!r}") from None
        if not (math.isfinite(width) and math.isfinite(height) and width > 0 and height > 0):
            raise SceneError(f"animate: figsize must be two positive numbers (inches), got {figsize!r}")
        _check_frame(Figure(figsize=(width, height)), float(Figure().dpi))
    horizontal = orientation == "horizontal"
    if not curves:
        figure = Figure(figsize=figsize or ((9.0, 3.2) if horizontal else (4.0, 6.5)), layout="constrained")
        return figure, figure.subplots(), None
    if horizontal:
        figure = Figure(figsize=figsize or (9.0, 6.5), layout="constrained")
        top, bottom = figure.subplots(2, 1, height_ratios=(1.0, 1.3))
        return figure, top, bottom
    figure = Figure(figsize=figsize or (11.0, 6.0), layout="constrained")
    left, right = figure.subplots(1, 2, width_ratios=(1.0, 2.2))
    return figure, left, right


def _curves(ax: Any, times: np.ndarray, positions: np.ndarray, chain: Chain,
            scene: Scene | None = None) -> list[tuple[Any, Any]]:
    """The x(t) curves' axes: full extent, faint guides, and the lines drawn frame by frame; the
    axes say the scene's units, or none for a scene written without units."""
    lines = []
    for row, name in zip(positions, chain.coordinates):
        (guide,) = ax.plot(times, row, linewidth=1.0, alpha=0.25)
        (line,) = ax.plot(times[:1], row[:1], linewidth=2.2, color=guide.get_color(),
                          label=f"{math_label(name)[:-1]}(t)$")
        (dot,) = ax.plot(times[:1], row[:1], "o", color=guide.get_color(), markersize=6)
        lines.append((line, dot))
    ax.axhline(0.0, color="0.6", linewidth=0.8, zorder=0)
    ax.set_xlim(times[0], times[-1])
    ax.set_xlabel(axis_label("time", scene))
    ax.set_ylabel(axis_label("position", scene))
    ax.grid(alpha=0.3)
    ax.legend(loc="upper right", framealpha=0.85, fontsize="small",
              ncols=2 if len(lines) > 6 else 1)
    return lines
