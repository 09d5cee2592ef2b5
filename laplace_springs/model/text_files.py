"""Reading text files that users point at (scene files, CSV force histories) safely."""

from __future__ import annotations

from pathlib import Path

from ..limits import limits
from .errors import SceneError

__all__ = ["read_text_file"]


def read_text_file(path: Path, what: str, limit_name: str, encoding: str = "utf-8") -> str:
    """The text of ``path``, reading at most the limit + 1 bytes whatever the file is.

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
        When the file cannot be read, is larger than ``limit`` or is not UTF-8 text.

    Examples
    --------
    >>> read_text_file(Path("no-such-file.toml"), "scene file", "max_file_bytes")
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: cannot read scene file 'no-such-file.toml': No such file or directory
    """
    limit = getattr(limits(), limit_name)
    try:
        with path.open("rb") as file:
            data = file.read(limit + 1)
    except OSError as exc:
        raise SceneError(f"cannot read {what} {str(path)!r}: {exc.strerror or exc}") from None
    if len(data) > limit:
        raise SceneError(f"{what} {str(path)!r} has more than {limit:,} bytes, the limit "
                         f"Limits.{limit_name}")
    try:
        return data.decode(encoding)
    except UnicodeDecodeError as exc:
        raise SceneError(f"{what} {str(path)!r} is not UTF-8 text: {exc}") from None
