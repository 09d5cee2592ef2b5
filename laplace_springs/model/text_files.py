"""Reading text files that users point at (scene files, CSV force histories) safely.

Only regular files are read: a FIFO, a device, a socket or a directory is refused before
it is opened (``os.stat``), and again after (``os.fstat`` of a descriptor opened without
blocking, so that a file swapped for a FIFO in between cannot make the read wait for a
writer). At most the size limit + 1 bytes are read, whatever the file is.

Paths that a scene file names (its CSV force histories) must stay inside the scene
file's folder unless the caller opts in: :func:`contained_path` refuses absolute paths
and paths that lead out of the folder (``../``, or a symbolic link pointing elsewhere).
"""

from __future__ import annotations

import os
import stat
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

from ..limits import limits
from .errors import SceneError

__all__ = ["read_text_file", "checked_path", "contained_path"]

T = TypeVar("T")

#: What a file that is not regular is, by the test of its mode.
_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISSOCK, "a socket"))
#: Opening without blocking (a FIFO with no writer would block) and without making a
#: terminal the controlling one; 0 where the platform has no such flag.
_OPEN_FLAGS = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0) | getattr(os, "O_BINARY", 0)


def checked_path(path: object, what: str) -> Path:
    """``path`` as a :class:`~pathlib.Path`, or a SceneError for anything that is not a
    path given as text or a path-like object (bytes, numbers, None, text with NUL).

    Examples
    --------
    >>> checked_path("force.csv", "CSV file")
    PosixPath('force.csv')
    >>> checked_path(123, "scene file")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: scene file: expected a path (text or a pathlib.Path), got 123
    """
    if isinstance(path, os.PathLike):
        path = os.fspath(path)
    if not isinstance(path, str):
        raise SceneError(f"{what}: expected a path (text or a pathlib.Path), got {_short(path)}")
    if "\x00" in path or not path:
        raise SceneError(f"{what}: expected a path, got {_short(path)}")
    return Path(path)


def _short(value: object) -> str:
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def _kind(mode: int) -> str | None:
    """What a file of this mode is when it is not a regular file, else None."""
    if stat.S_ISREG(mode):
        return None
    return next((kind for test, kind in _KINDS if test(mode)), "not a regular file")


def read_text_file(path: Path, what: str, limit_name: str, encoding: str = "utf-8") -> str:
    """The text of the regular file ``path``, reading at most the limit + 1 bytes.

    Parameters
    ----------
    path : pathlib.Path
        The file.
    what : str
        What it is, for messages ("scene file", "CSV file").
    limit_name : str
        The field of :class:`~laplace_springs.limits.Limits` that holds the largest size
        accepted (named in the message).
    encoding : str
        "utf-8", or "utf-8-sig" to drop a byte-order mark.

    Raises
    ------
    SceneError
        When the file cannot be read, is not a regular file (a FIFO, a device, a
        directory: refused before anything is read), is larger than the limit or is not
        UTF-8 text. The message never quotes the file's contents.

    Examples
    --------
    >>> read_text_file(Path("no-such-file.toml"), "scene file", "max_file_bytes")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: cannot read scene file 'no-such-file.toml': No such file or directory
    >>> read_text_file(Path("."), "scene file", "max_file_bytes")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: cannot read scene file '.': it is a directory, not a regular file
    """
    limit = getattr(limits(), limit_name)
    where = f"{what} {str(path)!r}"
    kind = _kind(_os_call(os.stat, path, where).st_mode)
    if kind is not None:
        raise SceneError(f"cannot read {where}: it is {kind}, not a regular file")
    descriptor = _os_call(os.open, path, where, _OPEN_FLAGS)
    with os.fdopen(descriptor, "rb") as file:
        try:
            kind = _kind(os.fstat(descriptor).st_mode)  # the file opened is the one checked
            if kind is not None:
                raise SceneError(f"cannot read {where}: it is {kind}, not a regular file")
            data = file.read(limit + 1)
        except OSError as exc:
            raise SceneError(f"cannot read {where}: {exc.strerror or exc}") from None
    if len(data) > limit:
        raise SceneError(f"{where} has more than {limit:,} bytes, the limit Limits.{limit_name}")
    try:
        return data.decode(encoding)
    except UnicodeDecodeError as exc:
        raise SceneError(f"{where} is not UTF-8 text: byte {exc.start + 1:,} cannot be decoded") from None


def _os_call(function: Callable[..., T], path: Path, where: str, *args: Any) -> T:
    """``function(path, *args)`` with its OSError (or the ValueError of a path the OS
    cannot take) as a SceneError naming the file."""
    try:
        return function(path, *args)
    except OSError as exc:
        raise SceneError(f"cannot read {where}: {exc.strerror or exc}") from None
    except ValueError as exc:
        raise SceneError(f"cannot read {where}: {exc}") from None


def contained_path(name: str, base: str | os.PathLike[str] | None, what: str,
                   allow_outside: bool = False) -> Path:
    """The path a file names (``csv = "force.csv"`` in a scene file), inside ``base``.

    Parameters
    ----------
    name : str
        The path as written, relative to ``base`` (the folder of the file that names it;
        the current directory when None).
    base : path-like or None
    what : str
        The entry, for messages.
    allow_outside : bool
        When True, absolute paths and paths leading out of ``base`` are allowed (the
        caller trusts the file that names them).

    Raises
    ------
    SceneError
        For an absolute path or one that leads out of ``base`` (``../``, or a symbolic
        link to elsewhere), unless ``allow_outside``.

    Examples
    --------
    >>> contained_path("data/force.csv", "/scenes", "forcing.m1.csv")
    PosixPath('/scenes/data/force.csv')
    >>> contained_path("../etc/passwd", "/scenes", "forcing.m1.csv")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: forcing.m1.csv: '../etc/passwd' leads out of the scene file's folder; ...
    """
    path = checked_path(name, what)
    folder = Path(base) if base is not None else Path.cwd()
    if allow_outside:
        return path if path.is_absolute() else folder / path
    hint = ("a scene file may only name files in its own folder (load_scene(..., "
            "allow_outside=True) if you trust it)")
    if path.is_absolute() or path.drive or path.root:
        raise SceneError(f"{what}: {name!r} is an absolute path; {hint}")
    joined = folder / path
    try:
        inside = joined.resolve().is_relative_to(folder.resolve())
    except (OSError, RuntimeError):  # a symbolic-link loop
        inside = False
    if not inside:
        raise SceneError(f"{what}: {name!r} leads out of the scene file's folder; {hint}")
    return joined
