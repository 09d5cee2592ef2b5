"""Command-line interface: ``laplace-springs solve SCENE`` and ``laplace-springs scenes``.

Examples
--------
Print the closed form, the LaTeX, or a table of values of a bundled scene::

    laplace-springs solve vertical-pair
    laplace-springs solve three-dashpots --pretty
    laplace-springs solve vertical-pair --modes
    laplace-springs solve chain.toml                 # a large scene: its modal summary
    laplace-springs solve chain.toml --formula --coordinates x1,x2
    laplace-springs solve vertical-pair --latex
    laplace-springs solve wall-pair-dashpot --latex --standalone -o wall-pair-dashpot.tex
    laplace-springs solve wall-pair-dashpot --at 0,0.5,1 --dps 30
    laplace-springs solve three-dashpots --plot motion.png
    laplace-springs solve my-scene.toml --param k=2 --param c=1/2 --at 0,1
    laplace-springs solve --equations eqs.txt --param k=4   # from the equations of motion
    laplace-springs scenes
    laplace-springs bench --quick -o bench-out

Every number given to an option must be finite, and every output path (``--plot``,
``-o``) is checked before any work starts: a directory, a device or FIFO, a missing
folder or a missing or unknown suffix is refused, so no file appears anywhere else.
Errors of the user (a bad scene file, an unknown scene, a bad option value, a scene
beyond the documented limits, a file that cannot be written) are reported as one line
``laplace-springs: error: ...`` on stderr with exit status 2, like argparse's own usage
errors. An internal error (a bug) is one line ``laplace-springs: internal error: ...``
with exit status 1; ``--debug`` shows its traceback. No text is ever evaluated as Python.
"""

from __future__ import annotations

import argparse
import math
import os
import re
import stat
import sys
import traceback
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import TextIO

import mpmath
import numpy as np
import sympy as sp

from ._version import __version__
from .analysis.frequency import frequency_response
from .analysis.modes import float_modes, modes
from .exact.screening import has_exact_form
from .limits import limits
from .model.errors import InitialDataWarning, InversionError, SceneError
from .model.forcing import parse_forcing
from .model.names import coordinate_index
from .model.numbers import NOT_FINITE_REAL, split_unit
from .model.options import NOT_FINITE as _NOT_FINITE
from .model.options import PLAIN_NUMBER as _PLAIN_NUMBER
from .model.options import strict_float, strict_int
from .model.scene import Scene
from .model.scene_files import bundled_scenes, load_scene
from .model.text_files import read_text_file
from .model.units import (
    frequencies_to_rad_per_second,
    in_length_unit,
    times_to_seconds,
    unit_note_text,
)
from .output.plots import overview_figure, plot_frequency_response
from .output.text import formula_lines, formula_terms, modal_formula_lines, summary_lines
from .solution import Solution
from .solving import solve

__all__ = ["main"]

PROG = "laplace-springs"

#: Significant digits of the ``--at`` table when no ``--dps`` is given.
TABLE_DIGITS = 12
#: Largest number of terms ``--formula`` prints for a scene beyond the exact form
#: (coordinates × terms per coordinate); choose coordinates with ``--coordinates``.
FORMULA_MAX_TERMS = 4000

_EXIT_ERROR = 2
_EXIT_INTERNAL = 1
_EXIT_INTERRUPTED = 130


class UsageError(ValueError):
    """A bad option value or combination on the command line."""


#: Errors that are the user's to fix (exit status 2), and so is a ValueError raised by this
#: package's own checks; anything else is internal (1).
_USER_ERRORS = (UsageError, SceneError, InversionError, ArithmeticError, OSError)
_PACKAGE = os.path.dirname(os.path.abspath(__file__))


def _is_user_error(exc: BaseException) -> bool:
    """Whether ``exc`` reports bad input rather than a bug."""
    if isinstance(exc, _USER_ERRORS):
        return True
    if not isinstance(exc, ValueError) or exc.__traceback__ is None:
        return False
    frames = traceback.extract_tb(exc.__traceback__)
    return os.path.abspath(frames[-1].filename).startswith(_PACKAGE)  # raised by our own check


#: Subcommands that need none of the publish stage's modules (animation, pages, sweeps):
#: ``animate`` and ``page`` are added to the parser only for the others and the help.
_CORE_COMMANDS = ("solve", "scenes", "bench", "response")


def _needs_publish(argv: Sequence[str]) -> bool:
    """Whether the parser must hold ``animate`` and ``page``: unless the first word that is
    not an option names a core command."""
    first = next((word for word in argv if not word.startswith("-")), None)
    return first not in _CORE_COMMANDS


def _build_parser(*, publish: bool = True) -> argparse.ArgumentParser:
    """The argument parser with its subcommands (``animate`` and ``page`` when ``publish``)."""
    parser = argparse.ArgumentParser(
        prog=PROG,
        description="Exact Laplace-transform solutions of spring-mass-damper systems.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument("--debug", action="store_true", help="show the traceback of an internal error")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    solve = commands.add_parser("solve", help="solve a scene and print x(t)",
                                description="Solve a scene exactly and print x(t).")
    solve.add_argument("scene", metavar="SCENE", nargs="?",
                       help="a bundled scene name (see 'laplace-springs scenes') or a .toml path")
    solve.add_argument("--equations", metavar="FILE",
                       help="read the scene from its equations of motion instead (a text file: "
                            "x1'' + 3*x1 - x2 = 0 ..., x1(0) = 1/20, x1'(0) = 2; primes, SymPy or "
                            "Mathematica notation; --param values fill its names)")
    output = solve.add_mutually_exclusive_group()
    output.add_argument("--pretty", action="store_true",
                        help="print the formula (or the modes) in Unicode: α₁, β₁, e^(α₁·t), c₁")
    output.add_argument("--latex", action="store_true",
                        help="print x(t) in LaTeX (aligned blocks, named constants defined)")
    output.add_argument("--at", metavar="T1,T2,...",
                        help="print a table of values at these times (t >= 0)")
    shown = solve.add_mutually_exclusive_group()
    shown.add_argument("--formula", action="store_true",
                       help="print the formula x(t) (the default up to "
                            f"{limits().exact_form_max_coordinates} coordinates; larger scenes print "
                            "their modal summary unless asked)")
    shown.add_argument("--modes", action="store_true",
                       help="print the modal summary: natural frequencies, damping ratios and "
                            "each mode's part in the initial data")
    solve.add_argument("--coordinates", metavar="NAMES",
                       help="with the formula: only these coordinates (or masses), e.g. x1,x5")
    solve.add_argument("--dps", type=strict_int, metavar="N",
                       help="with --at: evaluate with N decimal digits (mpmath) and print N digits")
    solve.add_argument("--unit", metavar="UNIT",
                       help="for a scene written with units: the unit of x in the output, e.g. cm "
                            "(default m)")
    solve.add_argument("--plot", metavar="FILE",
                       help="also save the scene's diagram and its motion to FILE (.png, .pdf, .svg)")
    solve.add_argument("--standalone", action="store_true",
                       help="with --latex: a complete .tex document (pdflatex, amsmath)")
    solve.add_argument("-o", "--output", metavar="FILE",
                       help="with --latex: write to FILE instead of standard output")
    solve.add_argument("--forcing", action="append", metavar="F",
                       help="external force: one per coordinate in order (repeat the option), "
                            "or NAME=EXPR for one coordinate or mass, e.g. --forcing 'x1=10*cos(20*t)'; "
                            "replaces the scene file's forcing")
    _add_common_options(solve)
    solve.set_defaults(run=_run_solve)

    scenes = commands.add_parser("scenes", help="list the bundled scenes",
                                 description="List the bundled scenes: name and title.")
    scenes.set_defaults(run=_run_scenes)
    scenes.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help=argparse.SUPPRESS)
    _add_bench_command(commands)
    _add_response_command(commands)
    if publish:  # animate, page
        from .publish.commands import add_publish_commands  # start-up of the other commands
        add_publish_commands(commands, _add_common_options, _scene_of)
    return parser


def _add_common_options(command: argparse.ArgumentParser) -> None:
    """``--param`` and ``--debug``, shared by the commands that take a scene."""
    command.add_argument("--param", action="append", metavar="NAME=VALUE",
                         help="give a parameter of the scene a value, e.g. --param k=2 "
                              "(repeat for more; the value may be 1/2, 0.3 or use other parameters)")
    command.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                         help="show the traceback of an internal error")


def _scene_of(args: argparse.Namespace) -> Scene:
    """The scene named on the command line, with the ``--param`` values substituted."""
    values = _param_values(args.param or [])
    scene = _equations_scene(args, values) if getattr(args, "equations", None) else _named_scene(args)
    if not values:
        return scene
    try:
        return scene.subs(values)
    except SceneError as exc:
        raise SceneError(f"--param: {str(exc).removeprefix('subs: ')}") from None


def _named_scene(args: argparse.Namespace) -> Scene:
    if args.scene is None:
        raise UsageError("solve: give a SCENE (a bundled name or a .toml path) or --equations FILE")
    return load_scene(args.scene)


def _equations_scene(args: argparse.Namespace, values: dict[str, str]) -> Scene:
    """The scene of ``--equations FILE``; the ``--param`` names are its declared parameters."""
    if args.scene is not None:
        raise UsageError(f"solve: give a SCENE or --equations, not both (got {args.scene!r} and "
                         f"--equations {args.equations!r})")
    path = Path(args.equations)
    text = read_text_file(path, "equations file", "max_file_bytes", "utf-8-sig")
    try:
        return Scene.from_equations(text, parameters=list(values), title=path.stem)
    except SceneError as exc:
        hint = (" (in an equations file, declare names by a line 'parameters: k, c' or give "
                "values: a line 'k = 2', or --param k=2)") if "unknown name" in str(exc) else ""
        raise SceneError(f"{path}: {exc}{hint}") from None


def _param_values(items: Sequence[str]) -> dict[str, str]:
    """``--param NAME=VALUE`` items as a mapping."""
    values: dict[str, str] = {}
    for item in items:
        name, equals, value = item.partition("=")
        name = name.strip()
        if not equals or not name or not value.strip() or "=" in value:
            raise UsageError(f"--param: expected NAME=VALUE such as k=2, got {item!r}")
        if name in values:
            raise UsageError(f"--param: {name!r} is given twice")
        values[name] = value.strip()
    return values


def _require_numbers(scene: Scene, what: str) -> None:
    """Refuse ``what`` (a table of values, a plot, ...) for a scene with free parameters."""
    if not scene.free_symbols:
        return
    names = sorted(symbol.name for symbol in scene.free_symbols)
    example = " ".join(f"--param {name}=..." for name in names)
    raise UsageError(f"{what} needs numbers, but the scene has the parameter"
                     f"{'s' if len(names) > 1 else ''} {', '.join(names)}; give "
                     f"{'them values' if len(names) > 1 else 'it a value'} with {example}")


def parse_times(text: str) -> list[float]:
    """Times from a comma-separated list, such as ``"0,0.5,1"``.

    Parameters
    ----------
    text : str
        Comma-separated numbers; spaces around items are allowed. A time may carry a unit
        (``0.5s``, ``250 ms``, ``2 min``): it is converted to seconds.

    Returns
    -------
    list of float

    Raises
    ------
    UsageError
        A ValueError, for an empty item, text that is not a number, NaN, infinity or a
        negative time; the message quotes the offending item.

    Examples
    --------
    >>> parse_times("0, 0.5,1e-3")
    [0.0, 0.5, 0.001]
    >>> parse_times("0,0.5s,250ms,1 min")
    [0.0, 0.5, 0.25, 60.0]
    >>> parse_times("1,abc")
    Traceback (most recent call last):
    ...
    laplace_springs.cli.UsageError: --at: 'abc' is not a number (give times like 0,0.5,1)
    """
    return [_parse_time(item.strip()) for item in text.split(",")]


#: A plain number on the command line: ASCII digits, an optional point and exponent.
#: Python's float() takes more (``1_0``, Arabic-Indic ``٣``), which the entries of a scene
#: refuse: the command line reads numbers as they do.
def _plain_number(item: str, what: str, convert, example: str) -> float:
    """An ``--at`` item as a float: a plain number, NaN or an infinity (refused by the
    caller), or a number with a unit (``convert`` takes it to SI); else a UsageError."""
    if _NOT_FINITE.fullmatch(item):
        return float(item)
    if not _PLAIN_NUMBER.fullmatch(item):
        return _with_unit(item, convert, example)
    value = float(item)
    mantissa = item.lower().partition("e")[0]
    if value == 0 and mantissa.strip("+-.0"):
        raise UsageError(f"--at: {what} {item!r} is below the float64 range (about 5e-324) and "
                         f"would be read as 0")
    return value + 0.0  # -0 is 0


def _parse_time(item: str) -> float:
    value = _plain_number(item, "time", times_to_seconds, "give times like 0,0.5,1")
    if not math.isfinite(value):
        raise UsageError(f"--at: time must be finite, got {item!r}")
    if value < 0:
        raise UsageError(f"--at: time must be >= 0 (the solution holds for t >= 0), got {item!r}")
    return value


def _with_unit(item: str, convert, example: str) -> float:
    """An ``--at`` item with a unit, converted (seconds, rad/s), or a UsageError."""
    try:
        _, unit = split_unit(item, "--at")
    except SceneError:
        unit = ""
    if not unit:
        raise UsageError(f"--at: {item!r} is not a number ({example})")
    try:
        return float(convert(item))
    except SceneError as exc:
        raise UsageError(f"--at: {exc}") from None
    except (ValueError, TypeError):  # "1 2": digits and a space, no unit to convert
        raise UsageError(f"--at: {item!r} is not a number ({example})") from None


def parse_frequencies(text: str) -> list[float]:
    """Driving frequencies (rad/s) from a comma-separated list, such as ``"1,2.5"``.

    Parameters
    ----------
    text : str
        Comma-separated numbers; an item may carry a unit (``2Hz``, ``3 rpm``): it is
        converted to rad/s.

    Returns
    -------
    list of float

    Raises
    ------
    UsageError
        For an empty item, text that is not a number, NaN or infinity (also a number
        beyond the float64 range, such as ``1e400``); the message quotes the item.

    Examples
    --------
    >>> parse_frequencies("1, 2.5")
    [1.0, 2.5]
    >>> parse_frequencies("1,nan")
    Traceback (most recent call last):
    ...
    laplace_springs.cli.UsageError: --at: frequency must be finite, got 'nan'
    """
    return [_parse_frequency(item.strip()) for item in text.split(",")]


def _parse_frequency(item: str) -> float:
    value = _plain_number(item, "frequency", frequencies_to_rad_per_second,
                          "give frequencies like 1,2.5 or 1Hz,2Hz")
    if not math.isfinite(value):
        raise UsageError(f"--at: frequency must be finite, got {item!r}")
    return value


def _check_dps(args: argparse.Namespace) -> None:
    if args.dps is None:
        return
    if args.at is None:
        raise UsageError("--dps needs --at (it sets the precision of the table of values)")
    if not 1 <= args.dps <= 10_000:
        raise UsageError(f"--dps must be between 1 and 10000, got {args.dps}")


def _coordinates_of(scene: Scene, text: str | None) -> list[int] | None:
    """The coordinates ``--coordinates`` names (coordinate or mass names), in order given."""
    if text is None:
        return None
    chosen: list[int] = []
    for item in (part.strip() for part in text.split(",")):
        index = coordinate_index(item, "--coordinates", names=scene.names, mass_names=scene.mass_names)
        if index in chosen:
            raise UsageError(f"--coordinates: {item!r} is given twice")
        chosen.append(index)
    return chosen


def _check_shown_options(args: argparse.Namespace) -> None:
    if (args.formula or args.modes) and (args.latex or args.at is not None):
        raise UsageError("--formula and --modes go without --latex and --at")
    if args.coordinates is not None and (args.modes or args.latex or args.at is not None):
        raise UsageError("--coordinates goes with the formula (not with --modes, --latex or --at)")


def _is_large(scene: Scene) -> bool:
    """Beyond the exact form: the summary by default, the formula from float64 modes."""
    return not has_exact_form(scene)


def _large_formula_lines(scene: Scene, chosen: list[int] | None, pretty: bool) -> list[str]:
    """The formula of a large scene from its float64 modes, if it is small enough."""
    if scene.is_forced:
        raise UsageError(f"--formula: the formula of a forced scene of more than "
                         f"{limits().exact_form_max_coordinates} coordinates is not written out; "
                         f"tabulate it with --at")
    mode_list = float_modes(scene)
    count = len(chosen) if chosen is not None else scene.n
    terms = count * formula_terms(scene, mode_list)
    if terms > FORMULA_MAX_TERMS:
        raise UsageError(f"--formula: x(t) of {count} coordinates has up to {terms:,} terms "
                         f"(more than {FORMULA_MAX_TERMS:,}); choose coordinates with "
                         f"--coordinates {','.join(scene.names[:2])}, or see the modes with --modes")
    return modal_formula_lines(scene, chosen, pretty=pretty, mode_list=mode_list)


def _without_exact_form(scene: Scene, chosen: list[int] | None, pretty: bool,
                        why: str) -> list[str]:
    """Where the exact route has no closed form (a factor with irrational coefficients):
    a free scene's formula from its float64 modes, after a note saying why; a forced
    scene is tabulated instead (a UsageError that says how)."""
    if scene.is_forced:
        raise UsageError(f"x(t) has no closed form here ({why}); tabulate it with --at T1,T2,... "
                         "or see the free motion's modes with --modes")
    return [f"note: no exact closed form ({why}); x(t) from the float64 modes:",
            *_large_formula_lines(scene, chosen, pretty=pretty)]


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
    _check_shown_options(args)
    times = parse_times(args.at) if args.at is not None else None
    scene = _scene_of(args)
    if args.forcing:
        scene = scene.with_forcing(_forcing_argument(scene, args.forcing))
    if args.unit:
        scene = in_length_unit(scene, args.unit)  # x in that unit
    chosen = _coordinates_of(scene, args.coordinates)
    if times is not None:
        _require_numbers(scene, "a table of values (--at)")
    if args.plot:
        _require_numbers(scene, "a plot (--plot)")
    text = not args.latex and times is None
    summary = args.modes or (text and _is_large(scene) and not args.formula and chosen is None)
    if summary:
        _require_numbers(scene, "the modal summary (--modes)")
    lines = [scene.title] if scene.title else []
    if summary or (text and _is_large(scene)):  # from the modes: no solution needed
        lines += summary_lines(scene, pretty=args.pretty) if summary else \
            _large_formula_lines(scene, chosen, pretty=args.pretty)
        if args.plot:
            _save_plot(solve(scene), args.plot)
        print("\n".join(lines), file=out)
        return
    solution = solve(scene)
    if args.plot:
        _save_plot(solution, args.plot)
    if args.latex:
        _write_latex(solution, args, out)
        return
    if times is not None:
        values = solution.evaluate(times, dps=args.dps)
        lines += _table_lines(scene.names, times, values, args.dps or TABLE_DIGITS)
    else:
        try:
            x = list(solution.x)
        except (InversionError, SceneError) as exc:  # a forced scene without an exact form
            lines += _without_exact_form(scene, chosen, args.pretty, str(exc))
        else:
            inexact = getattr(solution, "inexact_reason", None)  # float64 terms in x
            lines += _without_exact_form(scene, chosen, args.pretty, inexact) if inexact else \
                formula_lines(scene, x, solution.conditions, pretty=args.pretty,
                              coordinates=chosen)
    lines += [unit_note_text(scene)] if scene.units is not None else []
    print("\n".join(lines), file=out)


def _forcing_argument(scene: Scene, items: Sequence[str]) -> list[sp.Expr | str]:
    """``--forcing`` values, one force per coordinate: all positional or all NAME=EXPR.

    Each expression is parsed here, so that an error names the coordinate or mass as the
    user wrote it.
    """
    named = ["=" in item for item in items]
    if any(named) and not all(named):
        raise UsageError("--forcing: give either one expression per coordinate or NAME=EXPR items, not both")
    parameters = {symbol.name: symbol for symbol in scene.parameters}
    forces: list[sp.Expr | str] = [sp.Integer(0)] * scene.n
    if not all(named):
        if len(items) != scene.n:
            given = "once" if len(items) == 1 else f"{len(items)} times"
            raise UsageError(f"--forcing was given {given}; the scene has {_count(scene.n, 'coordinate')} "
                             f"({', '.join(scene.names)}): give one expression per coordinate, "
                             f"or NAME=EXPR for some of them")
        for index, (name, text) in enumerate(zip(scene.names, items)):
            forces[index] = _force(scene, text, f"--forcing #{index + 1} ({name})", parameters)
        return forces
    seen: set[int] = set()
    for item in items:
        name, _, text = item.partition("=")
        index = _coordinate_index(scene, name.strip())
        if index in seen:
            raise UsageError(f"--forcing: coordinate {scene.names[index]} is given twice")
        seen.add(index)
        forces[index] = _force(scene, text, f"--forcing {name.strip()}", parameters)
    return forces


def _force(scene: Scene, text: str, entry: str, parameters: dict[str, sp.Symbol]) -> sp.Expr | str:
    """A ``--forcing`` expression parsed here, or for a scene with units kept as text
    (``10*cos(3*t) N``) for ``Scene.with_forcing`` to read with its unit."""
    return text.strip() if scene.units is not None else parse_forcing(text, entry, parameters)


def _count(number: int, noun: str) -> str:
    return f"{number} {noun}{'' if number == 1 else 's'}"


def _coordinate_index(scene: Scene, name: str) -> int:
    """The coordinate a ``--forcing NAME=`` refers to: a mass name, else a coordinate name
    (:func:`~laplace_springs.model.names.coordinate_index`, as everywhere)."""
    return coordinate_index(name, f"--forcing {name}", names=scene.names, mass_names=scene.mass_names)


def _add_response_command(commands) -> None:
    """``laplace-springs response``: modes and the frequency response of a scene."""
    response = commands.add_parser(
        "response", help="natural frequencies, damping ratios and the frequency response",
        description="Print the modes of a scene (natural and damped frequencies, damping "
                    "ratios, shapes) and, with --plot, draw |H(iω)| and its phase.")
    response.add_argument("scene", metavar="SCENE", help="a bundled scene name or a .toml path")
    response.add_argument("--plot", metavar="FILE", help="save the frequency-response plot to FILE")
    response.add_argument("--force", type=strict_int, default=1, metavar="J",
                          help="the coordinate (1-based) the unit harmonic force acts on (default 1)")
    response.add_argument("--at", metavar="W1,W2,...",
                          help="print the amplitude of each coordinate per unit force at these frequencies")
    _add_common_options(response)
    response.set_defaults(run=_run_response)


def _run_response(args: argparse.Namespace, out: TextIO) -> None:
    scene = _scene_of(args)
    if not 1 <= args.force <= scene.n:
        raise UsageError(f"--force must be between 1 and {scene.n}, got {args.force}")
    _require_numbers(scene, "the modes and the frequency response")
    lines = [scene.title] if scene.title else []
    lines.append(f"{'mode':>4}  {'omega_n':>12}  {'zeta':>10}  {'omega_d':>12}  shape")
    for k, mode in enumerate(modes(scene), start=1):
        zeta = "-" if mode.damping_ratio is None else f"{float(mode.damping_ratio):.6g}"
        shape = ", ".join(_format_complex(v) for v in mode.shape)
        hertz = f"  f_n = {float(mode.natural_frequency_hz):.6g} Hz" if scene.units is not None else ""
        lines.append(f"{k:>4}  {float(mode.natural_frequency):>12.6g}  {zeta:>10}  "
                     f"{float(mode.damped_frequency):>12.6g}  [{shape}]  ({mode.kind}){hertz}")
    if scene.units is not None:
        lines.append("omega in rad/s, f = omega/(2 pi) in Hz")
    if args.at is not None:
        omegas = parse_frequencies(args.at)
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
        raise UsageError(f"--plot needs matplotlib ({exc}); pip install 'laplace_springs[plots]'") from None
    _save_figure(plot_frequency_response(scene, force=force), path)


def _save_figure(figure, path: str) -> None:
    """``figure.savefig(path)``, with a one-line error for a bad path or format."""
    try:
        figure.savefig(path, dpi=100)
    except OSError as exc:
        raise OSError(f"--plot: cannot write {path!r}: {exc.strerror or exc}") from None
    except ValueError as exc:  # matplotlib: unknown file format
        raise UsageError(f"--plot: cannot write {path!r}: {exc}") from None


def _check_latex_options(args: argparse.Namespace) -> None:
    if (args.standalone or args.output) and not args.latex:
        raise UsageError("--standalone and -o/--output go with --latex")


def _write_latex(solution: Solution, args: argparse.Namespace, out: TextIO) -> None:
    """The LaTeX of ``solution`` on ``out`` or, with ``-o FILE``, into FILE."""
    text = solution.latex(standalone=args.standalone)
    if not args.output:
        print(text, file=out)
        return
    try:
        with open(args.output, "w", encoding="utf-8") as handle:
            handle.write(text if text.endswith("\n") else text + "\n")
    except OSError as exc:
        raise OSError(f"-o: cannot write {args.output!r}: {exc.strerror or exc}") from None
    print(f"wrote {args.output}", file=out)


def _save_plot(solution: Solution, path: str) -> None:
    """Write the diagram and motion plot (no display needed)."""
    try:
        figure = overview_figure(solution)
    except ImportError as exc:
        raise UsageError(f"--plot needs matplotlib ({exc}); pip install 'laplace_springs[plots]'") from None
    _save_figure(figure, path)


def _add_bench_command(commands) -> None:
    """``laplace-springs bench``: error against run time (see laplace_springs.bench.harness)."""
    bench = commands.add_parser(
        "bench", help="error against run time: our routes and the peers on the battery",
        description="Measure error (against a 60-digit reference) and run time of every "
                    "method on every battery scene; write report.md, results.csv and "
                    "plots/<scene>.png, and print both verdicts (on the Pareto front; fastest at this accuracy).")
    bench.add_argument("-o", "--out", default="bench-out", metavar="DIR",
                       help="output directory (default: bench-out)")
    bench.add_argument("--scenes", metavar="PATTERNS",
                       help="comma-separated glob patterns of battery scene names")
    bench.add_argument("--methods", metavar="PATTERNS",
                       help="comma-separated glob patterns of method names (e.g. 'ours*,ivp-*')")
    bench.add_argument("--quick", action="store_true",
                       help="a smaller method set (one tolerance per solver, no SymPy)")
    bench.add_argument("--large", action="store_true", help="include the battery's large scenes")
    bench.add_argument("--time-limit", type=strict_float, default=2.0, metavar="SECONDS",
                       help="per-run limit of a peer (default 2; raised where ours is slower)")
    bench.add_argument("--sympy-limit", type=strict_float, default=10.0, metavar="SECONDS",
                       help="limit of SymPy's inversion per scene (default 10)")
    bench.add_argument("--no-plots", action="store_true", help="skip the PNG plots")
    bench.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    bench.add_argument("--list", action="store_true", help="list scenes and methods, run nothing")
    bench.add_argument("--debug", action="store_true", default=argparse.SUPPRESS, help=argparse.SUPPRESS)

    def run(args: argparse.Namespace, out: TextIO) -> None:
        from .bench import harness as bm  # the battery and the peers: loaded for this command only

        if args.time_limit <= 0 or args.sympy_limit <= 0:
            raise UsageError("--time-limit and --sympy-limit must be positive")
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


def _report(message: str, *, kind: str = "error", status: int = _EXIT_ERROR) -> int:
    """Print one error line to stderr and return the exit status."""
    one_line = " ".join(str(message).split())
    print(f"{PROG}: {kind}: {one_line}", file=sys.stderr)
    return status


def _user_message(exc: BaseException) -> str:
    if isinstance(exc, OSError) and exc.strerror:
        where = f"{exc.filename!r}: " if exc.filename else ""
        return f"{where}{exc.strerror}"
    if isinstance(exc, RecursionError):
        return "the input is nested too deeply"
    return str(exc) or type(exc).__name__


def main(argv: list[str] | None = None) -> int:
    """Run the command line.

    Parameters
    ----------
    argv : list of str, optional
        The arguments after the program name; ``sys.argv[1:]`` when omitted.

    Returns
    -------
    int
        Exit status: 0 on success; 2 for a usage error or a bad scene, option value or
        file (one line ``laplace-springs: error: ...`` on stderr); 1 for an internal error
        (one line ``laplace-springs: internal error: ...``; ``--debug`` adds the traceback);
        130 when interrupted.
    """
    parser = _build_parser(publish=_needs_publish(sys.argv[1:] if argv is None else argv))
    try:
        args = parser.parse_args(argv)
        if getattr(args, "command", None) == "solve" and args.scene is None and not args.equations:
            parser.error("solve: give a SCENE (a bundled name or a .toml path) or --equations FILE")
    except SystemExit as exc:  # --help, --version, or an argparse usage error
        return exc.code if isinstance(exc.code, int) else _EXIT_ERROR
    debug = getattr(args, "debug", False)
    try:
        _check_arguments(args)  # every number and output path, before any work
        with warnings.catch_warnings():
            warnings.showwarning = _show_note
            args.run(args, sys.stdout)
        sys.stdout.flush()
    except BrokenPipeError:  # output piped into `head` and closed early: stop quietly
        _silence_stdout()
        return 1
    except KeyboardInterrupt:
        return _report("interrupted", kind="stopped", status=_EXIT_INTERRUPTED)
    except Exception as exc:
        if debug:
            traceback.print_exc()
        if _is_user_error(exc):
            return _report(_user_message(exc))
        hint = "" if debug else "; run with --debug for the traceback"
        return _report(f"{type(exc).__name__}: {_user_message(exc)}{hint}",
                       kind="internal error", status=_EXIT_INTERNAL)
    return 0


_PYTHON_SHOWWARNING = warnings.showwarning


def _show_note(message: Warning | str, category: type[Warning], filename: str, lineno: int,
               file: TextIO | None = None, line: str | None = None) -> None:
    """Initial data a scene's equations do not keep, as one line ``laplace-springs: note:``
    on stderr; other warnings as Python shows them."""
    if issubclass(category, InitialDataWarning):
        print(f"laplace-springs: note: {message}", file=sys.stderr)
    else:
        _PYTHON_SHOWWARNING(message, category, filename, lineno, file, line)


#: Output files the commands write, by (command, option): the suffixes allowed (None: any).
#: A figure's format follows its suffix (matplotlib), so a plot needs one it knows.
_OUTPUT_FILES: dict[tuple[str, str], tuple[str, ...] | None] = {
    ("solve", "plot"): (".png", ".pdf", ".svg", ".svgz", ".eps", ".ps", ".jpg", ".jpeg", ".tif", ".tiff"),
    ("response", "plot"): (".png", ".pdf", ".svg", ".svgz", ".eps", ".ps", ".jpg", ".jpeg", ".tif", ".tiff"),
    ("solve", "output"): None,
    ("animate", "output"): (".gif", ".mp4", ".html"),
    ("page", "output"): (".html", ".htm", ".tex"),
}
#: Output folders, by (command, option).
_OUTPUT_FOLDERS = {("bench", "out")}


def _flag(name: str) -> str:
    return {"out": "-o/--out", "output": "-o/--output"}.get(name, "--" + name.replace("_", "-"))


def _check_arguments(args: argparse.Namespace) -> None:
    """Refuse non-finite numbers in any option, and output paths that cannot be written
    (a directory, a device or FIFO, a missing folder, a missing or unknown suffix), so that
    a bad option is one line before any work is done, and no file appears elsewhere."""
    for name, value in vars(args).items():
        if isinstance(value, float) and not math.isfinite(value):
            raise UsageError(f"{_flag(name)}: {value!r} is not a finite number")
    command = getattr(args, "command", None)
    if getattr(args, "at", None) is not None:  # the --at table: times, or frequencies
        (parse_frequencies if command == "response" else parse_times)(args.at)
    for item in getattr(args, "param", None) or []:
        _check_param_value(item)
    for (owner, name), suffixes in _OUTPUT_FILES.items():
        value = getattr(args, name, None)
        if owner == command and value is not None:
            _check_output_file(value, _flag(name), suffixes)
    for owner, name in _OUTPUT_FOLDERS:
        value = getattr(args, name, None)
        if owner == command and value is not None:
            _check_output_folder(value, _flag(name))


#: Words that name no finite real number in a ``--param`` value (``i`` and ``j`` may be
#: parameters of a scene, so the parser judges those).
_NOT_FINITE_WORDS = NOT_FINITE_REAL - {"i", "j"}


def _check_param_value(item: str) -> None:
    """A ``--param NAME=VALUE`` whose value names nan or infinity is refused before the
    scene is read (the scene's own check would first ask whether NAME is a parameter)."""
    name, _, value = item.partition("=")
    word = next((word for word in re.findall(r"[A-Za-z][A-Za-z0-9_]*", value)
                 if word.lower() in _NOT_FINITE_WORDS), None)
    if word is not None:
        raise UsageError(f"--param {name.strip()}: {word!r} is not a finite real number "
                         f"(in the value {value.strip()!r})")


def _existing_kind(path: str) -> str | None:
    """What is at ``path`` when it is not a regular file ("a directory", "a FIFO", ...),
    "" for a regular file, None when nothing is there."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return None
    except (OSError, ValueError) as exc:
        raise UsageError(f"cannot use {path!r}: {getattr(exc, 'strerror', None) or exc}") from None
    kinds = ((stat.S_ISREG, ""), (stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO"),
             (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
             (stat.S_ISSOCK, "a socket"))
    return next((kind for test, kind in kinds if test(mode)), "not a regular file")


def _check_output_file(path: str, flag: str, suffixes: tuple[str, ...] | None) -> None:
    """A file to write: a regular file or nothing yet, in a writable folder, with a suffix
    from ``suffixes`` (when given)."""
    if not path or path.endswith(("/", os.sep)):
        raise UsageError(f"{flag}: {path!r} is not a file name")
    kind = _existing_kind(path)
    if kind:
        raise UsageError(f"{flag}: {path!r} is {kind}, not a file to write")
    suffix = os.path.splitext(path)[1].lower()
    if suffixes is not None and suffix not in suffixes:
        given = f"has the suffix {suffix!r}" if suffix else "has no suffix"
        raise UsageError(f"{flag}: {path!r} {given}; the file name must end in "
                         f"{', '.join(suffixes[:-1])} or {suffixes[-1]} (the suffix picks the format)")
    _check_writable_folder(os.path.dirname(path) or ".", flag, path)


def _check_output_folder(path: str, flag: str) -> None:
    """A folder to write into: an existing directory, or a new one in a writable folder."""
    kind = _existing_kind(path)
    if kind == "a directory":
        _check_writable_folder(path, flag, path)
        return
    if kind is not None:
        raise UsageError(f"{flag}: {path!r} is {'a file' if kind == '' else kind}, not a folder")
    _check_writable_folder(os.path.dirname(os.path.normpath(path)) or ".", flag, path)


def _check_writable_folder(folder: str, flag: str, path: str) -> None:
    if _existing_kind(folder) != "a directory":
        raise UsageError(f"{flag}: {path!r}: the folder {folder!r} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise UsageError(f"{flag}: {path!r}: the folder {folder!r} is not writable")


def _silence_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's final flush does not fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):  # stdout without a file descriptor
        pass
