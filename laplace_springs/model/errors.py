"""Exceptions raised by laplace_springs."""

from __future__ import annotations

__all__ = ["SceneError", "InversionError"]


class SceneError(ValueError):
    """A scene (matrices, components, initial data, scene file) is malformed.

    The message names the offending entry and its value, for example
    ``mass 'm2' must be positive, got -1``.
    """


class InversionError(ValueError):
    """A transform cannot be inverted in the requested form.

    Raised, for example, for a non-rational transform or for an irreducible
    factor of degree three or more whose coefficients are symbolic.
    """
