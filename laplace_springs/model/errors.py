"""Exceptions raised by laplace_springs, one class per cause.

* :class:`SceneError`: the input is wrong (a malformed entry, a negative mass, text that
  is not a number). The message names the entry and its value.
* :class:`LimitError`: the input is fine but exceeds a limit of the package (a size, a
  memory or time budget; see :mod:`laplace_springs.limits`). The message names the limit
  and the way out. Both are ``ValueError`` subclasses, so ``except ValueError`` code
  keeps working.
* :class:`FloatRangeError` (a :class:`LimitError`): one engine cannot hold the scene in
  float64; the planner takes another.
* :class:`InternalError`: the package failed where it should not have; a bug to report.
* :class:`InversionError`: a transform cannot be inverted in the requested form.
"""

from __future__ import annotations

__all__ = ["SceneError", "LimitError", "FloatRangeError", "InternalError", "InversionError",
           "InitialDataWarning"]


class SceneError(ValueError):
    """A scene (matrices, components, initial data, scene file) is malformed.

    The message names the offending entry and its value, for example
    ``mass 'm2' must be positive, got -1``.
    """


class LimitError(ValueError):
    """A request exceeds a limit of the package (size, memory, time), not a mistake in it.

    The message names the limit (a field of :class:`laplace_springs.limits.Limits`) and
    the way out, for example evaluating in chunks or solving a coarser model.
    """


class FloatRangeError(LimitError):
    """An engine cannot hold this scene in float64: a scale beyond its range, or a matrix
    singular to working precision. The planner reads it as that engine's refusal and takes
    another engine; it reaches the caller only when the caller named the engine."""


class InternalError(RuntimeError):
    """The package failed in a way it should not (please report it with the scene)."""


class InversionError(ValueError):
    """A transform cannot be inverted in the requested form.

    Raised, for example, for a non-rational transform or for an irreducible
    factor of degree three or more whose coefficients are symbolic.
    """


class InitialDataWarning(UserWarning):
    """Given initial data the equations do not keep: a massless node's position set by its
    springs, or a velocity a massless node cannot have. The motion starts from x(0⁺),
    x'(0⁺); the solution's ``reason`` says the same."""
