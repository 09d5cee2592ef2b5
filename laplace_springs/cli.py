"""Command-line interface: ``laplace-springs solve SCENE`` and ``laplace-springs scenes``.

Examples
--------
Print the closed form, the LaTeX, or a table of values of a bundled scene::

    laplace-springs solve vertical-pair
    laplace-springs solve vertical-pair --latex
    laplace-springs solve wall-pair-dashpot --latex --standalone -o wall-pair-dashpot.tex
    laplace-springs solve wall-pair-dashpot --at 0,0.5,1 --dps 30
    laplace-springs solve three-dashpots --plot motion.png
    laplace-springs scenes
    laplace-springs bench --quick -o bench-out

Errors (a bad scene file, an unknown scene, a bad option value) are reported as one
line ``laplace-springs: error: ...`` on stderr with exit status 2, like argparse's own
usage errors.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from collections.abc import Sequence
from typing import TextIO

import mpmath
import numpy as np
import sympy as sp

from ._version import __version__
from .analysis.frequency import frequency_response
from .analysis.modes import modes
from .bench import harness as bm
from .model.scene import Scene
from .model.scene_files import bundled_scenes, load_scene
from .model.symbols import lam
from .output.plots import overview_figure, plot_frequency_response
from .solution import Solution
from .solve import solve

__all__ = ["main"]

PROG = "laplace-springs"

#: Significant digits of the ``--at`` table when no ``--dps`` is given.
TABLE_DIGITS = 12

_EXIT_ERROR = 2


def _build_parser() -> argparse.ArgumentParser:
    """The argument parser with its ``solve`` and ``scenes`` subcommands."""
    parser = argparse.ArgumentParser(
        prog=PROG,
        description="Exact Laplace-transform solutions of spring-mass-damper systems.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    solve = commands.add_parser("solve", help="solve a scene and print x(t)",
                                description="Solve a scene exactly and print x(t).")
    solve.add_argument("scene", metavar="SCENE",
                       help="a bundled scene name (see 'laplace-springs scenes') or a .toml path")
    output = solve.add_mutually_exclusive_group()
    output.add_argument("--pretty", action="store_true",
                        help="print each coordinate as a 2-D pretty-printed formula")
    output.add_argument("--latex", action="store_true",
                        help="print x(t) in LaTeX (aligned blocks, named constants defined)")
    output.add_argument("--at", metavar="T1,T2,...",
                        help="print a table of values at these times (t >= 0)")
    solve.add_argument("--dps", type=int, metavar="N",
                       help="with --at: evaluate with N decimal digits (mpmath) and print N digits")
    solve.add_argument("--plot", metavar="FILE",
                       help="also save the scene's diagram and its motion to FILE (.png, .pdf, .svg)")
    solve.add_argument("--standalone", action="store_true",
                       help="with --latex: a complete .tex document (pdflatex, amsmath)")
    solve.add_argument("-o", "--output", metavar="FILE",
                       help="with --latex: write to FILE instead of standard output")
    solve.add_argument("--forcing", action="append", metavar="F",
                       help="external force: one per coordinate in order (repeat the option), "
                            "or NAME=EXPR for one coordinate, e.g. --forcing 'x1=10*cos(20*t)'; "
                            "replaces the scene file's forcing")
    solve.set_defaults(run=_run_solve)

    scenes = commands.add_parser("scenes", help="list the bundled scenes",
                                 description="List the bundled scenes: name and title.")
    scenes.set_defaults(run=_run_scenes)
    _add_bench_command(commands)
    _add_response_command(commands)
    return parser


def parse_times(text: str) -> list[float]:
    """Times from a comma-separated list, such as ``"0,0.5,1"``.

    Parameters
    ----------
    text : str
        Comma-separated numbers; spaces around items are allowed.

    Returns
    -------
    list of float

    Raises
    ------
    ValueError
        For an empty item, text that is not a number, NaN, infinity or a negative time;
        the message quotes the offending item.

    Examples
    --------
    >>> parse_times("0, 0.5,1e-3")
    [0.0, 0.5, 0.001]
    >>> parse_times("1,abc")
    Traceback (most recent call last):
    ...
    ValueError: --at: 'abc' is not a number (give times like 0,0.5,1)
    """
    return [_parse_time(item.strip()) for item in text.split(",")]


def _parse_time(item: str) -> float:
    try:
        value = float(item)
    except ValueError:
        raise ValueError(f"--at: {item!r} is not a number (give times like 0,0.5,1)") from None
    if not math.isfinite(value):
        raise ValueError(f"--at: time must be finite, got {item!r}")
    if value < 0:
        raise ValueError(f"--at: time must be >= 0 (the solution holds for t >= 0), got {item!r}")
    return value


def _check_dps(args: argparse.Namespace) -> None:
    if args.dps is None:
        return
    if args.at is None:
        raise ValueError("--dps needs --at (it sets the precision of the table of values)")
    if not 1 <= args.dps <= 10_000:
        raise ValueError(f"--dps must be between 1 and 10000, got {args.dps}")


def _root_names(exprs: Sequence[sp.Expr]) -> dict[sp.CRootOf, sp.Symbol]:
    """Short names r1, r2, ... for the CRootOf objects in the expressions."""
    roots = sorted(set().union(*(e.atoms(sp.CRootOf) for e in exprs)), key=sp.default_sort_key)
    return {root: sp.Symbol(f"r{j}") for j, root in enumerate(roots, start=1)}


def _root_legend(names: dict[sp.CRootOf, sp.Symbol]) -> list[str]:
    """Lines ``where r1 = CRootOf(...) ≈ value`` for the named roots."""
    if not names:
        return []
    lines = ["where (algebraic numbers: CRootOf(p, k) is the k-th root of p)"]
    for root, name in names.items():
        # CRootOf holds a generator-free PurePoly, and SymPy's cache may hand back an
        # instance first built in another variable: always print p in λ.
        poly = sp.sstr(root.poly.as_expr(lam))
        lines.append(f"  {name} = CRootOf({poly}, {root.index}) ≈ {sp.sstr(sp.N(root, 15))}")
    return lines


def _formula_lines(scene: Scene, solution: Solution, *, pretty: bool) -> list[str]:
    """``x1(t) = ...`` for each coordinate, with long root objects named once."""
    exprs = list(solution.x)
    names = _root_names(exprs)
    lines = []
    for name, expr in zip(scene.names, exprs):
        short = expr.xreplace(names)
        if pretty:
            lines += [f"{name}(t) =", sp.pretty(short, use_unicode=True), ""]
        else:
            lines.append(f"{name}(t) = {sp.sstr(short)}")
    return lines + _root_legend(names)


def _format_value(value, digits: int) -> str:
    if isinstance(value, mpmath.mpf):
        return mpmath.nstr(value, digits, min_fixed=-4, max_fixed=digits)
    return f"{float(value):.{digits}g}"


def _format_time(time: float) -> str:
    """A time as typed: 12 significant digits when they say it all, else Python's repr."""
    short = f"{time:.12g}"
    return short if float(short) == time else repr(time)


def _table_lines(names: Sequence[str], times: Sequence[float], values, digits: int,
                 variable: str = "t") -> list[str]:
    """A right-aligned table: t (or ``variable``) then one column per coordinate."""
    width = digits + 8
    rows = ["  ".join(cell.rjust(width) for cell in [variable, *names])]
    for col, time in enumerate(times):
        cells = [_format_time(time)] + [_format_value(values[i, col], digits)
                                          for i in range(len(names))]
        rows.append("  ".join(cell.rjust(width) for cell in cells))
    return rows


def _run_solve(args: argparse.Namespace, out: TextIO) -> None:
    _check_dps(args)
    _check_latex_options(args)
    times = parse_times(args.at) if args.at is not None else None
    scene = load_scene(args.scene)
    if args.forcing:
        scene = scene.with_forcing(_forcing_argument(scene, args.forcing))
    solution = solve(scene)
    if args.plot:
        _save_plot(solution, args.plot)
    if args.latex:
        _write_latex(solution, args, out)
        return
    lines = [scene.title] if scene.title else []
    if times is not None:
        values = solution.evaluate(times, dps=args.dps)
        lines += _table_lines(scene.names, times, values, args.dps or TABLE_DIGITS)
    else:
        lines += _formula_lines(scene, solution, pretty=args.pretty)
    print("\n".join(lines), file=out)


def _forcing_argument(scene: Scene, items: Sequence[str]) -> list[str] | dict[str, str]:
    """``--forcing`` values: all positional (one per coordinate) or all NAME=EXPR."""
    named = ["=" in item for item in items]
    if any(named) and not all(named):
        raise ValueError("--forcing: give either one expression per coordinate or NAME=EXPR items, not both")
    if not all(named):
        if len(items) != scene.n:
            raise ValueError(f"--forcing was given {len(items)} times; the scene has {scene.n} "
                             f"coordinates ({', '.join(scene.names)}); use NAME=EXPR for fewer")
        return list(items)
    pairs = dict(item.split("=", 1) for item in items)
    return {name.strip(): text for name, text in pairs.items()}


def _add_response_command(commands) -> None:
    """``laplace-springs response``: modes and the frequency response of a scene."""
    response = commands.add_parser(
        "response", help="natural frequencies, damping ratios and the frequency response",
        description="Print the modes of a scene (natural and damped frequencies, damping "
                    "ratios, shapes) and, with --plot, draw |H(iω)| and its phase.")
    response.add_argument("scene", metavar="SCENE", help="a bundled scene name or a .toml path")
    response.add_argument("--plot", metavar="FILE", help="save the frequency-response plot to FILE")
    response.add_argument("--force", type=int, default=1, metavar="J",
                          help="the coordinate (1-based) the unit harmonic force acts on (default 1)")
    response.add_argument("--at", metavar="W1,W2,...",
                          help="print the amplitude of each coordinate per unit force at these frequencies")
    response.set_defaults(run=_run_response)


def _run_response(args: argparse.Namespace, out: TextIO) -> None:
    scene = load_scene(args.scene)
    if not 1 <= args.force <= scene.n:
        raise ValueError(f"--force must be between 1 and {scene.n}, got {args.force}")
    lines = [scene.title] if scene.title else []
    lines.append(f"{'mode':>4}  {'omega_n':>12}  {'zeta':>10}  {'omega_d':>12}  shape")
    for k, mode in enumerate(modes(scene), start=1):
        zeta = "-" if mode.damping_ratio is None else f"{float(mode.damping_ratio):.6g}"
        shape = ", ".join(_format_complex(v) for v in mode.shape)
        lines.append(f"{k:>4}  {float(mode.natural_frequency):>12.6g}  {zeta:>10}  "
                     f"{float(mode.damped_frequency):>12.6g}  [{shape}]  ({mode.kind})")
    if args.at is not None:
        omegas = parse_times(args.at)
        H = frequency_response(scene, omegas)[:, :, args.force - 1]
        lines.append(f"amplitude per unit force on {scene.names[args.force - 1]}:")
        lines += _table_lines(scene.names, omegas, np.abs(H).T, TABLE_DIGITS, variable="omega")
    if args.plot:
        _save_response_plot(scene, args.force - 1, args.plot)
        lines.append(f"wrote {args.plot}")
    print("\n".join(lines), file=out)


def _format_complex(value: complex) -> str:
    if abs(value.imag) < 1e-12:
        return f"{value.real:.6g}"
    return f"{value.real:.6g}{value.imag:+.6g}i"


def _save_response_plot(scene: Scene, force: int, path: str) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
    except ImportError as exc:
        raise ValueError(f"--plot needs matplotlib ({exc}); pip install 'laplace_springs[plots]'") from None
    plot_frequency_response(scene, force=force).savefig(path, dpi=100)


def _check_latex_options(args: argparse.Namespace) -> None:
    if (args.standalone or args.output) and not args.latex:
        raise ValueError("--standalone and -o/--output go with --latex")


def _write_latex(solution: Solution, args: argparse.Namespace, out: TextIO) -> None:
    """The LaTeX of ``solution`` on ``out`` or, with ``-o FILE``, into FILE."""
    text = solution.latex(standalone=args.standalone)
    if not args.output:
        print(text, file=out)
        return
    with open(args.output, "w", encoding="utf-8") as handle:
        handle.write(text if text.endswith("\n") else text + "\n")
    print(f"wrote {args.output}", file=out)


def _save_plot(solution: Solution, path: str) -> None:
    """Write the diagram and motion plot (no display needed)."""
    try:
        figure = overview_figure(solution)
    except ImportError as exc:
        raise ValueError(f"--plot needs matplotlib ({exc}); pip install 'laplace_springs[plots]'") from None
    figure.savefig(path, dpi=100)


def _add_bench_command(commands) -> None:
    """``laplace-springs bench``: error against run time (see laplace_springs.bench.harness)."""
    bench = commands.add_parser(
        "bench", help="error against run time: our routes and the peers on the battery",
        description="Measure error (against a 60-digit reference) and run time of every "
                    "method on every battery scene; write report.md, results.csv and "
                    "plots/<scene>.png, and print the Pareto verdicts.")
    bench.add_argument("-o", "--out", default="bench-out", metavar="DIR",
                       help="output directory (default: bench-out)")
    bench.add_argument("--scenes", metavar="PATTERNS",
                       help="comma-separated glob patterns of battery scene names")
    bench.add_argument("--methods", metavar="PATTERNS",
                       help="comma-separated glob patterns of method names (e.g. 'ours*,ivp-*')")
    bench.add_argument("--quick", action="store_true",
                       help="a smaller method set (one tolerance per solver, no SymPy)")
    bench.add_argument("--large", action="store_true", help="include the battery's large scenes")
    bench.add_argument("--time-limit", type=float, default=2.0, metavar="SECONDS",
                       help="per-run limit of a peer (default 2; raised where ours is slower)")
    bench.add_argument("--sympy-limit", type=float, default=10.0, metavar="SECONDS",
                       help="limit of SymPy's inversion per scene (default 10)")
    bench.add_argument("--no-plots", action="store_true", help="skip the PNG plots")
    bench.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    bench.add_argument("--list", action="store_true", help="list scenes and methods, run nothing")

    def run(args: argparse.Namespace, out: TextIO) -> None:
        if args.time_limit <= 0 or args.sympy_limit <= 0:
            raise ValueError("--time-limit and --sympy-limit must be positive")
        def split(text):
            return ([p.strip() for p in text.split(",") if p.strip()] if text else None)
        if args.list:
            cases = bm.default_cases(large=args.large)
            print("scenes: " + ", ".join(case.name for case in cases), file=out)
            methods = bm.select_methods(quick=args.quick)
            print("methods: " + ", ".join(m.name for m in methods), file=out)
            return
        settings = bm.BenchSettings(time_limit=args.time_limit, sympy_limit=args.sympy_limit)
        result = bm.run_benchmark(methods=split(args.methods), scenes=split(args.scenes),
                                  out_dir=args.out, quick=args.quick, large=args.large,
                                  settings=settings, progress=not args.no_progress,
                                  plots=not args.no_plots)
        lines = bm.summary_lines(result) + [f"wrote {path}" for key, path in result.files.items()
                                            if not key.startswith("plot:")]
        print("\n".join(lines), file=out)

    bench.set_defaults(run=run)


def _run_scenes(args: argparse.Namespace, out: TextIO) -> None:
    scenes = bundled_scenes()
    width = max((len(name) for name in scenes), default=0)
    for name, title in scenes.items():
        print(f"{name.ljust(width)}  {title}", file=out)


def _report(message: str) -> int:
    """Print one error line to stderr and return the error exit status."""
    one_line = " ".join(str(message).split())
    print(f"{PROG}: error: {one_line}", file=sys.stderr)
    return _EXIT_ERROR


def main(argv: list[str] | None = None) -> int:
    """Run the command line.

    Parameters
    ----------
    argv : list of str, optional
        The arguments after the program name; ``sys.argv[1:]`` when omitted.

    Returns
    -------
    int
        Exit status: 0 on success, 2 for a usage error or a bad scene, option value or
        file (reported as one line ``laplace-springs: error: ...`` on stderr).
    """
    parser = _build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or an argparse usage error
        return exc.code if isinstance(exc.code, int) else _EXIT_ERROR
    try:
        args.run(args, sys.stdout)
        sys.stdout.flush()
    except BrokenPipeError:  # output piped into `head` and closed early: stop quietly
        _silence_stdout()
        return 1
    except (ValueError, OSError) as exc:  # SceneError and InversionError are ValueErrors
        return _report(str(exc) or type(exc).__name__)
    return 0


def _silence_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's final flush does not fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):  # stdout without a file descriptor
        pass
