"""Components of a scene built from parts: springs and dashpots between two nodes."""

from __future__ import annotations

from dataclasses import dataclass

import sympy

__all__ = ["Component"]


@dataclass(frozen=True)
class Component:
    """A spring or dashpot between two nodes (mass names or fixed supports).

    Attributes
    ----------
    kind : str
        ``"spring"`` (value is a stiffness) or ``"dashpot"`` (value is a damping constant).
    label : str
        The component's name, e.g. ``"k1"`` or ``"mu2"``.
    a, b : str
        The nodes it connects: mass names, or a support name in lower case.
    value : sympy.Expr
        The exact stiffness or damping constant.
    """

    kind: str
    label: str
    a: str
    b: str
    value: sympy.Expr
