"""A scene as a drawable chain: masses in coordinate order and the components between them.

:func:`chain_of` reads a scene built from components as it is, and a scene built from
matrices as a chain in disguise: with a diagonal M and symmetric C, K, off-diagonal
entries ``-K[i,j]`` are springs between masses i and j and row sums are springs to a
support (likewise dashpots from C). A normalised scene ``x'' + Bx' + Ax = 0`` with a
non-symmetric A (the seed's ``A = [[3, -1], [-2, 2]]``) is first rescaled by the masses
d_i that make ``diag(d) A`` symmetric (here m2/m1 = 1/2). Anything else (a non-diagonal
M, a positive off-diagonal stiffness, an unsymmetrisable A) raises
:class:`~laplace_springs.model.errors.SceneError` saying why; build such a scene with
:meth:`Scene.from_components <laplace_springs.model.scene.Scene.from_components>` to draw it.

:func:`math_label` and :func:`value_text` turn names and values into the labels the
diagrams show.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import sympy as sp

from ..model.components import Component
from ..model.errors import SceneError
from ..model.numbers import to_exact
from ..model.scene import Scene
from ..model.units import value_latex

__all__ = ["Chain", "chain_of", "physical_matrices", "math_label", "latex_symbol", "value_text"]

_GREEK = {"alpha", "beta", "gamma", "delta", "epsilon", "zeta", "eta", "theta", "kappa",
          "lambda", "mu", "nu", "xi", "rho", "sigma", "tau", "phi", "chi", "psi", "omega"}


# ----------------------------------------------------------------------------
# The chain: masses and components, from components or inferred from matrices
# ----------------------------------------------------------------------------


@dataclass(frozen=True)
class Chain:
    """A scene as a drawable chain: masses, their values, coordinates and components.

    Attributes
    ----------
    masses : tuple of str
        Mass labels in coordinate order (``m1``, ``m2``, ...).
    mass_values : tuple of sympy.Expr
        The masses (for a rescaled normalised scene, the rescaling weights).
    coordinates : tuple of str
        The coordinate names (``x1``, ...), one per mass.
    components : tuple of Component
        Springs and dashpots.
    layout : str
        ``"horizontal"`` or ``"vertical"``.
    inferred : bool
        True when the components were read off the matrices.
    """

    masses: tuple[str, ...]
    mass_values: tuple[sp.Expr, ...]
    coordinates: tuple[str, ...]
    components: tuple[Component, ...]
    layout: str
    inferred: bool = False


def _is_zero(value: sp.Expr) -> bool:
    value = sp.cancel(value) if value.free_symbols else value
    return value == 0


def _symmetrising_weights(A: sp.MatrixBase, B: sp.MatrixBase) -> list[sp.Expr]:
    """Positive d with diag(d)·A and diag(d)·B symmetric (d = 1 on each component's root)."""
    n = A.rows
    weights: list[sp.Expr | None] = [None] * n
    for root in range(n):
        if weights[root] is not None:
            continue
        weights[root] = sp.Integer(1)
        stack = [root]
        while stack:
            i = stack.pop()
            for j in range(n):
                if j == i or weights[j] is not None:
                    continue
                ratio = _ratio(A, B, i, j)
                if ratio is None:
                    continue
                weights[j] = sp.cancel(weights[i] * ratio)
                stack.append(j)
    return [w for w in weights if w is not None]


def _ratio(A: sp.MatrixBase, B: sp.MatrixBase, i: int, j: int) -> sp.Expr | None:
    """d_j / d_i from the first coupling of i and j in A or B (None when uncoupled)."""
    for matrix, name in ((A, "A"), (B, "B")):
        forward, backward = matrix[i, j], matrix[j, i]
        if _is_zero(forward) and _is_zero(backward):
            continue
        if _is_zero(forward) or _is_zero(backward):
            raise SceneError(
                f"cannot draw this scene as a chain: {name}[{i},{j}] = {forward} but "
                f"{name}[{j},{i}] = {backward} (a one-way coupling is no spring or dashpot)")
        ratio = sp.cancel(forward / backward)
        if ratio.is_positive is False:
            raise SceneError(
                f"cannot draw this scene as a chain: {name}[{i},{j}] = {forward} and "
                f"{name}[{j},{i}] = {backward} have opposite signs")
        return ratio
    return None


def physical_matrices(scene: Scene) -> tuple[sp.ImmutableMatrix, sp.ImmutableMatrix, sp.ImmutableMatrix]:
    """Symmetric ``(M, C, K)`` describing the scene's mechanics, M diagonal when possible.

    A scene whose M, C, K are symmetric is returned as it is. A scene with a diagonal
    M and non-symmetric ``A = M⁻¹K`` (the seed's normalised Example 1) is rescaled by
    the weights d with ``diag(d)·A`` and ``diag(d)·B`` symmetric; the motion is the
    same, and ``½vᵀMv + ½xᵀKx`` is then its energy.

    Raises
    ------
    SceneError
        When no such rescaling exists.

    Examples
    --------
    >>> from laplace_springs import Scene
    >>> M, C, K = physical_matrices(Scene.from_normalized(A=[[3, -1], [-2, 2]], x0=[1, 0], v0=[0, 0]))
    >>> M.tolist(), K.tolist()
    ([[1, 0], [0, 1/2]], [[3, -1], [-1, 1]])
    """
    M, C, K = scene.M, scene.C, scene.K
    if all(m.is_symmetric() for m in (M, C, K)):
        return M, C, K
    if not M.is_diagonal():
        raise SceneError("cannot symmetrise a scene with a non-diagonal mass matrix M and "
                         f"non-symmetric K or C; M = {M.tolist()}")
    A, B = scene.normalized()
    weights = _symmetrising_weights(A, B)
    D = sp.diag(*weights)
    K2, C2 = (D * A).applyfunc(sp.cancel), (D * B).applyfunc(sp.cancel)
    for matrix, name in ((K2, "A"), (C2, "B")):
        difference = (matrix - matrix.T).applyfunc(sp.cancel)
        if any(entry != 0 for entry in difference):
            raise SceneError(f"cannot draw this scene as a chain: no positive masses make "
                             f"diag(m)·{name} symmetric for {name} = {(A if name == 'A' else B).tolist()}")
    return sp.ImmutableMatrix(D), sp.ImmutableMatrix(C2), sp.ImmutableMatrix(K2)


def _support_for(index: int, n: int, layout: str, kind: str) -> tuple[str, bool]:
    """The support a mass's grounded component attaches to, and whether it comes first.

    Ends of the chain for springs (and for dashpots of a horizontal chain, as in the
    seed's Example 5); air resistance, across the chain, for dashpots of a vertical one
    (the seed's Example 2).
    """
    if layout == "vertical" and kind == "dashpot":
        return "air", True
    start, end = ("ceiling", "floor") if layout == "vertical" else ("wall", "wall")
    if index == 0:
        return start, True
    if index == n - 1:
        return end, False
    return "ground", True


def _inferred_components(matrix: sp.MatrixBase, kind: str, masses: Sequence[str],
                         layout: str) -> list[tuple[float, Component]]:
    """(position, component) pairs read off a symmetric stiffness or damping matrix."""
    letter = "K" if kind == "spring" else "C"
    n = matrix.rows
    found = []
    for i in range(n):
        grounded = sp.cancel(sum(matrix[i, j] for j in range(n)))
        if grounded.is_negative:
            raise SceneError(f"cannot draw this scene as a chain: row {i} of {letter} sums to "
                             f"{grounded} < 0 (a negative {kind} to a support)")
        if grounded != 0:
            support, first = _support_for(i, n, layout, kind)
            ends = (support, masses[i]) if first else (masses[i], support)
            position = i - 0.5 if first and i == 0 else (i + 0.5 if not first else i + 0.25)
            found.append((position, Component(kind, "", *ends, grounded)))
        for j in range(i + 1, n):
            value = sp.cancel(-matrix[i, j])
            if value.is_negative:
                raise SceneError(f"cannot draw this scene as a chain: {letter}[{i},{j}] = "
                                 f"{matrix[i, j]} > 0 (a {kind} has a negative off-diagonal entry)")
            if value != 0:
                found.append(((i + j) / 2, Component(kind, "", masses[i], masses[j], value)))
    return found


def _infer_chain(scene: Scene) -> Chain:
    M, C, K = physical_matrices(scene)
    if not M.is_diagonal():
        raise SceneError("cannot draw a scene with a non-diagonal mass matrix M = "
                         f"{M.tolist()}; build it with Scene.from_components to draw it")
    masses = tuple(f"m{i + 1}" for i in range(scene.n))
    components = []
    for kind, matrix, prefix in (("spring", K, "k"), ("dashpot", C, "mu")):
        found = sorted(_inferred_components(matrix, kind, masses, scene.layout), key=lambda p: p[0])
        components += [Component(c.kind, f"{prefix}{j}", c.a, c.b, c.value)
                       for j, (_, c) in enumerate(found, start=1)]
    return Chain(masses, tuple(M[i, i] for i in range(scene.n)), scene.names,
                 tuple(components), scene.layout, inferred=True)


def chain_of(scene: Scene) -> Chain:
    """The scene as a chain of masses and components (see the module notes).

    Examples
    --------
    >>> from laplace_springs import load_scene, Scene
    >>> [c.label for c in chain_of(load_scene("three-dashpots")).components]
    ['k1', 'k2', 'k3', 'mu1', 'mu2', 'mu3']
    >>> chain = chain_of(Scene.from_matrices(M=[[1, 0], [0, 2]], K=[[3, -1], [-1, 1]],
    ...                                      C=[[1, 0], [0, 0]], x0=[1, 0], v0=[0, 0]))
    >>> [(c.label, c.a, c.b, c.value) for c in chain.components]
    [('k1', 'wall', 'm1', 2), ('k2', 'm1', 'm2', 1), ('mu1', 'wall', 'm1', 1)]
    """
    if scene.components:
        M = scene.M
        return Chain(scene.mass_names, tuple(M[i, i] for i in range(scene.n)), scene.names,
                     scene.components, scene.layout)
    return _infer_chain(scene)


# ----------------------------------------------------------------------------
# Labels
# ----------------------------------------------------------------------------


def math_label(name: str, value: Any = None) -> str:
    """A name as matplotlib mathtext: ``k1`` → ``$k_{1}$``, ``mu2`` → ``$\\mu_{2}$``.

    Examples
    --------
    >>> math_label("k1"), math_label("mu2"), math_label("b"), math_label("delta_1")
    ('$k_{1}$', '$\\\\mu_{2}$', '$b$', '$\\\\delta_{1}$')
    >>> math_label("m2", sp.Rational(2, 3))
    '$m_{2} = \\\\frac{2}{3}$'
    """
    head = name.rstrip("0123456789").rstrip("_")
    tail = name[len(head):].lstrip("_")
    if not head or not head.isalpha():
        head, tail = name, ""
    symbol = f"\\{head}" if head.lower() in _GREEK else head
    text = f"{symbol}_{{{tail}}}" if tail else symbol
    if value is not None:
        shown_value = value if isinstance(value, str) else sp.latex(to_exact(value, name))
        text += f" = {shown_value}"
    return f"${text}$"


def latex_symbol(name: str) -> str:
    """A name as LaTeX (math mode): ``k1`` → ``k_{1}``, ``mu2`` → ``\\mu_{2}``.

    >>> latex_symbol("k1"), latex_symbol("omega")
    ('k_{1}', '\\\\omega')
    """
    return math_label(name)[1:-1]


#: The quantity each kind of diagram value is, for :func:`value_text`.
QUANTITIES = ("mass", "stiffness", "damping", "displacement")


def value_text(value: Any, quantity: str, scene: Scene | None = None) -> str:
    """A value as the diagrams show it (mathtext without the ``$``): exact, as the scene holds it.

    The one place where a diagram's values become text: a scene that records the units
    its entries were written in shows them here (the units of :mod:`laplace_springs.model`
    plug in at this function; ``quantity`` is one of :data:`QUANTITIES`).

    Examples
    --------
    >>> value_text(sp.Rational(2, 3), "mass"), value_text("0.4", "damping")
    ('\\\\frac{2}{3}', '\\\\frac{2}{5}')
    """
    if quantity not in QUANTITIES:
        raise ValueError(f"quantity must be one of {', '.join(QUANTITIES)}, got {quantity!r}")
    return value_latex(to_exact(value, quantity), quantity, scene)  # with its unit, if any


# ----------------------------------------------------------------------------
