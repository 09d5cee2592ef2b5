"""Physical units: entries such as ``"2.5 N/cm"``, converted exactly to SI as a scene is read.

Units are optional. A scene written with bare numbers works as it always has, in whatever
consistent units its author had in mind; a scene whose entries carry units (text such as
``"0.5 kg"``, ``"500 g"``, ``"250 N/m"``, ``"2.5 N/cm"``, ``"1.4 N*s/m"``, ``"5 cm"``,
``"2 m/s"``, ``"10*cos(3*t) N"``, or pint Quantities) is converted to exact SI rationals
as it is read, and keeps a record of the units its author wrote (:class:`SceneUnits`) for
the output: ``Solution.evaluate(times, units=True)``, axis labels, LaTeX, the command line.
Inside, every computation is unit-free: kilograms, metres, seconds and newtons.

The one registry is pint's application registry (``pint.get_application_registry()``,
an optional dependency: ``pip install 'laplace_springs[units]'``). Text is never
evaluated: :func:`~laplace_springs.model.numbers.split_unit` reads the number (or the
expression in ``t``) with the package's own parser and hands only the unit text to
pint's unit parser (``parse_units``).

Exact conversion. pint holds its conversion factors as floats; here each factor is
rebuilt exactly from pint's definitions, one definition at a time (``inch = yard / 36``,
``yard = 0.9144 * meter``, ``centi- = 1e-2``): a definition's float scale is read back as
the simplest rational that rounds to it, or as its shortest decimal when that is simpler
(:func:`exact_rational`), and the product is checked against pint's own float factor. So
``5 cm`` is exactly 1/20 m, ``500 g`` 1/2 kg, ``2.5 N/cm`` 250 N/m and ``1 lbf``
4.4482216152605 N. The tests check the factor of every unit named below against its SI
definition:

====================  =====================================================================
what                  units (any SI prefix works: mg, mm, kN, µm, ...)
====================  =====================================================================
mass                  kg, g, mg, t (tonne), lb
length                m, cm, mm, km, µm, in, ft
time                  s, ms, min, h
force                 N, kN, mN, dyn, lbf
stiffness             N/m, N/cm, N/mm, kN/m, lbf/in
damping               N*s/m (also N·s/m, N s/m), kg/s
velocity              m/s, cm/s, km/h
frequency             rad/s, 1/s, Hz (cycles per second: ω = 2π f), rpm
====================  =====================================================================

Dimension checks. Each entry has a dimension by what it is: masses and ``M`` a mass,
springs and ``K`` a stiffness (force per length), dashpots and ``C`` a damping (force per
velocity), ``x0`` a length, ``v0`` a velocity, ``forcing`` a force (a force per unit mass
for :meth:`Scene.from_normalized`, whose ``A`` is a stiffness per mass, 1/s², and ``B`` a
damping per mass, 1/s), support motions a length; ``t`` in a forcing is in seconds. An
entry of another dimension, and a bare nonzero number in a scene whose other entries carry
units, is a :class:`~laplace_springs.model.errors.SceneError` naming the entry, its
value, the dimension found and the one expected. Zero needs no unit; a parameter written
alone (``"k"``) is a quantity in SI and takes the dimension of its entry, and one written
with a unit (``"k N/m"``) is a number in that unit.
"""

from __future__ import annotations

import dataclasses
import decimal
import fractions
import math
import numbers
import re
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import mpmath
import numpy as np
import sympy

from ..kernels.precision import workprec
from .errors import InternalError, SceneError
from .numbers import ALLOWED_FUNCTIONS, shown, split_unit, to_exact
from .periodic import PERIODIC_FUNCTIONS
from .symbols import TIME

__all__ = [
    "Kind",
    "KINDS",
    "SceneUnits",
    "Unit",
    "attach_units",
    "axis_label",
    "damping_ratio",
    "exact_rational",
    "frequencies_to_rad_per_second",
    "in_length_unit",
    "natural_frequency",
    "parameter_value",
    "parse_unit",
    "read_scene_units",
    "registry",
    "spring_constant",
    "times_to_seconds",
    "unit_note_latex",
    "unit_note_text",
    "updated_entries",
    "value_latex",
]

Dimensions = tuple[tuple[str, int], ...]

#: Largest |exponent| of one unit in a unit text (``m**3`` is fine, ``cm**10000`` is not).
MAX_UNIT_EXPONENT = 12
#: Relative agreement required between an exact factor and pint's own float factor.
_FACTOR_TOLERANCE = 1e-12
#: Text that cannot hold a unit (digits, decimal points, exponents, operators).
_PLAIN_TEXT = re.compile(r"[\s0-9.eE+\-*/()^]*")
#: Types that never carry a unit.
_PLAIN_TYPES = frozenset({int, float, fractions.Fraction})
#: What a unit text may contain before pint sees it: letters (µ, Å, Ω too), digits, spaces,
#: ``* / ^ ( ) . - _ · ° %``; quotes, brackets, commas and colons never reach pint's parser.
_UNIT_TEXT = re.compile(r"[\w\s*/^().\-·⋅−°%]+")
_INSTALL = "pip install 'laplace_springs[units]'"


@dataclass(frozen=True)
class Kind:
    """What an entry is, physically: its name, dimensions and SI unit.

    Examples
    --------
    >>> KINDS["stiffness"].describe()
    'a stiffness, [mass] / [time] ** 2 (N/m)'
    """

    name: str
    dimensions: Dimensions
    si: str

    def describe(self) -> str:
        """The kind in words, with its dimensions and SI unit, for messages."""
        article = "an" if self.name[0] in "aeiou" else "a"
        unit = f" ({self.si})" if self.si else ""
        return f"{article} {self.name}, {dimension_text(self.dimensions)}{unit}"


def _dims(**powers: int) -> Dimensions:
    return tuple(sorted((f"[{name}]", power) for name, power in powers.items() if power))


#: The kinds of entries, by name.
KINDS: Mapping[str, Kind] = {kind.name: kind for kind in (
    Kind("mass", _dims(mass=1), "kg"),
    Kind("stiffness", _dims(mass=1, time=-2), "N/m"),
    Kind("damping", _dims(mass=1, time=-1), "N*s/m"),
    Kind("length", _dims(length=1), "m"),
    Kind("velocity", _dims(length=1, time=-1), "m/s"),
    Kind("acceleration", _dims(length=1, time=-2), "m/s**2"),
    Kind("force", _dims(mass=1, length=1, time=-2), "N"),
    Kind("time", _dims(time=1), "s"),
    Kind("stiffness per mass", _dims(time=-2), "1/s**2"),
    Kind("damping per mass", _dims(time=-1), "1/s"),
    Kind("frequency", _dims(time=-1), "rad/s"),
    Kind("energy", _dims(mass=1, length=2, time=-2), "J"),
    Kind("number", (), ""),
)}

#: The kind of each input of the three scene builders.
_FORM_KINDS: Mapping[str, Mapping[str, str]] = {
    "matrices": {"M": "mass", "C": "damping", "K": "stiffness", "x0": "length",
                 "v0": "velocity", "forcing": "force"},
    "normalized": {"A": "stiffness per mass", "B": "damping per mass", "x0": "length",
                   "v0": "velocity", "forcing": "acceleration"},
    "components": {"masses": "mass", "springs": "stiffness", "dashpots": "damping",
                   "x0": "length", "v0": "velocity", "forcing": "force", "support_motion": "length"},
}


def dimension_text(dimensions: Dimensions) -> str:
    """Dimensions as pint writes them: ``[mass] / [time] ** 2``; ``dimensionless``.

    Examples
    --------
    >>> dimension_text((("[length]", 1), ("[time]", -1)))
    '[length] / [time]'
    """
    if not dimensions:
        return "dimensionless"

    def power(name: str, exponent: int) -> str:
        return name if exponent == 1 else f"{name} ** {exponent}"

    upper = [power(name, p) for name, p in dimensions if p > 0]
    lower = [power(name, -p) for name, p in dimensions if p < 0]
    text = " * ".join(upper) or "1"
    return text + "".join(f" / {part}" for part in lower)


# ----------------------------------------------------------------------------
# The registry and exact factors
# ----------------------------------------------------------------------------


def registry() -> Any:
    """pint's application registry: the one registry of the package.

    Raises
    ------
    ImportError
        Without pint, saying how to install it.
    """
    try:
        import pint
    except ImportError as exc:
        raise ImportError(f"units need the optional package pint ({exc}): {_INSTALL}") from None
    return pint.get_application_registry()


def _simplest_between(low: fractions.Fraction, high: fractions.Fraction) -> fractions.Fraction:
    """The fraction of smallest denominator in [low, high] (0 < low <= high)."""
    whole = low.numerator // low.denominator
    if whole == low or whole + 1 <= high:
        return fractions.Fraction(whole if whole == low else whole + 1)
    return whole + 1 / _simplest_between(1 / (high - whole), 1 / (low - whole))


def exact_rational(scale: object) -> fractions.Fraction:
    """The exact rational a unit definition's scale stands for.

    A float scale is read back as the simplest rational that rounds to it or as its
    shortest decimal, whichever has the smaller denominator: ``1/36`` (``inch = yard /
    36``) and ``0.9144`` (``yard = 0.9144 * meter``) both come back exactly.

    Examples
    --------
    >>> exact_rational(1 / 36), exact_rational(0.9144), exact_rational(64.79891), exact_rational(1e-2)
    (Fraction(1, 36), Fraction(1143, 1250), Fraction(6479891, 100000), Fraction(1, 100))
    """
    if isinstance(scale, (int, fractions.Fraction)):
        return fractions.Fraction(scale)
    value = float(scale)  # type: ignore[arg-type]
    if not math.isfinite(value) or value <= 0:
        raise InternalError(f"a unit definition has the scale {scale!r}")
    decimal = fractions.Fraction(repr(value))
    low = (fractions.Fraction(value) + fractions.Fraction(math.nextafter(value, 0.0))) / 2
    high = (fractions.Fraction(value) + fractions.Fraction(math.nextafter(value, math.inf))) / 2
    simplest = _simplest_between(low, high)
    return min(decimal, simplest, key=lambda f: f.denominator)


class _UnitProblem(Exception):
    """Internal: why a unit text cannot be used; turned into a SceneError with its entry."""


def _root_factor(reg: Any, name: str, depth: int = 0) -> sympy.Expr:
    """The exact factor of unit ``name`` relative to pint's root units (gram, metre, second)."""
    if depth > 40:
        raise _UnitProblem(f"the definition of {name!r} is nested too deeply")
    candidates = reg.parse_unit_name(name)
    if not candidates:
        raise _UnitProblem(f"unknown unit {name!r}")
    prefix, unit, _ = candidates[0]
    value: sympy.Expr = sympy.Integer(1)
    if prefix:
        value *= sympy.Rational(exact_rational(reg._prefixes[prefix].converter.scale))
    if unit == "pi":
        return value * sympy.pi
    definition = reg._units[unit]
    if definition.is_base:
        return value
    converter = definition.converter
    if type(converter).__name__ != "ScaleConverter":
        raise _UnitProblem(f"{unit!r} is not a multiple of an SI unit (it has an offset or a "
                           f"logarithmic scale)")
    value *= sympy.Rational(exact_rational(converter.scale))
    for reference, exponent in definition.reference.items():
        value *= _root_factor(reg, reference, depth + 1) ** _integer_exponent(reference, exponent)
    return value


def _integer_exponent(name: str, exponent: object) -> int:
    if not float(exponent).is_integer() or abs(float(exponent)) > MAX_UNIT_EXPONENT:  # type: ignore[arg-type]
        raise _UnitProblem(f"{shown(name)} has the exponent {shown(exponent)}; exponents must be whole "
                           f"numbers up to {MAX_UNIT_EXPONENT}")
    return int(float(exponent))  # type: ignore[arg-type]


@dataclass(frozen=True)
class Unit:
    """A unit text resolved by pint, with its exact factor to SI.

    Attributes
    ----------
    text : str
        As written, e.g. ``"N/cm"``.
    name : str
        pint's name, e.g. ``"newton / centimeter"``.
    factor : sympy.Expr
        Exact: one of this unit is ``factor`` SI units (``N/cm``: 100).
    dimensions : tuple of (str, int)
        E.g. ``(("[mass]", 1), ("[time]", -2))``.
    cycles : int
        The power of ``Hz`` in it (a hertz is a cycle per second: 2π rad/s).
    """

    text: str
    name: str
    factor: sympy.Expr
    dimensions: Dimensions
    cycles: int = 0


_UNITS: dict[tuple[int, str], Unit] = {}


def parse_unit(text: str) -> Unit:
    """Resolve a unit text with pint's unit parser and rebuild its factor to SI exactly.

    Raises
    ------
    SceneError
        For text pint does not know, an offset or logarithmic unit (°C, dB), or a
        non-integer or large exponent.
    ImportError
        Without pint.

    Examples
    --------
    >>> unit = parse_unit("N/cm")
    >>> unit.factor, unit.dimensions
    (100, (('[mass]', 1), ('[time]', -2)))
    >>> parse_unit("lbf").factor
    8896443230521/2000000000000
    """
    reg = registry()
    key = (id(reg.get()), text)
    if key not in _UNITS:
        try:
            _UNITS[key] = _resolve(reg, text)
        except _UnitProblem as exc:
            raise SceneError(f"unit {shown(text)}: {exc}") from None
    return _UNITS[key]


def _resolve(reg: Any, text: str) -> Unit:
    import pint

    if not _UNIT_TEXT.fullmatch(text):
        raise _UnitProblem("a unit is letters, digits, spaces and * / ^ ( ) . - only")
    normalised = text.replace("·", "*").replace("⋅", "*").replace("−", "-")
    try:
        units = reg.parse_units(normalised)
        root_float, _ = reg.get_root_units(units)
    except (pint.PintError, ValueError, TypeError, SyntaxError, AttributeError, KeyError,
            AssertionError, ArithmeticError, RecursionError) as exc:
        # pint's expression builder asserts on some malformed text; its float factors
        # overflow (kg^10000, kg^(10**400)) or divide by zero (kg/0)
        raise _UnitProblem(f"not a unit pint knows ({exc})" if str(exc) else "not a unit pint knows") from None
    except Exception as exc:  # the tokenizer's TokenError for unbalanced brackets
        if type(exc).__name__ != "TokenError":
            raise
        raise _UnitProblem("unbalanced brackets") from None
    dimensions = tuple(sorted((str(name), _integer_exponent(str(name), power))
                              for name, power in units.dimensionality.items()))
    factor = sympy.Integer(1)
    cycles = 0
    for name, exponent in units._units.items():
        power = _integer_exponent(name, exponent)
        factor *= _root_factor(reg, name) ** power
        if reg.parse_unit_name(name)[0][1] == "hertz":
            cycles += power
    if abs(float(factor) - float(root_float)) > _FACTOR_TOLERANCE * abs(float(root_float)):
        raise InternalError(f"unit {text!r}: the exact factor {factor} disagrees with pint's "
                            f"{root_float}")
    mass_power = dict(dimensions).get("[mass]", 0)  # pint's root of mass is the gram
    return Unit(text, str(units), factor / sympy.Integer(1000) ** mass_power, dimensions, cycles)


def _is_quantity(value: object) -> bool:
    """Whether ``value`` is a pint Quantity (checked without importing pint)."""
    module = getattr(type(value), "__module__", None) or ""  # None for SymPy's f(t) of Function("f")
    return (module == "pint" or module.startswith("pint.")) and hasattr(value, "magnitude") \
        and hasattr(value, "units")


def _quantity_unit(value: Any) -> Unit:
    return parse_unit(str(value.units))


def _checked_unit(text: str, entry: str, value: object, kind: Kind) -> Unit:
    """``text`` resolved, and of ``kind``'s dimensions, or a SceneError naming ``entry``."""
    try:
        unit = parse_unit(text)
    except SceneError as exc:
        raise SceneError(f"{entry}: {shown(value)}: {exc}; expected {kind.describe()}") from None
    if unit.dimensions != kind.dimensions:
        raise SceneError(f"{entry}: {shown(value)} has dimension {dimension_text(unit.dimensions)} "
                         f"({unit.name}), expected {kind.describe()}")
    return unit


# ----------------------------------------------------------------------------
# Reading the entries of a scene
# ----------------------------------------------------------------------------


@dataclass(frozen=True)
class SceneUnits:
    """The units a scene was written in: the record kept for its output.

    Attributes
    ----------
    written : tuple of (str, str)
        Each entry given with a unit, and that unit as written: ``("x0[0]", "cm")``.
    length : str
        The unit of the scene's coordinates x (``"m"``: the entries are held in SI; see
        :func:`in_length_unit`). Times are in seconds.
    forcing : str
        The kind of the forcing entries: ``"force"``, or ``"acceleration"`` for a scene
        built from the normalised form.
    parameters : tuple of (str, tuple)
        The dimensions of each parameter whose dimensions the entries tell (a parameter
        written alone is a quantity in SI; one written with a unit is a number).
    declared : str
        ``"SI"`` when bare numbers were declared to be SI (``units="SI"``), else ``""``.

    Examples
    --------
    >>> import laplace_springs as ls
    >>> scene = ls.Scene.from_components(masses={"m": "500 g"}, springs={"k": ("wall", "m", "2.5 N/cm")},
    ...                                  x0=["5 cm"], v0=[0])
    >>> scene.M, scene.K, scene.x0
    (Matrix([[1/2]]), Matrix([[250]]), Matrix([[1/20]]))
    >>> scene.units.written
    (("mass 'm'", 'g'), ("spring 'k'", 'N/cm'), ('x0[0]', 'cm'))
    """

    written: tuple[tuple[str, str], ...] = ()
    length: str = "m"
    forcing: str = "force"
    parameters: tuple[tuple[str, Dimensions], ...] = ()
    declared: str = ""

    def parameter_dimensions(self, name: str) -> Dimensions | None:
        """The dimensions of parameter ``name``, or None when unknown."""
        return dict(self.parameters).get(name)


#: The functions a forcing text may call (as :func:`~.forcing.parse_forcing` allows).
_FORCING_FUNCTIONS: Mapping[str, Any] = {**ALLOWED_FUNCTIONS, **PERIODIC_FUNCTIONS}


class _Reader:
    """Walks a builder's inputs, converting the entries that carry units (one pass) and
    collecting the bare ones, which are checked only when some entry had a unit."""

    def __init__(self, parameters: Mapping[str, sympy.Symbol], declared: str = "",
                 context: str = "") -> None:
        self.parameters = parameters
        self.declared = declared
        self.context = context  # why bare numbers need units, when not from the entries
        self.sympy_is_si = False  # SymPy values are the scene's own numbers (updates)
        self.written: list[tuple[str, str]] = []
        self.bare: list[tuple[str, Any, Kind, bool]] = []
        self.dimensions: dict[str, Dimensions | None] = {}
        self.split_cache: dict[tuple[str, bool], tuple[sympy.Expr, str]] = {}

    # -- one entry -------------------------------------------------------------------
    def leaf(self, value: Any, entry: str, kind: Kind, expression: bool = False) -> Any:
        """The exact SI value of an entry with a unit; a bare entry unchanged (noted)."""
        if type(value) in _PLAIN_TYPES or type(value) is str and _PLAIN_TEXT.fullmatch(value):
            self.bare.append((entry, value, kind, expression))  # the common case, first
            return value
        if _is_quantity(value):
            unit = _checked_unit(str(value.units), entry, value, kind)
            magnitude = value.magnitude
            exact = to_exact(magnitude, entry, parameters=self.parameters)
            return self._converted(exact * unit.factor, entry, unit, str(value.units), exact)
        if isinstance(value, str):  # with a letter: perhaps a unit
            try:
                number, unit_text = self._split(value, entry, expression)
            except SceneError:  # not even a number: the builder reports it, as without units
                number, unit_text = sympy.S.Zero, ""
            if unit_text:
                unit = _checked_unit(unit_text, entry, value, kind)
                return self._converted(number * unit.factor, entry, unit, unit_text, number)
        self.bare.append((entry, value, kind, expression))
        return value

    def _split(self, text: str, entry: str, expression: bool) -> tuple[sympy.Expr, str]:
        key = (text, expression)
        if key not in self.split_cache:
            functions = _FORCING_FUNCTIONS if expression else ALLOWED_FUNCTIONS
            expected = "an expression in t" if expression else "a number"
            self.split_cache[key] = split_unit(text.strip(), entry, allowed_functions=functions,
                                               variables=self.parameters, expected=expected)
        return self.split_cache[key]

    def _converted(self, value: sympy.Expr, entry: str, unit: Unit, text: str,
                   number: sympy.Expr) -> sympy.Expr:
        if unit.cycles:
            raise SceneError(f"{entry}: write frequencies in a scene in rad/s, not {text}")
        self.written.append((entry, text))
        self._note_parameters(number, ())  # "k N/m": k is a number (of N/m)
        return value

    # -- parameters ------------------------------------------------------------------
    def _note_parameters(self, value: sympy.Expr, dimensions: Dimensions) -> None:
        """The dimensions of the parameters written alone in a term of ``value``: the
        entry's for a bare entry (``"k"``: a stiffness), none with a unit (``"k N/m"``).
        A parameter found with two different dimensions, or only inside other
        expressions, has unknown dimensions."""
        if not isinstance(value, sympy.Basic):
            return
        symbols = [s for s in value.free_symbols if s != TIME and isinstance(s, sympy.Symbol)]
        if not symbols:
            return
        alone = {s for term in sympy.Add.make_args(sympy.expand(value)) for s in term.free_symbols
                 if s in symbols and (term / s).is_number}
        for symbol in symbols:
            known = self.dimensions.get(symbol.name, dimensions) if symbol in alone else None
            self.dimensions[symbol.name] = known if known == dimensions else None

    # -- the end -----------------------------------------------------------------------
    def record(self, form: str) -> SceneUnits | None:
        """The record, after checking the bare entries; None when no entry had a unit."""
        if not self.written and not self.declared and not self.context:
            return None
        for entry, value, kind, expression in self.bare:
            self._check_bare(entry, value, kind, expression)
        parameters = tuple(sorted((name, dims) for name, dims in self.dimensions.items() if dims is not None))
        return SceneUnits(tuple(self.written), forcing=_FORM_KINDS[form]["forcing"],
                          parameters=parameters, declared=self.declared)

    def _check_bare(self, entry: str, value: Any, kind: Kind, expression: bool) -> None:
        if self.sympy_is_si and isinstance(value, sympy.Basic):
            return
        if isinstance(value, sympy.MatrixBase):
            for (i, j), item in sorted(value.todok().items()):
                self._check_bare(f"{entry}[{i},{j}]", item, kind, expression)
            return
        exact = self._bare_value(value, entry, expression)
        if exact is None:
            raise SceneError(f"{entry}: {shown(value)} carries no unit, but other entries of this scene "
                             f"do; a scene with units takes {kind.describe()} here as text with its "
                             f"unit, or a pint Quantity")
        if exact == 0:
            return
        if exact.free_symbols - {TIME}:
            self._note_parameters(exact, kind.dimensions)
            return
        if self.declared:
            return
        why = self.context or "the scene's other entries carry units ({}: {})".format(*self.written[0])
        raise SceneError(f"{entry}: {shown(value)} has no unit (dimension found: none), expected "
                         f"{kind.describe()}: {why}; give this one its unit too (only 0 may stand "
                         f"without one)")

    def _bare_value(self, value: Any, entry: str, expression: bool) -> sympy.Expr | None:
        """The exact value of a bare entry, or None for an object that is no number."""
        if value is None:
            return sympy.S.Zero
        if isinstance(value, str):
            return self._split(value, entry, expression)[0]
        if isinstance(value, sympy.Basic):
            return value if isinstance(value, sympy.Expr) else None
        if not isinstance(value, (numbers.Real, decimal.Decimal)):
            return None
        return to_exact(value, entry, parameters=self.parameters)

    # -- containers --------------------------------------------------------------------
    def matrix(self, value: Any, name: str, kind: Kind) -> Any:
        """A matrix input with its unit entries converted (the same object if none)."""
        if value is None:
            return None
        if isinstance(value, sympy.MatrixBase):
            self.bare.append((name, value, kind, False))
            return value
        if _is_quantity(value):
            unit = _checked_unit(str(value.units), name, value, kind)
            rows = np.asarray(value.magnitude, dtype=object).tolist()
            if not isinstance(rows, list) or not all(isinstance(row, list) for row in rows):
                return value
            self.written.append((name, str(value.units)))
            return [[to_exact(item, f"{name}[{i},{j}]", parameters=self.parameters) * unit.factor
                     for j, item in enumerate(row)] for i, row in enumerate(rows)]
        rows = value.tolist() if hasattr(value, "tolist") else value
        if isinstance(rows, (str, bytes)) or not isinstance(rows, Sequence) or not all(
                isinstance(row, Sequence) and not isinstance(row, str) for row in rows):
            return value
        converted = [[self.leaf(item, f"{name}[{i},{j}]", kind) for j, item in enumerate(row)]
                     for i, row in enumerate(rows)]
        same = all(a is b for new, old in zip(converted, rows) for a, b in zip(new, old))
        return value if same else converted

    def vector(self, value: Any, name: str, kind: Kind, expression: bool = False) -> Any:
        """A vector input (flat, a column, a row, or a mapping by name) with its unit entries
        converted (the same object if none)."""
        if value is None or isinstance(value, (str, bytes)):
            return value
        if _is_quantity(value):
            items = np.asarray(value.magnitude, dtype=object).ravel().tolist()
            unit = _checked_unit(str(value.units), name, value, kind)
            self.written.append((name, str(value.units)))
            return [to_exact(item, f"{name}[{i}]", parameters=self.parameters) * unit.factor
                    for i, item in enumerate(items)]
        if isinstance(value, Mapping):
            converted = {key: self.leaf(item, f"{name}[{key!r}]", kind, expression)
                         for key, item in value.items()}
            return value if all(converted[k] is value[k] for k in value) else converted
        items = value.tolist() if hasattr(value, "tolist") else value
        if not isinstance(items, Sequence):
            return value
        nested = [isinstance(item, Sequence) and not isinstance(item, str) for item in items]
        if all(nested) and all(len(item) == 1 for item in items) and items:
            items = [item[0] for item in items]
        elif len(items) == 1 and nested[0]:
            items = list(items[0])
        elif any(nested):
            return value
        entries = [self.leaf(item, f"{name}[{i}]", kind, expression) for i, item in enumerate(items)]
        return value if all(a is b for a, b in zip(entries, items)) else entries

    def masses(self, value: Any, kind: Kind) -> Any:
        if isinstance(value, Mapping):
            converted = {name: self.leaf(item, f"mass {name!r}", kind) for name, item in value.items()}
            return value if all(converted[k] is value[k] for k in value) else converted
        if isinstance(value, (str, bytes)) or not isinstance(value, Iterable):
            return value
        rows = list(value)
        if not all(isinstance(row, Sequence) and not isinstance(row, str) and len(row) == 2 for row in rows):
            return rows
        return [(row[0], self.leaf(row[1], f"mass {row[0]!r}", kind)) for row in rows]

    def components(self, value: Any, what: str, kind: Kind) -> Any:
        def spec(label: Any, item: Any) -> Any:
            if isinstance(item, str) or not isinstance(item, Sequence) or len(item) != 3:
                return item
            converted = self.leaf(item[2], f"{what} {label!r}", kind)
            return item if converted is item[2] else (item[0], item[1], converted)

        if isinstance(value, Mapping):
            converted = {label: spec(label, item) for label, item in value.items()}
            return value if all(converted[k] is value[k] for k in value) else converted
        if isinstance(value, (str, bytes)) or not isinstance(value, Iterable):
            return value
        rows = list(value)
        if not all(isinstance(row, Sequence) and not isinstance(row, str) and len(row) == 4 for row in rows):
            return rows
        return [(row[0], *spec(row[0], tuple(row[1:]))) for row in rows]


def read_scene_units(form: str, inputs: Mapping[str, Any], parameters: Mapping[str, sympy.Symbol],
                     units: object = None) -> tuple[dict[str, Any], SceneUnits | None]:
    """A builder's inputs with every entry that carries a unit converted to exact SI.

    Parameters
    ----------
    form : {"matrices", "normalized", "components"}
        Which builder: it decides each input's kind (see the module notes).
    inputs : mapping
        The builder's inputs by name (``M``, ``x0``, ``masses``, ``springs`` ...).
    parameters : mapping of str to sympy.Symbol
        The declared parameters.
    units : None, "SI" or SceneUnits
        None: read units from the entries. ``"SI"``: bare numbers are in SI (units are
        declared, not guessed). A :class:`SceneUnits`: the inputs are already in SI.

    Returns
    -------
    (dict, SceneUnits or None)
        The inputs (the very objects given when no entry has a unit) and the record
        (None for a scene without units).

    Raises
    ------
    SceneError
        For an entry of the wrong dimension, an unknown unit, or a bare nonzero number
        among entries with units; the message names the entry, its value, the dimension
        found and the one expected.

    Examples
    --------
    >>> inputs, record = read_scene_units("matrices", {"M": [["2 kg"]], "x0": ["5 cm"]}, {})
    >>> inputs["M"], inputs["x0"]
    ([[2]], [1/20])
    >>> read_scene_units("matrices", {"M": [["2 kg"]], "x0": ["5 s"]}, {})
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: x0[0]: '5 s' has dimension [time] (second), expected a length, [length] (m)
    """
    if isinstance(units, SceneUnits):
        return dict(inputs), units
    if units is not None and units != "SI":
        raise SceneError(f"units must be None (read them from the entries) or 'SI' (bare numbers "
                         f"are SI), got {shown(units)}")
    reader = _Reader(parameters, "SI" if units == "SI" else "")
    kinds = _FORM_KINDS[form]
    inputs = {name: list(value) if isinstance(value, Iterator) else value for name, value in inputs.items()}
    converted: dict[str, Any] = {}
    for name, value in inputs.items():
        kind = KINDS[kinds[name]]
        if name == "masses":
            converted[name] = reader.masses(value, kind)
        elif name in ("springs", "dashpots"):
            converted[name] = reader.components(value, name[:-1], kind)
        elif name in ("x0", "v0", "forcing") or name == "support_motion" and isinstance(value, Mapping):
            converted[name] = reader.vector(value, name, kind, name in ("forcing", "support_motion"))
        elif name == "support_motion":
            converted[name] = value
        else:
            converted[name] = reader.matrix(value, name, kind)
    record = reader.record(form)
    return (converted, record) if record is not None else (dict(inputs), None)


def updated_entries(record: SceneUnits | None, inputs: Mapping[str, Any],
                    parameters: Mapping[str, sympy.Symbol]) -> dict[str, Any]:
    """New ``x0``, ``v0`` or ``forcing`` of an existing scene, read in its units.

    In a scene with units they need units (0 aside), except SymPy values, which are the
    scene's own numbers (``scene.with_initial(x0=other.v0)``); in a scene without units
    they must not have any.

    Examples
    --------
    >>> updated_entries(SceneUnits((("x0[0]", "cm"),)), {"x0": ["3 mm"]}, {})
    {'x0': [3/1000]}
    """
    if record is None:
        reader = _Reader(parameters)
        for name, value in inputs.items():
            reader.vector(value, name, KINDS[_FORM_KINDS["matrices"][name]], name == "forcing")
        if reader.written:
            entry, unit = reader.written[0]
            raise SceneError(f"{entry}: has the unit {unit!r}, but the scene was written without units "
                             f"(give bare numbers, or build the scene with units)")
        return dict(inputs)
    reader = _Reader(parameters, record.declared, context="the scene was written with units")
    reader.sympy_is_si = True
    kinds = {"x0": "length", "v0": "velocity", "forcing": record.forcing}
    converted = {name: reader.vector(value, name, KINDS[kinds[name]], name == "forcing")
                 for name, value in inputs.items()}
    reader.record("matrices")
    scale = _length_factor(record)  # the scene's numbers are in its length unit
    return {name: value if scale == 1 or value is inputs[name] else _divided(value, scale)
            for name, value in converted.items()}


def _divided(value: Any, scale: sympy.Expr) -> Any:
    """Converted entries (SI values; bare ones are 0 or symbolic) over ``scale``."""
    if isinstance(value, Mapping):
        return {key: _divided(item, scale) for key, item in value.items()}
    if isinstance(value, list):
        return [_divided(item, scale) for item in value]
    return value / scale if isinstance(value, sympy.Basic) else value


def parameter_value(value: Any, name: str, record: SceneUnits | None,
                    parameters: Mapping[str, sympy.Symbol]) -> Any:
    """A value for parameter ``name`` (``Scene.subs``), converted to SI if it has a unit.

    In a scene with units, a parameter written alone in an entry has that entry's
    dimensions and its value needs a unit; one written with a unit (``"k N/m"``) is a
    plain number. In a scene without units, values have none.

    Examples
    --------
    >>> record = SceneUnits(parameters=(("k", (("[mass]", 1), ("[time]", -2))),))
    >>> parameter_value("2.5 N/cm", "k", record, {})
    250
    >>> parameter_value("2.5", "k", record, {})
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: parameter 'k': '2.5' has no unit (dimension found: none), expected a stiffness, [mass] / [time] ** 2 (N/m): the scene has units; write the value with its unit
    """
    entry = f"parameter {name!r}"
    reader = _Reader(parameters)
    dimensions = None if record is None else record.parameter_dimensions(name)
    if not _has_unit(reader, value, entry):
        exact = reader._bare_value(value, entry, False)
        if record is not None and not record.declared and dimensions and exact is not None \
                and exact != 0 and not exact.free_symbols - {TIME}:
            raise SceneError(f"{entry}: {shown(value)} has no unit (dimension found: none), expected "
                             f"{_kind_of(dimensions).describe()}: the scene has units; write the "
                             f"value with its unit")
        return value
    if dimensions is None:
        why = "the scene was written without units" if record is None else \
            "its dimension is unknown (it is written alone in no entry)"
        raise SceneError(f"{entry}: {shown(value)} has a unit, but {why}; give a bare number (in SI)")
    return reader.leaf(value, entry, _kind_of(dimensions))


def _has_unit(reader: _Reader, value: Any, entry: str) -> bool:
    if _is_quantity(value):
        return True
    return isinstance(value, str) and not _PLAIN_TEXT.fullmatch(value) and \
        bool(reader._split(value, entry, False)[1])


def _kind_of(dimensions: Dimensions) -> Kind:
    """The first kind of these dimensions (``stiffness`` for [mass]/[time]²), or a new one."""
    return next((kind for kind in KINDS.values() if kind.dimensions == dimensions),
                Kind("quantity", dimensions, ""))


# ----------------------------------------------------------------------------
# Times, frequencies and answers in units
# ----------------------------------------------------------------------------


def _time_item(value: Any, entry: str) -> Any:
    if _is_quantity(value):
        unit = _checked_unit(str(value.units), entry, value, KINDS["time"])
        return to_exact(value.magnitude, entry) * unit.factor
    if isinstance(value, str) and not _PLAIN_TEXT.fullmatch(value):
        number, text = split_unit(value.strip(), entry)
        if text:
            return number * _checked_unit(text, entry, value, KINDS["time"]).factor
    return value


def times_to_seconds(times: Any) -> Any:
    """Times with units (``"0.5 s"``, ``"250 ms"``, pint Quantities) as exact seconds.

    Times without units are returned as they are (the same object).

    Examples
    --------
    >>> times_to_seconds(["0.5 s", "250 ms", 1, "0.1"])
    [1/2, 1/4, 1, '0.1']
    >>> times_to_seconds("2 min")
    120
    """
    if isinstance(times, np.ndarray) and times.dtype.kind in "fiu":
        return times
    if _is_quantity(times):
        unit = _checked_unit(str(times.units), "times", times, KINDS["time"])
        magnitude = times.magnitude
        if unit.factor == 1:
            return magnitude
        factor = fractions.Fraction(int(unit.factor.p), int(unit.factor.q))
        exact = [_fraction(v) * factor for v in np.asarray(magnitude, dtype=object).ravel().tolist()]
        return exact if np.ndim(magnitude) else exact[0]
    if isinstance(times, str):
        return _time_item(times, "times[0]")
    if isinstance(times, (list, tuple)) and any(isinstance(v, str) or _is_quantity(v) for v in times):
        return [_time_item(v, f"times[{i}]") for i, v in enumerate(times)]
    return times


def _fraction(value: object) -> fractions.Fraction:
    exact = to_exact(value, "times")
    return fractions.Fraction(int(exact.p), int(exact.q))


def _omega_item(value: Any, entry: str) -> Any:
    if _is_quantity(value):
        unit = _checked_unit(str(value.units), entry, value, KINDS["frequency"])
        magnitude = value.magnitude
    elif isinstance(value, str) and not _PLAIN_TEXT.fullmatch(value):
        magnitude, text = split_unit(value.strip(), entry)
        if not text:
            return value
        unit = _checked_unit(text, entry, value, KINDS["frequency"])
    else:
        return value
    factor = unit.factor * (2 * sympy.pi) ** unit.cycles
    return float(to_exact(magnitude, entry) * factor) if np.ndim(magnitude) == 0 else \
        np.asarray(magnitude, dtype=float) * float(factor)


def frequencies_to_rad_per_second(omegas: Any) -> Any:
    """Driving frequencies with units as rad/s (``"3 Hz"`` is 6π rad/s); others unchanged.

    Examples
    --------
    >>> frequencies_to_rad_per_second(["1 Hz", "2 rad/s", 3.0])
    [6.283185307179586, 2.0, 3.0]
    """
    if omegas is None or isinstance(omegas, np.ndarray) and omegas.dtype.kind in "fiu":
        return omegas
    if _is_quantity(omegas) or isinstance(omegas, str):
        return _omega_item(omegas, "omegas")
    if isinstance(omegas, (list, tuple)) and any(isinstance(v, str) or _is_quantity(v) for v in omegas):
        return [_omega_item(v, f"omegas[{i}]") for i, v in enumerate(omegas)]
    return omegas


def _record_of(scene: Any, what: str) -> SceneUnits:
    record = getattr(scene, "units", None)
    if record is None:
        raise SceneError(f"{what}: this scene was written without units, so its numbers have none "
                         f"(units are never guessed); write its entries with units, e.g. '5 cm', "
                         f"or declare them with units='SI'")
    return record


def _length_factor(record: SceneUnits) -> sympy.Expr:
    return parse_unit(record.length).factor


def attach_units(values: Any, scene: Any, order: int = 0, unit: str | bool = True) -> Any:
    """Values of x (``order`` 0), x' (1) or x'' (2) of a scene with units as a pint Quantity.

    Parameters
    ----------
    values : numpy.ndarray
        In the scene's units (metres, or its ``units.length``; per second for x').
    scene : Scene
        A scene written with units.
    order : {0, 1, 2}
    unit : True or str
        True: the scene's length unit (and /s, /s**2); or a unit to convert to (``"cm"``).

    Returns
    -------
    pint.Quantity

    Examples
    --------
    >>> import laplace_springs as ls
    >>> scene = ls.Scene.from_matrices(M=[["1 kg"]], K=[["4 N/m"]], x0=["5 cm"], v0=[0])
    >>> attach_units(np.array([[0.05]]), scene, 0, "cm")
    <Quantity([[5.]], 'centimeter')>
    """
    record = _record_of(scene, "units")
    kind = KINDS[("length", "velocity", "acceleration")[order]]
    base = record.length + ("", "/s", "/s**2")[order]
    target = _checked_unit(base if unit is True else str(unit), "units", unit, kind)
    ratio = parse_unit(base).factor / target.factor
    magnitude = _scaled(values, ratio)
    return registry().Quantity(magnitude, target.name)


def _scaled(values: Any, ratio: sympy.Expr) -> Any:
    if ratio == 1:
        return values
    array = np.asarray(values)
    if array.dtype != object:
        return array * float(ratio)
    bits = max((v._mpf_[1].bit_length() for v in array.ravel() if isinstance(v, mpmath.mpf)), default=53)
    with workprec(bits + 20):
        factor = mpmath.mpf(int(ratio.p)) / int(ratio.q)
        return np.array([v * factor for v in array.ravel()], dtype=object).reshape(array.shape)


def in_length_unit(scene: Any, unit: str) -> Any:
    """The same scene with its coordinates x measured in ``unit`` (``"cm"``, ``"mm"``...).

    The motion is linear in x0, v0 and the forces, so scaling them by the ratio of the units
    gives x in the new unit exactly; masses, stiffnesses and dampings stay SI.

    Examples
    --------
    >>> import laplace_springs as ls
    >>> scene = ls.Scene.from_matrices(M=[["1 kg"]], K=[["4 N/m"]], x0=["5 cm"], v0=[0])
    >>> in_cm = in_length_unit(scene, "cm")
    >>> in_cm.x0, in_cm.units.length
    (Matrix([[5]]), 'cm')
    """
    record = _record_of(scene, "--unit")
    target = _checked_unit(unit, "--unit", unit, KINDS["length"])
    ratio = _length_factor(record) / target.factor
    if scene.sampled is not None and ratio != 1:
        raise SceneError("--unit: a scene with a sampled force history keeps its coordinates in metres")
    forcing = None if scene.forcing is None else sympy.ImmutableMatrix(scene.forcing * ratio)
    return dataclasses.replace(
        scene, x0=sympy.ImmutableMatrix(scene.x0 * ratio), v0=sympy.ImmutableMatrix(scene.v0 * ratio),
        forcing=forcing, support_motion=tuple((name, u * ratio) for name, u in scene.support_motion),
        units=dataclasses.replace(record, length=unit))


#: Axis titles of the quantities plots show: (title, unit in a scene with units, unit
#: without). ``{L}`` is the scene's length unit.
_AXES = {"time": ("Time", "s", ""), "position": ("Position", "{L}", ""),
         "velocity": ("Velocity", "{L}/s", ""), "energy": ("Energy", "J", ""),
         "frequency": ("Frequency", "rad/s", ""),
         "receptance": ("Amplitude per unit force", "{L}/N", ""),
         "receptance_db": ("Magnitude", "dB re 1 {L}/N", "dB"),
         "rate": ("Re s", "1/s", ""), "angular_rate": ("Im s", "rad/s", "")}


def axis_label(quantity: str, scene: Any = None, unit: str | None = None, *,
               title: str | None = None) -> str:
    """The axis label of a quantity: ``"Time (s)"``, ``"Position (cm)"``, or ``"Time"``.

    Parameters
    ----------
    quantity : str
        One of ``"time"``, ``"position"``, ``"velocity"``, ``"energy"``, ``"frequency"``,
        ``"receptance"``, ``"receptance_db"``, ``"rate"``, ``"angular_rate"``.
    scene : Scene, optional
        A scene with units gives the unit (its length unit for positions); a scene
        without units gives none: its numbers are in whatever units its author used.
    unit : str, optional
        The unit to write, whatever the scene.
    title : str, optional
        The words before the unit (default: the quantity's, e.g. ``"Time"``).

    Examples
    --------
    >>> import laplace_springs as ls
    >>> scene = ls.Scene.from_matrices(M=[["1 kg"]], K=[["4 N/m"]], x0=["5 cm"], v0=[0])
    >>> axis_label("time", scene), axis_label("position", scene), axis_label("velocity", scene)
    ('Time (s)', 'Position (m)', 'Velocity (m/s)')
    >>> axis_label("position", ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0]))
    'Position'
    >>> axis_label("position", unit="cm"), axis_label("frequency", scene, title="driving frequency ω")
    ('Position (cm)', 'driving frequency ω (rad/s)')
    """
    default_title, template, without = _AXES[quantity]
    record = getattr(scene, "units", None)
    if unit is None:
        unit = without if record is None else template.replace("{L}", record.length)
        if record is not None and quantity == "energy" and record.length != "m":
            unit = f"kg·{record.length}²/s²"
    words = default_title if title is None else title
    return f"{words} ({unit})" if unit else words


def unit_note_latex(scene: Any) -> list[str]:
    """The row saying the units of x and t, for LaTeX answers of a scene with units.

    Examples
    --------
    >>> import laplace_springs as ls
    >>> unit_note_latex(ls.Scene.from_matrices(M=[["1 kg"]], K=[["4 N/m"]], x0=["5 cm"], v0=[0]))
    ['&\\\\text{with } x \\\\text{ in m and } t \\\\text{ in s}']
    >>> unit_note_latex(ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0]))
    []
    """
    record = getattr(scene, "units", None)
    if record is None:
        return []
    return [rf"&\text{{with }} x \text{{ in {record.length} and }} t \text{{ in s}}"]


def unit_note_text(scene: Any) -> str:
    """The line saying the units of x and t, for text answers (empty without units).

    >>> import laplace_springs as ls
    >>> unit_note_text(ls.Scene.from_matrices(M=[["1 kg"]], K=[["4 N/m"]], x0=["5 cm"], v0=[0]))
    'x in m, t in s'
    """
    record = getattr(scene, "units", None)
    return "" if record is None else f"x in {record.length}, t in s"


def value_latex(value: sympy.Expr, kind: str, scene: Any) -> str:
    """A value as LaTeX, with its unit when the scene has units (``200\\,\\mathrm{N/m}``).

    ``kind`` is a name of :data:`KINDS` (``"displacement"`` is a length); lengths and
    velocities take the scene's length unit, the rest SI.

    Examples
    --------
    >>> import laplace_springs as ls
    >>> scene = ls.Scene.from_matrices(M=[["1 kg"]], K=[["4 N/m"]], x0=["5 cm"], v0=[0])
    >>> value_latex(sympy.Integer(200), "stiffness", scene), value_latex(sympy.Rational(1, 20), "displacement", scene)
    ('200\\\\,\\\\mathrm{N/m}', '\\\\frac{1}{20}\\\\,\\\\mathrm{m}')
    >>> value_latex(sympy.Integer(200), "stiffness", None)
    '200'
    """
    text = str(sympy.latex(value))
    record = getattr(scene, "units", None)
    if record is None:
        return text
    unit = KINDS["length" if kind == "displacement" else kind].si
    unit = unit.replace("m", record.length, 1) if kind in ("displacement", "length", "velocity") else unit
    unit = unit.replace("*", r"\cdot ").replace("**2", "^2")
    return rf"{text}\,\mathrm{{{unit}}}"


# ----------------------------------------------------------------------------
# Helpers the seed uses
# ----------------------------------------------------------------------------


def _si(value: Any, entry: str, kind: str) -> sympy.Expr:
    """The exact SI value of a quantity that must carry a unit."""
    reader = _Reader({})
    converted = reader.leaf(value, entry, KINDS[kind])
    if not reader.written:
        raise SceneError(f"{entry}: {shown(value)} has no unit (dimension found: none), expected "
                         f"{KINDS[kind].describe()}: write it with its unit, e.g. '5 {KINDS[kind].si}'")
    if converted.free_symbols:
        raise SceneError(f"{entry}: {shown(value)} must be a number with its unit")
    return converted


def _magnitude(value: sympy.Expr) -> Any:
    if value.is_Integer:
        return int(value)
    if value.is_Rational:
        return fractions.Fraction(int(value.p), int(value.q))
    return float(value)


def spring_constant(load: Any, deflection: Any) -> Any:
    """Hooke's law k = F/δ from a load and the deflection it causes, exactly, in N/m.

    The seed's Example 5: "if 5 N of force was applied to a spring and it displaced 2 cm,
    the spring constant would be k = 250 N/m".

    Examples
    --------
    >>> spring_constant("5 N", "2 cm")
    <Quantity(250, 'newton / meter')>
    >>> spring_constant("5 N", "2 kg")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: deflection: '2 kg' has dimension [mass] (kilogram), expected a length, [length] (m)
    """
    force = _si(load, "load", "force")
    delta = _si(deflection, "deflection", "length")
    if delta == 0:
        raise SceneError(f"deflection: {shown(deflection)} is zero; a spring constant needs a deflection")
    return registry().Quantity(_magnitude(force / delta), "N/m")


def natural_frequency(stiffness: Any, mass: Any, unit: str = "Hz") -> Any:
    """The natural frequency of a mass on a spring, √(k/m), in Hz (cycles/s) or rad/s.

    Examples
    --------
    >>> f = natural_frequency("250 N/m", "0.5 kg")  # √500 rad/s over 2π
    >>> round(f.magnitude, 9), str(f.units)
    (3.558812717, 'hertz')
    >>> omega = natural_frequency("250 N/m", "0.5 kg", "rad/s")
    >>> round(omega.magnitude, 9), str(omega.units)
    (22.360679775, 'radian / second')
    """
    k = _si(stiffness, "stiffness", "stiffness")
    m = _si(mass, "mass", "mass")
    if m <= 0 or k < 0:
        raise SceneError(f"natural_frequency: needs a positive mass and a nonnegative stiffness, got "
                         f"{shown(mass)} and {shown(stiffness)}")
    target = _checked_unit(unit, "unit", unit, KINDS["frequency"])
    omega = sympy.sqrt(k / m) / (target.factor * (2 * sympy.pi) ** target.cycles)
    return registry().Quantity(float(omega), target.name)


def damping_ratio(damping: Any, stiffness: Any, mass: Any) -> sympy.Expr:
    """The damping ratio ζ = c / (2√(k m)) of a dashpot on a mass and spring, exactly.

    ζ < 1 oscillates (underdamped), ζ = 1 is critical damping, ζ > 1 creeps back.

    Examples
    --------
    >>> damping_ratio("1.4 N*s/m", "400 N/m", "1 kg")
    7/200
    >>> damping_ratio("40 kg/s", "400 N/m", "1 kg")
    1
    """
    c = _si(damping, "damping", "damping")
    k = _si(stiffness, "stiffness", "stiffness")
    m = _si(mass, "mass", "mass")
    if m <= 0 or k <= 0 or c < 0:
        raise SceneError(f"damping_ratio: needs a positive mass and stiffness and a nonnegative "
                         f"damping, got {shown(mass)}, {shown(stiffness)} and {shown(damping)}")
    return sympy.radsimp(c / (2 * sympy.sqrt(k * m)))
