"""Sampled (measured) force histories: a force given by its values at sample times.

A :class:`Sampled` entry is a forcing entry like a formula, but it is data, not a SymPy
expression (10⁵ samples would be 10⁵ Heaviside pieces). The force is the interpolant of
the samples:

* ``kind="linear"``: the straight line between neighbouring samples (piecewise linear,
  continuous);
* ``kind="zoh"``: zero-order hold, the value of sample k on [t_k, t_{k+1}) (the last
  value is reached only at the last time, so it plays no role).

**Outside the data's time span the force is zero**: before the first sample time and
after the last one. A force that should last past the data needs samples up to then.
The response is exact for the interpolant (see :mod:`laplace_springs.numeric.sampled`).

Read a CSV column with :meth:`Sampled.from_csv` (or :func:`sampled_from_csv`); a scene
file points at one with ``forcing = { m1 = { csv = "force.csv", time = "t", value =
"F", kind = "linear" } }`` (the path relative to the scene file).
"""

from __future__ import annotations

import csv
import dataclasses
import decimal
import math
import numbers
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..limits import limits
from .errors import LimitError, SceneError
from .numbers import shown
from .text_files import checked_path, contained_path, read_text_file

__all__ = ["KINDS", "Sampled", "sampled", "sampled_from_csv",
           "sampled_entries", "formula_part", "resolve_csv_entries"]

#: The interpolants: piecewise linear, or piecewise constant (zero-order hold).
KINDS = ("linear", "zoh")
_CSV_KEYS = ("csv", "time", "value", "kind", "delimiter")


def _array(values: Any, name: str) -> np.ndarray:
    """A flat, finite float64 array of real numbers, or a SceneError naming the first bad
    entry (a complex, huge, text or boolean value is never converted silently).

    Arrays of integers and floats convert at once; other sequences entry by entry
    (:func:`_real_number`). At most :attr:`~laplace_springs.limits.Limits.max_samples`
    entries, checked before any is converted.
    """
    if isinstance(values, (str, bytes)) or not hasattr(values, "__len__"):
        raise SceneError(f"sampled {name} must be a sequence of numbers, got {shown(values)}")
    size = int(values.size) if isinstance(values, np.ndarray) else len(values)
    if size > limits().max_samples:
        raise LimitError(f"sampled {name} has {size:,} samples, more than the limit "
                         f"{limits().max_samples:,} (Limits.max_samples); resample the history "
                         "more coarsely, or split it into several scenes")
    array = values if isinstance(values, np.ndarray) else _plain_array(values)
    if array is None or array.dtype.kind not in "fiu":
        array = np.array([_real_number(value, f"sampled {name}[{index}]")
                          for index, value in enumerate(_flat(values, name))], dtype=float)
    else:
        array = np.array(array, dtype=float)  # a copy: the caller's array stays theirs
    if array.ndim != 1:
        raise SceneError(f"sampled {name} must be one-dimensional, got shape {array.shape}")
    bad = np.flatnonzero(~np.isfinite(array))
    if bad.size:
        raise SceneError(f"sampled {name}[{int(bad[0])}] = {float(array[bad[0]])!r} is not finite")
    return array


def _plain_array(values: Any) -> np.ndarray | None:
    """``values`` as NumPy reads it when that is a numeric array, else None (ragged,
    mixed or exotic entries go entry by entry)."""
    try:
        array = np.asarray(values)
    except (TypeError, ValueError, OverflowError):
        return None
    if array.dtype.kind not in "fiu" or any(isinstance(value, (bool, np.bool_)) for value in values):
        return None  # NumPy would read True as 1
    return array


def _flat(values: Any, name: str) -> list[Any]:
    """The entries of a one-dimensional sequence (a nested one is refused by its shape)."""
    items = values.tolist() if isinstance(values, np.ndarray) else list(values)
    if isinstance(values, np.ndarray) and values.ndim != 1:
        raise SceneError(f"sampled {name} must be one-dimensional, got shape {values.shape}")
    for index, item in enumerate(items):
        if isinstance(item, (list, tuple, np.ndarray)):
            raise SceneError(f"sampled {name} must be a flat sequence of numbers, but entry {index} "
                             f"is {shown(item)}")
    return items


def _complex(value: Any, entry: str) -> Any:
    """The real part of a number that is complex in form (Python, NumPy or SymPy) with a
    zero imaginary part; a SceneError for a complex or non-numeric value."""
    try:
        number = complex(value)
    except OverflowError:
        raise SceneError(f"{entry} = {shown(value)} is beyond the float64 range (about 1.8e308)") from None
    except (TypeError, ValueError):
        raise SceneError(f"{entry} = {shown(value)} is not a number") from None
    if number.imag != 0:
        raise SceneError(f"{entry} = {shown(value)} is complex; samples must be real")
    return number.real


def _real_number(value: Any, entry: str) -> float:
    """One sample as a float64: a real number within the float64 range (an int, a
    Fraction, a Decimal, a NumPy or SymPy number), or a complex one whose imaginary part
    is zero; anything else is a SceneError naming the entry."""
    if isinstance(value, (bool, np.bool_)):
        raise SceneError(f"{entry} = {value!r} is a boolean, not a number")
    if isinstance(value, (str, bytes)):
        raise SceneError(f"{entry} = {shown(value)} is not a number")
    if not isinstance(value, (numbers.Real, decimal.Decimal)):
        value = _complex(value, entry)
    beyond = f"{entry} = {shown(value)} is beyond the float64 range (about 1.8e308)"
    try:
        number = float(value)
    except OverflowError:
        raise SceneError(beyond) from None
    except (TypeError, ValueError):
        raise SceneError(f"{entry} = {shown(value)} is not a real number") from None
    if not math.isfinite(number):
        finite = isinstance(value, decimal.Decimal) and value.is_finite() or isinstance(value, numbers.Rational)
        raise SceneError(beyond if finite else f"{entry} = {shown(value)} is not finite")
    return number


@dataclass(frozen=True, eq=False)
class Sampled:
    """A force history given by samples: its interpolant, zero outside the data's span.

    Build it with :func:`sampled` (checked) or :meth:`from_csv`.

    Attributes
    ----------
    times : numpy.ndarray
        float64, strictly increasing, ≥ 0, at least 2.
    values : numpy.ndarray
        float64, finite, one per time.
    kind : {"linear", "zoh"}
        Piecewise linear interpolation, or zero-order hold.
    source : str
        Where the data came from (a file name), for messages; may be empty.
    """

    times: np.ndarray
    values: np.ndarray
    kind: str = "linear"
    source: str = ""

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise SceneError(f"sampled kind must be one of {', '.join(KINDS)}, got {shown(self.kind)}")
        times, values = _array(self.times, "times"), _array(self.values, "values")
        if times.size != values.size:
            raise SceneError(f"sampled times has {times.size} entries but values has {values.size}; "
                             "they must have the same length")
        if times.size < 2:
            raise SceneError(f"sampled data needs at least 2 samples (the force lives between the "
                             f"first and the last time), got {times.size}")
        if times[0] < 0:
            raise SceneError(f"sampled times[0] = {float(times[0])!r} is negative; the motion starts at t = 0")
        step = np.diff(times)
        bad = np.flatnonzero(~(step > 0))
        if bad.size:
            k = int(bad[0]) + 1
            raise SceneError(f"sampled times must be strictly increasing: times[{k}] = {float(times[k])!r} "
                             f"follows times[{k - 1}] = {float(times[k - 1])!r}")
        times.setflags(write=False)
        values.setflags(write=False)
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "values", values)

    def __repr__(self) -> str:
        where = f" from {self.source!r}" if self.source else ""
        return (f"<Sampled {self.kind}: {self.times.size} samples on "
                f"[{self.times[0]:g}, {self.times[-1]:g}]{where}>")

    @property
    def start(self) -> float:
        """The first sample time: the force is zero before it."""
        return float(self.times[0])

    @property
    def end(self) -> float:
        """The last sample time: the force is zero after it."""
        return float(self.times[-1])

    def slopes(self) -> np.ndarray:
        """The slope of the interpolant on each interval (zeros for ``"zoh"``)."""
        if self.kind == "zoh":
            return np.zeros(self.times.size - 1)
        return np.diff(self.values) / np.diff(self.times)

    def __call__(self, t: Any) -> np.ndarray:
        """The interpolated force at times ``t`` (zero outside [start, end]).

        Intervals are closed on the left: at a sample time the value is the sample's,
        for "zoh" too.

        Examples
        --------
        >>> f = sampled([0, 1, 3], [0, 2, 0])
        >>> f([0.5, 1, 2, 3, 4]).tolist()
        [1.0, 2.0, 1.0, 0.0, 0.0]
        >>> sampled([0, 1, 3], [0, 2, 0], kind="zoh")([0.5, 1, 2.9, 3]).tolist()
        [0.0, 2.0, 2.0, 0.0]
        """
        t = np.asarray(t, dtype=float)
        k = np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, self.times.size - 2)
        tau = t - self.times[k]
        out = self.values[k] + self.slopes()[k] * tau
        if self.kind == "linear":
            out = np.where(t == self.end, self.values[-1], out)
        return np.where((t < self.start) | (t > self.end) | ((t == self.end) & (self.kind == "zoh")),
                        0.0, out)

    @classmethod
    def from_csv(cls, path: str | os.PathLike[str], time: str = "t", value: str | None = None,
                 kind: str = "linear", *, delimiter: str = ",") -> Sampled:
        """Read a force history from two columns of a CSV file with a header row.

        Parameters
        ----------
        path : str or os.PathLike
        time : str
            The header of the time column.
        value : str, optional
            The header of the force column; by default the one column besides ``time``.
        kind : {"linear", "zoh"}
        delimiter : str
            The field separator (``","``; ``";"`` or ``"\\t"`` for other exports).

        Cells are read with ``float`` (decimal text such as ``1.5``, ``-2e-3``; never
        evaluated). Blank lines and lines starting with ``#`` are skipped.

        Raises
        ------
        SceneError
            For a missing file or column, a cell that is not a number (naming its line),
            more than :attr:`~laplace_springs.limits.Limits.max_csv_bytes`, and every check of :func:`sampled`.

        Examples
        --------
        >>> import tempfile, pathlib
        >>> folder = pathlib.Path(tempfile.mkdtemp())
        >>> _ = (folder / "force.csv").write_text("t,F\\n0,0\\n0.5,1.5\\n1,0\\n")
        >>> Sampled.from_csv(folder / "force.csv", time="t", value="F")
        <Sampled linear: 3 samples on [0, 1] from 'force.csv'>
        """
        path = checked_path(path, "CSV file")
        _check_csv_options(time, value, kind, delimiter)
        text = _read_csv_text(path)
        numbered = _csv_rows(text, delimiter, path.name)
        if not numbered:
            raise SceneError(f"{path.name}: the CSV file is empty")
        header = [cell.strip() for cell in numbered[0][1]]
        columns = [_column(header, time, "time", path.name)]
        if value is None:
            others = [index for index, name in enumerate(header) if name != time]
            if len(others) != 1:
                raise SceneError(f"{path.name}: say which column is the force (value=...): the "
                                 f"header (line {numbered[0][0]}) has {len(header)} columns")
            value = header[others[0]]
        columns.append(_column(header, value, "value", path.name))
        if len(numbered) - 1 > limits().max_samples:
            raise LimitError(f"{path.name}: {len(numbered) - 1:,} rows of samples, more than the "
                             f"limit {limits().max_samples:,} (Limits.max_samples); resample the "
                             "history more coarsely")
        data = np.empty((len(numbered) - 1, 2))
        names = (time, value)
        for r, (line, row) in enumerate(numbered[1:]):
            for c, index in enumerate(columns):
                if index >= len(row):
                    raise SceneError(f"{path.name}, line {line}: no {names[c]!r} entry")
                data[r, c] = _number(row[index], f"{path.name}, line {line}, column {names[c]!r}")
        try:
            return cls(data[:, 0], data[:, 1], kind, path.name)
        except SceneError as exc:
            raise SceneError(f"{path.name}: {exc}") from None


def _check_csv_options(time: object, value: object, kind: object, delimiter: object) -> None:
    """The options of :meth:`Sampled.from_csv`, checked before the file is read."""
    for option, given in (("time", time), ("value", value)):
        if given is not None and not isinstance(given, str):
            raise SceneError(f"sampled CSV: {option} must be a column name (text), got {shown(given)}")
    if kind not in KINDS:
        raise SceneError(f"sampled kind must be one of {', '.join(KINDS)}, got {shown(kind)}")
    if not (isinstance(delimiter, str) and len(delimiter) == 1 and delimiter not in "\"\r\n"):
        raise SceneError(f"sampled CSV: delimiter must be one character (',', ';' or a tab), "
                         f"got {shown(delimiter)}")


def _csv_rows(text: str, delimiter: str, name: str) -> list[tuple[int, list[str]]]:
    """The (line number, cells) of the rows that are not blank or ``#`` comments."""
    reader = csv.reader(text.splitlines(), delimiter=delimiter)
    rows: list[tuple[int, list[str]]] = []
    try:
        for row in reader:
            if row and any(cell.strip() for cell in row) and not row[0].lstrip().startswith("#"):
                rows.append((reader.line_num, row))
    except csv.Error as exc:
        limit = csv.field_size_limit()
        why = (f"a cell has more than {limit:,} characters" if "field larger" in str(exc)
               else f"it cannot be read as CSV ({exc})")
        raise SceneError(f"{name}, line {max(reader.line_num, 1)}: {why}") from None
    return rows


def _read_csv_text(path: Path) -> str:
    return read_text_file(path, "CSV file", "max_csv_bytes", "utf-8-sig")


def _column(header: list[str], name: str, role: str, where: str) -> int:
    """The index of column ``name``; the message does not quote the header (the file may
    not be a CSV file at all, and its contents are not for an error message)."""
    if name not in header:
        raise SceneError(f"{where}: no column {name!r} for the {role} in the header row "
                         f"({len(header)} columns)")
    return header.index(name)


def _number(cell: str, where: str) -> float:
    text = cell.strip()
    shown_cell = repr(text) if len(text) <= 40 else repr(text[:40]) + "..."  # the offending cell only
    try:
        value = float(text)  # decimal text only: float() evaluates nothing
    except ValueError:
        raise SceneError(f"{where}: {shown_cell} is not a number") from None
    if not math.isfinite(value):
        raise SceneError(f"{where}: {shown_cell} is not finite")
    return value


def sampled(times: Any, values: Any, kind: str = "linear") -> Sampled:
    """A sampled force history, to use as a forcing entry.

    The force is the interpolant of the samples (``"linear"``, or ``"zoh"`` for piecewise
    constant) and **zero outside the data's time span** [times[0], times[-1]].

    Parameters
    ----------
    times : array_like
        Strictly increasing, finite, ≥ 0; at least 2.
    values : array_like
        Finite, one per time.
    kind : {"linear", "zoh"}

    Raises
    ------
    SceneError
        Naming the offending index and value.

    Examples
    --------
    >>> import laplace_springs as ls
    >>> from laplace_springs.model.sampled import sampled
    >>> f = sampled([0, 0.5, 1], [0, 1, 0])
    >>> f
    <Sampled linear: 3 samples on [0, 1]>
    >>> scene = ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[0], v0=[0], forcing=[f])
    >>> scene
    <Scene 1 coordinate, undamped, forced (sampled)>
    >>> sampled([0, 2, 1], [0, 0, 0])
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: sampled times must be strictly increasing: times[2] = 1.0 follows times[1] = 2.0

    ``sampled.from_csv`` reads a CSV column (see :meth:`Sampled.from_csv`).
    """
    return Sampled(times, values, kind)


def sampled_from_csv(path: str | os.PathLike[str], time: str = "t", value: str | None = None,
                     kind: str = "linear", *, delimiter: str = ",") -> Sampled:
    """:meth:`Sampled.from_csv`: a force history from two columns of a CSV file.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> path = pathlib.Path(tempfile.mkdtemp()) / "f.csv"
    >>> _ = path.write_text("time;force\\n0;1\\n2;1\\n")
    >>> sampled_from_csv(path, time="time", delimiter=";", kind="zoh").values.tolist()
    [1.0, 1.0]
    """
    return Sampled.from_csv(path, time, value, kind, delimiter=delimiter)


sampled.from_csv = Sampled.from_csv  # type: ignore[attr-defined]


def sampled_entries(values: Any) -> tuple[Sampled | None, ...] | None:
    """The sampled entries of a forcing sequence, per coordinate (None where a formula
    is), or None when there are none (see ``Scene.sampled``).

    Examples
    --------
    >>> kept = sampled_entries(["cos(t)", sampled([0, 1], [1, 1])])
    >>> kept[0], kept[1].kind
    (None, 'linear')
    >>> sampled_entries(["cos(t)", 0]) is None
    True
    """
    if not isinstance(values, (list, tuple)):
        return None
    if not any(isinstance(value, Sampled) for value in values):
        return None
    return tuple(value if isinstance(value, Sampled) else None for value in values)


def formula_part(scene: Any) -> Any:
    """The scene without its sampled entries (formula forcing and initial data kept)."""
    return dataclasses.replace(scene, sampled=None)


def resolve_csv_entries(forcing: Any, base: str | os.PathLike[str] | None, *,
                        allow_outside: bool = False) -> Any:
    """A scene file's forcing with ``{csv = ..., time = ..., value = ..., kind = ...}``
    tables replaced by :class:`Sampled` entries.

    A path is relative to ``base`` (the scene file's folder; the current directory when
    None) and must stay inside it: absolute paths and paths leading out of it (``../``, a
    symbolic link to elsewhere) are refused unless ``allow_outside`` (see
    :func:`~laplace_springs.model.text_files.contained_path`), so that a scene file from
    someone else cannot make the toolkit read files beside it.

    Examples
    --------
    >>> resolve_csv_entries({"m1": "cos(t)"}, None)
    {'m1': 'cos(t)'}
    >>> resolve_csv_entries({"m1": {"csv": "/etc/passwd"}}, "/scenes")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: forcing.m1.csv: '/etc/passwd' is an absolute path; a scene file may only name files in its own folder (...)
    """
    if isinstance(forcing, dict):
        return {key: _csv_entry(value, f"forcing.{key}", base, allow_outside)
                for key, value in forcing.items()}
    if isinstance(forcing, list):
        return [_csv_entry(value, f"forcing[{i}]", base, allow_outside) for i, value in enumerate(forcing)]
    return forcing


def _csv_entry(value: Any, entry: str, base: str | os.PathLike[str] | None, allow_outside: bool) -> Any:
    if not isinstance(value, dict):
        return value
    unknown = [key for key in value if key not in _CSV_KEYS]
    if unknown or "csv" not in value:
        raise SceneError(f"{entry}: a sampled force is a table {{csv = \"file.csv\", time = \"t\", "
                         f"value = \"F\", kind = \"linear\"}}; "
                         + (f"unknown key {shown(unknown[0])}" if unknown else "it needs 'csv'"))
    for key in _CSV_KEYS:
        if key in value and not isinstance(value[key], str):
            raise SceneError(f"{entry}.{key} must be a string, got {shown(value[key])}")
    path = contained_path(value["csv"], base, f"{entry}.csv", allow_outside)
    try:
        return Sampled.from_csv(path, value.get("time", "t"), value.get("value"),
                                value.get("kind", "linear"), delimiter=value.get("delimiter", ","))
    except SceneError as exc:
        raise SceneError(f"{entry}: {exc}") from None
