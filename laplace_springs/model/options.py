"""Numbers on the command line: argparse ``type`` functions that read a number as a scene's
entry is read (ASCII digits only: Python's int() and float() also take ``1_0`` and other
scripts' digits such as ``٣``). Shared by :mod:`laplace_springs.cli` and the publish
commands."""

from __future__ import annotations

import argparse
import re

__all__ = ["strict_int", "strict_float", "PLAIN_NUMBER", "NOT_FINITE"]

PLAIN_NUMBER = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
NOT_FINITE = re.compile(r"[+-]?(?:nan|inf|infinity)", re.IGNORECASE)


def strict_int(text: str) -> int:
    """An integer option: ASCII digits with an optional sign (argparse's ``type``).

    Python's int() also takes ``1_0`` and other scripts' digits (``٣``); a scene's entries
    do not, and neither does the command line.

    Examples
    --------
    >>> strict_int(" 30 "), strict_int("-2")
    (30, -2)
    >>> strict_int("1_0")
    Traceback (most recent call last):
    ...
    argparse.ArgumentTypeError: expected an integer such as 30, got '1_0'
    """
    if re.fullmatch(r"\s*[+-]?[0-9]+\s*", text) is None:
        raise argparse.ArgumentTypeError(f"expected an integer such as 30, got {text!r}")
    return int(text)


def strict_float(text: str) -> float:
    """A number option: a plain decimal number, ``nan`` or ``inf`` (refused by the command's
    own checks with their reason), as argparse's ``type``.

    Examples
    --------
    >>> strict_float("2.5"), strict_float("1e-3")
    (2.5, 0.001)
    >>> strict_float("٣")
    Traceback (most recent call last):
    ...
    argparse.ArgumentTypeError: expected a number such as 2.5, got '٣'
    """
    item = text.strip()
    if PLAIN_NUMBER.fullmatch(item) is None and NOT_FINITE.fullmatch(item) is None:
        raise argparse.ArgumentTypeError(f"expected a number such as 2.5, got {text!r}")
    return float(item)
