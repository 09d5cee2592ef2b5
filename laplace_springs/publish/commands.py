"""The ``animate`` and ``page`` subcommands of the command line.

Examples
--------
::

    laplace-springs animate wall-pair -o wall-pair.gif
    laplace-springs animate three-dashpots -o pair.mp4 --duration 6 --fps 25
    laplace-springs animate chain.toml -o chain.gif --masses x1,x50,x100 --no-curves
    laplace-springs page three-dashpots -o page.html
    laplace-springs page three-dashpots -o page.tex     # the LaTeX document instead
"""

from __future__ import annotations

import argparse
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any, TextIO

from ..model.errors import SceneError
from ..model.options import strict_float, strict_int
from ..model.scene import Scene
from ..output.animation import animate
from ..solving import solve
from .page import worked_example

__all__ = ["add_publish_commands"]

SceneReader = Callable[[argparse.Namespace], Scene]


def add_publish_commands(commands: Any, add_common_options: Callable[[argparse.ArgumentParser], None],
                         scene_of: SceneReader) -> None:
    """Add ``animate`` and ``page`` to the command line's subcommands.

    ``add_common_options`` adds ``--param`` and ``--debug``; ``scene_of`` reads the scene the
    arguments name (both from :mod:`laplace_springs.cli`).
    """
    movie = commands.add_parser(
        "animate", help="animate a scene's diagram along its motion (GIF, MP4 or HTML)",
        description="Animate the scene's diagram (masses sliding, springs stretching) along the "
                    "solution, with its x(t) curves; the file suffix picks the format.")
    movie.add_argument("scene", metavar="SCENE", help="a bundled scene name or a .toml path")
    movie.add_argument("-o", "--output", metavar="FILE", required=True,
                       help="the file to write: .gif, .mp4 (needs ffmpeg) or .html")
    movie.add_argument("--t-end", type=strict_float, metavar="T", help="last time shown (default: a few periods)")
    timing = movie.add_mutually_exclusive_group()
    timing.add_argument("--duration", type=strict_float, metavar="S", help="length of the clip in seconds")
    timing.add_argument("--speed", type=strict_float, metavar="X", help="simulated seconds per second of clip")
    movie.add_argument("--fps", type=strict_int, default=20, help="frames per second (default 20)")
    movie.add_argument("--masses", metavar="X1,X2,...", help="animate these coordinates only")
    movie.add_argument("--no-curves", action="store_true", help="the diagram alone, without x(t)")
    movie.add_argument("--values", action="store_true", help="write the values beside the labels")
    movie.add_argument("--dpi", type=strict_float, default=80, help="resolution of the frames (default 80)")
    add_common_options(movie)
    movie.set_defaults(run=lambda args, out: _run_animate(args, out, scene_of))

    page = commands.add_parser(
        "page", help="write a worked-example page (HTML, works offline) or LaTeX document",
        description="Write a self-contained worked example of the scene: diagram, equations, "
                    "matrices, Δ(λ), resolvent, partial fractions, solution, residuals, plots, "
                    "animation and sliders; .html (typeset offline by the packaged MathJax) or "
                    ".tex (a standalone document).")
    page.add_argument("scene", metavar="SCENE", help="a bundled scene name or a .toml path")
    page.add_argument("-o", "--output", metavar="FILE", required=True, help="page.html or document.tex")
    page.add_argument("--no-animation", action="store_true", help="leave the animation out (a smaller page)")
    add_common_options(page)
    page.set_defaults(run=lambda args, out: _run_page(args, out, scene_of))


def _run_animate(args: argparse.Namespace, out: TextIO, scene_of: SceneReader) -> None:
    path = Path(args.output)
    if path.suffix.lower() not in (".gif", ".mp4", ".html"):
        raise SceneError(f"animate: -o {args.output!r}: the file name must end in .gif, .mp4 or .html")
    masses = _masses_option(args.masses) if args.masses else None
    solution = solve(scene_of(args))
    movie = animate(solution, t_end=args.t_end, duration=args.duration, speed=args.speed,
                    fps=args.fps, curves=not args.no_curves, masses=masses, show_values=args.values)
    movie.save(path, dpi=args.dpi)
    print(f"wrote {path} ({len(movie)} frames, t = 0 to {movie.times[-1]:g} s)", file=out)


def _masses_option(text: str) -> list[str | int]:
    """``--masses x1,x3`` or ``1,3``: coordinate names, or their numbers from 1.

    >>> _masses_option("x1, 3")
    ['x1', 3]
    >>> _masses_option("1,,2")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: animate: --masses '1,,2': item 2 is empty
    """
    items: list[str | int] = []
    for position, item in enumerate((part.strip() for part in text.split(",")), start=1):
        if not item:
            raise SceneError(f"animate: --masses {text!r}: item {position} is empty")
        items.append(int(item) if re.fullmatch(r"[0-9]+", item) else item)
    return items


def _run_page(args: argparse.Namespace, out: TextIO, scene_of: SceneReader) -> None:
    path = Path(args.output)
    suffix = path.suffix.lower()
    if suffix not in (".html", ".htm", ".tex"):
        raise SceneError(f"page: -o {args.output!r}: the file name must end in .html or .tex")
    example = worked_example(scene_of(args), animation=not args.no_animation and suffix != ".tex")
    if suffix == ".tex":
        example.save_tex(path)
    else:
        example.save_html(path)
    print(f"wrote {path}", file=out)
