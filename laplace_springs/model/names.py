"""Names of coordinates, resolved one way everywhere.

A scene's coordinates have names (``Scene.names``, ``x1 .. xn`` by default) and, for a
scene built from components, its masses have names too (``Scene.mass_names``, in the
same order). Wherever the user names a coordinate (initial data and forces given as
mappings, ``with_forcing``, ``with_initial``, scene files, the command line, outputs of
frequency responses, sweeps, animations) the name is resolved here, by one rule:

1. a mass name means that mass, even where it is also the default name of another
   coordinate (masses named ``x2``, ``x1`` in that order: ``x1`` is the second mass);
2. otherwise a coordinate name means that coordinate;
3. anything else is a :class:`~laplace_springs.model.errors.SceneError` listing the names.

Two keys of one mapping that resolve to the same coordinate (``{"m1": 1, "x1": 2}``)
are an error too, never a silent choice.

Examples
--------
>>> coordinate_index("x1", "forcing", names=("x1", "x2"), mass_names=("x2", "x1"))
1
>>> in_coordinate_order({"x1": 5}, "forcing", names=("x1", "x2"), mass_names=("x2", "x1"))
[0, 5]
>>> describe_coordinate(1, names=("x1", "x2"), mass_names=("m1", "m2"))
"mass 'm2' (coordinate x2)"
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from .errors import SceneError
from .numbers import shown

__all__ = ["coordinate_index", "in_coordinate_order", "describe_coordinate"]

#: Names listed in an error message (the rest are counted).
_LISTED = 10


def _listed(names: Sequence[str]) -> str:
    names = list(names)
    if len(names) <= _LISTED:
        return ", ".join(names)
    return f"{', '.join(names[:_LISTED])}, ... ({len(names):,} in all)"


def coordinate_index(name: Any, entry: str, *, names: Sequence[str],
                     mass_names: Sequence[str] = ()) -> int:
    """The coordinate (0-based) a name denotes: a mass name first, then a coordinate name.

    Parameters
    ----------
    name : str
        The name as the user wrote it.
    entry : str
        What is being named, for the message (``"forcing"``, ``"--coordinates"``).
    names, mass_names : sequence of str
        The scene's coordinate names and mass names (empty for scenes built from matrices).

    Raises
    ------
    SceneError
        For anything but a mass or coordinate name, listing both.

    Examples
    --------
    >>> coordinate_index("m2", "x0", names=("x1", "x2"), mass_names=("m1", "m2"))
    1
    >>> coordinate_index("m3", "x0", names=("x1", "x2"), mass_names=("m1", "m2"))
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: x0: unknown mass or coordinate 'm3'; masses are m1, m2; coordinates are x1, x2
    """
    if isinstance(name, str):
        if name in mass_names:
            return list(mass_names).index(name)
        if name in names:
            return list(names).index(name)
    masses = f"masses are {_listed(mass_names)}; " if mass_names else ""
    what = "mass or coordinate" if mass_names else "coordinate"
    raise SceneError(f"{entry}: unknown {what} {shown(name)}; {masses}coordinates are {_listed(names)}")


def in_coordinate_order(values: Mapping[Any, Any], entry: str, *, names: Sequence[str],
                        mass_names: Sequence[str] = (), missing: Any = 0) -> list[Any]:
    """A mapping name -> value as a list in coordinate order (``missing`` where not given).

    Raises
    ------
    SceneError
        For an unknown name, or two names of the same coordinate.

    Examples
    --------
    >>> in_coordinate_order({"m2": "1/2"}, "x0", names=("x1", "x2"), mass_names=("m1", "m2"))
    [0, '1/2']
    >>> in_coordinate_order({"m1": 1, "x1": 2}, "x0", names=("x1", "x2"), mass_names=("m1", "m2"))
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: x0: 'm1' and 'x1' name the same coordinate (mass 'm1' (coordinate x1)); give it once
    """
    column = [missing] * len(names)
    given: dict[int, Any] = {}
    for key, value in values.items():
        index = coordinate_index(key, entry, names=names, mass_names=mass_names)
        if index in given:
            raise SceneError(f"{entry}: {shown(given[index])} and {shown(key)} name the same coordinate "
                             f"({describe_coordinate(index, names=names, mass_names=mass_names)}); "
                             "give it once")
        given[index] = key
        column[index] = value
    return column


def describe_coordinate(index: int, *, names: Sequence[str], mass_names: Sequence[str] = ()) -> str:
    """A coordinate as the user knows it: ``mass 'm2' (coordinate x2)`` or ``coordinate x2``.

    Falls back to the 0-based index when the names do not cover it.

    Examples
    --------
    >>> describe_coordinate(0, names=("x1",))
    'coordinate x1'
    >>> describe_coordinate(3, names=())
    'coordinate 3 (0-based)'
    """
    coordinate = f"coordinate {names[index]}" if 0 <= index < len(names) else f"coordinate {index} (0-based)"
    if 0 <= index < len(mass_names):
        return f"mass {mass_names[index]!r} ({coordinate})"
    return coordinate
