"""Scene files: TOML descriptions of scenes, and the bundled scenes of the seed.

A scene file describes a scene in one of three forms. Components::

    title = "Two masses hanging from the ceiling"
    layout = "vertical"
    description = "free text"
    [masses]
    m1 = "1"
    m2 = "1/2"
    [springs]                      # label = [node_a, node_b, value]
    k1 = ["ceiling", "m1", "2"]
    k2 = ["m1", "m2", "1"]
    [dashpots]
    [initial]
    x0 = ["1", "0"]                # or a table {m1 = "1"}
    v0 = ["0", "1"]
    [forcing]                      # optional: mass name = force in t (or an array)
    m1 = "10*cos(20*t)"
    [support_motion]               # optional: moving support = its displacement u(t)
    ceiling = "sin(3*t)/100"       # (wall_left, ground2 ... name distinct supports)
    [parameters]                   # optional: names the text may use as symbols
    F0 = "amplitude of the force"  # a description (positive), or an assumption:
    a = "real"                     # positive, nonnegative, real or negative

matrices (``[matrices]`` with ``M`` and optionally ``C``, ``K``), or the seed's
normalised form (``[normalized]`` with ``A`` and optionally ``B``); both take
``[initial]`` too and an optional top-level ``names`` array. Or the equations of motion
(``[equations]``, read by :meth:`Scene.from_equations`; forces on their right-hand
side, initial conditions among them or in ``[initial]``)::

    [equations]
    motion = [
        "m1*x1'' + (k1 + k2)*x1 - k2*x2 = 0",
        "m2*x2'' - k2*x1 + (k2 + k3)*x2 = cos(t)",
        "x1(0) = 1/20; x1'(0) = 0; x2(0) = 0; x2'(0) = 0",
    ]
    coordinates = ["x1", "x2"]     # optional: the column order

Numbers may be TOML strings (``"1/2"``, ``"0.2"``, ``"k1"``) or TOML numbers (a TOML float ``0.2``
means ``1/5``); all go through :func:`laplace_springs.model.numbers.to_exact`, and no
text is ever evaluated. A value with a unit is a string (``m1 = "500 g"``,
``k1 = ["wall", "m1", "2.5 N/cm"]``, ``x0 = ["5 cm", "3 cm"]``, ``m1 = "10*cos(3*t) N"``
in ``[forcing]``; see :mod:`laplace_springs.model.units`); a top-level ``units = "SI"``
declares bare numbers to be SI. A name in text is a parameter only if the ``[parameters]``
table declares it; an undeclared name is an error, so a typo is never a symbol.
Unknown keys are refused, to catch typos.

Limits. A scene file is read in time proportional to its size, and these limits are
checked before any heavy work, each violation a :class:`SceneError` that names the table
or entry and the limit:

* :attr:`~laplace_springs.limits.Limits.max_file_bytes` (16 MiB): the file's size, checked before it is parsed (no
  more than this is ever read);
* :attr:`~laplace_springs.limits.Limits.max_coordinates` (100,000): masses in
  ``[masses]``, coordinates of a scene;
* :attr:`~laplace_springs.limits.Limits.max_components` (300,000): springs and dashpots
  together;
* :attr:`~laplace_springs.limits.Limits.max_matrix_input_size` (500): n of the n x n
  arrays of ``[matrices]`` and ``[normalized]`` (n² entries each); describe larger
  scenes by their masses, springs and dashpots;
* :attr:`~laplace_springs.limits.Limits.max_parameters` (10,000): names in
  ``[parameters]``;
* nesting of TOML arrays and tables as deep as the TOML reader takes (a few hundred).

Files. Only a regular file is read (a FIFO, a device or a directory is refused before
it is opened), and the CSV files a scene file names must lie in its folder
(``load_scene(path, allow_outside=True)`` for a scene file you trust); see
:mod:`laplace_springs.model.text_files`.

The counts of ``[masses]``, ``[springs]``, ``[dashpots]`` and ``[parameters]`` and the first row of a
matrix are read from the text before it is parsed, so an oversized file is refused in
a fraction of a second; the counts are checked again, exactly, on the parsed tables.
Measured on one core (benchmarks/bench_loading.py): a chain of 10,000 masses with
springs and dashpots (30,000 entries, 0.8 MB) loads in about 1.5 s, 30,000 springs
between 1,000 masses in about 1.5 s, a 100,000-mass chain (8.5 MB) in about 20 s.
"""

from __future__ import annotations

import os
import re
import tomllib
from collections.abc import Mapping
from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import Any

from ..limits import limits
from .errors import SceneError
from .numbers import shown
from .sampled import resolve_csv_entries
from .scene import Scene
from .text_files import checked_path, read_text_file

__all__ = ["bundled_scenes", "load_scene", "scene_from_toml_text"]


#: A line that opens a table (``[name]``, ``[[name]]``, quoted or dotted names).
_HEADER = re.compile(r"^[ \t]*\[\[?([^\[\]\n]*)\]\]?[ \t]*(?:#[^\n]*)?$", re.M)
#: A line that starts a key/value pair.
_KEY_LINE = re.compile(r"^[ \t]*[A-Za-z0-9_\"'-][^=\n]*=", re.M)
#: The first row of a matrix key's nested array: ``M = [[a, b, ...]``.
_FIRST_ROW = re.compile(r"^[ \t]*(M|A)[ \t]*=[ \t]*\[\s*\[([^\]]*)\]", re.M)

_COMMON_KEYS = ("title", "layout", "description", "initial", "forcing", "parameters")
_FORMS = {
    "masses": ("masses", "springs", "dashpots", "support_motion", "units"),
    "matrices": ("matrices", "names", "units"),
    "normalized": ("normalized", "names", "units"),
    "equations": ("equations",),
}
_FORM_TABLES = {"matrices": ("M", "C", "K"), "normalized": ("A", "B")}
_EQUATIONS_KEYS = ("motion", "coordinates")
_INITIAL_KEYS = ("x0", "v0")


def _check_keys(table: Mapping[str, Any], allowed: tuple[str, ...], where: str) -> None:
    for key in table:
        if key not in allowed:
            raise SceneError(f"unknown key {shown(key)} {where}; allowed keys: {', '.join(allowed)}")


def _table(data: Mapping[str, Any], key: str) -> dict[str, Any]:
    value = data.get(key, {})
    if not isinstance(value, dict):
        raise SceneError(f"{key!r} must be a table, like [{key}], got {shown(value)}")
    return value


def _text(data: Mapping[str, Any], key: str, default: str) -> str:
    value = data.get(key, default)
    if not isinstance(value, str):
        raise SceneError(f"{key!r} must be a string, got {shown(value)}")
    return value


def _form_of(data: Mapping[str, Any]) -> str:
    """Which of the four forms the file uses; exactly one must be present."""
    present = [form for form in _FORMS if form in data]
    if len(present) != 1:
        found = ", ".join(f"[{form}]" for form in present) or "none"
        raise SceneError("a scene file needs exactly one of [masses], [matrices], [normalized], "
                         f"[equations]; found {found}")
    form = present[0]
    allowed = _COMMON_KEYS + _FORMS[form]
    for key in data:
        if any(key in keys for keys in _FORMS.values()) and key not in allowed:
            raise SceneError(f"key {key!r} does not belong with [{form}]")
    _check_keys(data, allowed, "at the top level")
    return form


def _scene_from_data(data: Mapping[str, Any], base: str | os.PathLike[str] | None = None,
                     allow_outside: bool = False) -> Scene:
    scene = _unforced_scene(data)
    forcing = data.get("forcing")
    if forcing is None:
        return scene
    if "equations" in data:
        raise SceneError("[forcing] does not belong with [equations]: write the forces on the "
                         "right-hand side of the equations")
    if not isinstance(forcing, (list, dict)):
        raise SceneError(f"'forcing' must be an array (one entry per coordinate) or a table "
                         f"(mass name = expression), got {shown(forcing)}")
    return scene.with_forcing(resolve_csv_entries(  # {csv = ...}: model/sampled.py
        forcing, base, allow_outside=allow_outside))


def _parameters(data: Mapping[str, Any]) -> dict[str, Any]:
    """The ``[parameters]`` table: name -> assumption word or description."""
    table = _table(data, "parameters")
    for name, declaration in table.items():
        if not isinstance(declaration, str):
            raise SceneError(f"[parameters] {name} must be a string (an assumption such as "
                             f"\"positive\" or \"real\", or a description), got {shown(declaration)}")
    return table


def _unforced_scene(data: Mapping[str, Any]) -> Scene:
    form = _form_of(data)
    initial = _table(data, "initial")
    _check_keys(initial, _INITIAL_KEYS, "in [initial]")
    title, layout = _text(data, "title", ""), _text(data, "layout", "horizontal")
    _text(data, "description", "")  # checked only: free text, not part of a Scene
    parameters = _parameters(data)
    if form == "equations":
        return _equations_scene(_table(data, "equations"), initial, parameters, title, layout)
    if form == "masses":
        return Scene.from_components(
            masses=_table(data, "masses"),
            springs=_table(data, "springs"),
            dashpots=_table(data, "dashpots"),
            x0=initial.get("x0"),
            v0=initial.get("v0"),
            title=title,
            layout=layout,
            parameters=parameters,
            support_motion=_table(data, "support_motion") or None,
            units=data.get("units"),
        )
    matrices = _table(data, form)
    _check_keys(matrices, _FORM_TABLES[form], f"in [{form}]")
    required = _FORM_TABLES[form][0]
    if required not in matrices:
        raise SceneError(f"[{form}] needs {required}")
    zeros = [0] * len(matrices[required]) if isinstance(matrices[required], list) else None
    x0, v0, names = initial.get("x0", zeros), initial.get("v0", zeros), _names(data)
    common: dict[str, Any] = {"x0": x0, "v0": v0, "names": names, "title": title, "layout": layout,
                              "parameters": parameters, "units": data.get("units")}
    if form == "matrices":
        return Scene.from_matrices(**matrices, **common)
    return Scene.from_normalized(**matrices, **common)


def _equations_scene(table: Mapping[str, Any], initial: Mapping[str, Any],
                     parameters: Mapping[str, Any], title: str, layout: str) -> Scene:
    """The ``[equations]`` form: ``motion`` (text, or an array of statements) and
    optionally ``coordinates``; initial conditions in the text or in ``[initial]``."""
    _check_keys(table, _EQUATIONS_KEYS, "in [equations]")
    motion = table.get("motion")
    if isinstance(motion, list) and all(isinstance(item, str) for item in motion):
        motion = "\n".join(motion)
    if not isinstance(motion, str):
        raise SceneError(f"[equations] motion must be a string or an array of strings (the "
                         f"equations), got {shown(motion)}")
    coordinates = table.get("coordinates")
    if coordinates is not None and not (isinstance(coordinates, list)
                                        and all(isinstance(name, str) for name in coordinates)):
        raise SceneError(f"[equations] coordinates must be an array of names, got {shown(coordinates)}")
    return Scene.from_equations(motion, parameters=parameters, coordinates=coordinates,
                                x0=initial.get("x0"), v0=initial.get("v0"), title=title,
                                layout=layout)


def _names(data: Mapping[str, Any]) -> list[str] | None:
    names = data.get("names")
    if names is not None and not (isinstance(names, list) and all(isinstance(name, str) for name in names)):
        raise SceneError(f"'names' must be an array of strings, got {shown(names)}")
    return names


def scene_from_toml_text(text: str, source: str = "<string>", *,
                         base: str | os.PathLike[str] | None = None,
                         allow_outside: bool = False) -> Scene:
    """A scene from the text of a TOML scene file.

    A forcing entry may point at a CSV file of samples, ``m1 = { csv = "force.csv",
    time = "t", value = "F", kind = "linear" }`` (see :mod:`laplace_springs.model.sampled`);
    a relative path is taken relative to ``base`` (the scene file's folder for
    :func:`load_scene`; the current directory when None) and must stay inside it.

    Parameters
    ----------
    text : str
        The TOML text (see the module documentation for the format).
    source : str, optional
        Where the text comes from, for error messages (a file name).
    base : path-like, optional
        The folder CSV paths are relative to.
    allow_outside : bool, optional
        Let CSV paths be absolute or lead out of ``base`` (``../``): only for a scene file
        you trust. By default such a path is a SceneError, so that a scene file from
        someone else cannot make the toolkit read (or quote) files outside its folder.

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        For malformed TOML (with tomllib's line and column), unknown keys, and
        every error of the scene builders; the message starts with ``source``.

    Examples
    --------
    >>> scene = scene_from_toml_text('''
    ... title = "One mass on a wall spring"
    ... [masses]
    ... m1 = 2
    ... [springs]
    ... k1 = ["wall", "m1", 0.5]
    ... [initial]
    ... x0 = {m1 = "1/10"}
    ... ''')
    >>> scene
    <Scene 'One mass on a wall spring': 1 coordinate, undamped>
    >>> scene.K, scene.x0
    (Matrix([[1/2]]), Matrix([[1/10]]))
    >>> scene_from_toml_text('titel = "typo"\\n[masses]\\nm1 = 1', source="typo.toml")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: typo.toml: unknown key 'titel' at the top level; allowed keys: ...
    """
    if not isinstance(text, str):
        raise SceneError(f"{source}: expected the text of a scene file, got {shown(text)}")
    try:
        _check_text_size(text)
        _check_counts(text)
    except SceneError as exc:
        raise SceneError(f"{source}: {exc}") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"{source}: malformed TOML: {exc}") from None
    except RecursionError:
        raise SceneError(f"{source}: malformed TOML: arrays or tables nested too deeply for "
                         "the TOML reader") from None
    try:
        return _scene_from_data(data, base, allow_outside)
    except SceneError as exc:
        raise SceneError(f"{source}: {exc}") from None


def _scenes_folder() -> Traversable:
    return resources.files("laplace_springs.model") / "scenes"


def _bundled_files() -> dict[str, Traversable]:
    """Bundled scene files by scene name, sorted by name."""
    files = {entry.name.removesuffix(".toml"): entry for entry in _scenes_folder().iterdir()
             if entry.name.endswith(".toml")}
    return dict(sorted(files.items()))


def bundled_scenes() -> dict[str, str]:
    """The bundled scenes: name -> title, sorted by name.

    Examples
    --------
    >>> scenes = bundled_scenes()
    >>> list(scenes)
    ['example5-in-units', 'three-dashpots', 'vertical-pair', 'vertical-pair-damped', 'wall-pair', 'wall-pair-dashpot']
    >>> scenes["vertical-pair"]
    'Example 1: two masses hanging from the ceiling'
    """
    return {
        name: _text(tomllib.loads(entry.read_text(encoding="utf-8")), "title", "")
        for name, entry in _bundled_files().items()
    }


def _looks_like_path(name_or_path: str | os.PathLike[str]) -> bool:
    if isinstance(name_or_path, os.PathLike):
        return True
    if not isinstance(name_or_path, str):
        raise SceneError(f"load_scene: expected a bundled scene name or the path of a .toml file "
                         f"(text or a pathlib.Path), got {shown(name_or_path)}")
    return name_or_path.endswith(".toml") or "/" in name_or_path or os.sep in name_or_path


def _read_path(path: Path) -> str:
    """The text of a scene file: at most Limits.max_file_bytes are read, whatever the file is."""
    return read_text_file(path, "scene file", "max_file_bytes", "utf-8-sig")


def _check_text_size(text: str) -> None:
    if len(text) > limits().max_file_bytes:  # characters: at least as many bytes
        raise SceneError(f"the text has {len(text):,} characters, more than the limit "
                         f"{limits().max_file_bytes:,} bytes (Limits.max_file_bytes)")


def _section_lines(text: str) -> dict[str, int]:
    """Key lines in each table opened by a plain ``[name]`` line, counted without parsing.

    Tables end where any table header starts, so entries are never counted in the wrong
    table; inline tables and dotted keys are not counted here (the exact counts follow
    the parse).
    """
    headers = list(_HEADER.finditer(text))
    counts: dict[str, int] = {}
    for header, following in zip(headers, [*headers[1:], None]):
        name = header.group(1).strip()
        if header.group(0).lstrip().startswith("[["):
            continue
        end = following.start() if following is not None else len(text)
        counts[name] = counts.get(name, 0) + sum(1 for _ in _KEY_LINE.finditer(text, header.end(), end))
    return counts


def _check_counts(text: str) -> None:
    """Limits.max_coordinates, Limits.max_components and Limits.max_matrix_input_size, from the text (fast)."""
    if len(text) < 100_000:
        return  # small files are parsed in milliseconds and checked exactly
    counts = _section_lines(text)
    masses = counts.get("masses", 0)
    if masses > limits().max_coordinates:
        raise SceneError(f"[masses]: {masses:,} masses, more than the limit {limits().max_coordinates:,} "
                         "(Limits.max_coordinates)")
    parameters = counts.get("parameters", 0)
    if parameters > limits().max_parameters:
        raise SceneError(f"[parameters]: {parameters:,} parameters, more than the limit "
                         f"{limits().max_parameters:,} (Limits.max_parameters)")
    components = counts.get("springs", 0) + counts.get("dashpots", 0)
    if components > limits().max_components:
        raise SceneError(f"[springs] and [dashpots]: {components:,} components, more than the limit "
                         f"{limits().max_components:,} (Limits.max_components)")
    for form in ("matrices", "normalized"):
        header = re.search(rf"^[ \t]*\[[ \t]*{form}[ \t]*\]", text, re.M)
        row = _FIRST_ROW.search(text, header.end()) if header else None
        if row is None:
            continue
        entries = row.group(2).strip().rstrip(",")
        size = entries.count(",") + 1 if entries else 0
        if size > limits().max_matrix_input_size:
            raise SceneError(
                f"[{form}] {row.group(1)}: {size:,} entries in its first row, more than the limit "
                f"{limits().max_matrix_input_size:,} (Limits.max_matrix_input_size); describe a larger scene by "
                "its masses, springs and dashpots ([masses], [springs], [dashpots])")


def load_scene(name_or_path: str | os.PathLike[str], *, allow_outside: bool = False) -> Scene:
    """Load a bundled scene by name, or a scene file by path.

    Parameters
    ----------
    name_or_path : str or os.PathLike
        A bundled scene name (see :func:`bundled_scenes`), or the path of a
        TOML scene file (a path-like object, or text ending in ``.toml`` or
        containing a path separator). Only a regular file is read: a FIFO, a device
        or a directory is refused before it is opened.
    allow_outside : bool, optional
        Let the CSV files the scene file names lie outside its folder (absolute paths,
        ``../``); by default they are refused (see :func:`scene_from_toml_text`).

    Returns
    -------
    Scene

    Raises
    ------
    SceneError
        For an unknown name (the message lists the bundled ones), an unreadable
        file, or any error in the file.

    Examples
    --------
    >>> scene = load_scene("vertical-pair")
    >>> scene.normalized()[0]
    Matrix([
    [ 3, -1],
    [-2,  2]])
    >>> load_scene("no-such-scene")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: unknown scene 'no-such-scene'; bundled scenes: example5-in-units, three-dashpots, ...
    """
    if _looks_like_path(name_or_path):
        path = checked_path(name_or_path, "load_scene")
        return scene_from_toml_text(_read_path(path), source=str(path), base=path.parent,
                                    allow_outside=allow_outside)
    files = _bundled_files()
    if name_or_path not in files:
        raise SceneError(
            f"unknown scene {name_or_path!r}; bundled scenes: {', '.join(files)} "
            f"(or give the path of a .toml file)"
        )
    return scene_from_toml_text(
        files[name_or_path].read_text(encoding="utf-8"), source=f"{name_or_path}.toml"
    )
