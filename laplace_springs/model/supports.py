"""Supports: their names, and supports that move (base excitation).

A spring or dashpot of a scene built from components joins two masses, or a mass and a
support. A support is named by one of the words of :data:`SUPPORTS` (``wall``,
``ceiling``, ``ground``, ``floor``, ``support``, ``air``; any case), or by such a word
followed by ``_``, ``-`` or a digit and more letters, digits, ``_`` or ``-``:
``wall_left``, ``wall_right``, ``ground2`` and ``floor-b`` are four distinct supports.
Names are kept in lower case.

Moving supports. A support may move with a prescribed displacement u(t) (see
``support_motion`` of :meth:`Scene.from_components
<laplace_springs.model.scene.Scene.from_components>`). A spring k between mass i and the
support then pulls with k (u(t) − x_i) instead of −k x_i, and a dashpot c with
c (u'(t) − x_i'). The scene keeps its M, C, K; the support's motion enters as the
equivalent force

    f_i(t) = Σ_springs k u(t) + Σ_dashpots c u'(t)

added to any external force on mass i. u is any forcing input of
:mod:`laplace_springs.model.forcing` (text is parsed, never evaluated) and u' is its exact
derivative: a step in u is an impulse in u', so a dashpot on a support that steps by h
gives the mass a blow of momentum c h. u(t) is the support's position for t > 0 measured
from its rest position, like the masses' coordinates; a u with u(0) ≠ 0 and no step
(``"1/100"``, ``"cos(t)"``) is a support already displaced at t = 0 (no blow), while
``"Heaviside(t)/100"`` steps at t = 0 (a blow c/100 through each dashpot).
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping, Sequence
from typing import Any, Protocol

import sympy as sp

from .components import Component
from .errors import SceneError
from .forcing import input_transform, parse_forcing
from .numbers import shown
from .symbols import TIME


class Scene(Protocol):
    """What this module reads of a :class:`~laplace_springs.model.scene.Scene` (the scene
    module imports this one, so the type is described here rather than imported)."""

    @property
    def components(self) -> tuple[Component, ...]: ...

    @property
    def mass_names(self) -> tuple[str, ...]: ...

    @property
    def support_motion(self) -> tuple[tuple[str, sp.Expr], ...]: ...

    @property
    def n(self) -> int: ...

__all__ = [
    "SUPPORTS",
    "MotionRecord",
    "is_support",
    "support_name",
    "scene_supports",
    "parse_support_motion",
    "support_velocity",
    "support_forcing",
    "with_support_forcing",
    "support_columns",
    "moving_support",
    "support_motion_latex",
    "support_motion_words",
]

#: The words that name a fixed support (case-insensitive). A name that is one of these
#: words, or one followed by ``_``, ``-`` or a digit and more (``wall_left``, ``ground2``),
#: is a support.
SUPPORTS = frozenset({"wall", "ceiling", "ground", "floor", "support", "air"})

#: What may follow a support word in a support name (after lower-casing).
_SUFFIX = re.compile(r"[_\-0-9][a-z0-9_\-]*")

#: The scene's record of its moving supports: (support name, displacement u(t)) pairs.
MotionRecord = tuple[tuple[str, sp.Expr], ...]


def support_name(node: Any) -> str | None:
    """The support a node name denotes, in lower case; ``None`` if it names no support.

    Examples
    --------
    >>> support_name("Wall"), support_name("wall_left"), support_name("ground2")
    ('wall', 'wall_left', 'ground2')
    >>> support_name("m1"), support_name("wallace"), support_name(3)
    (None, None, None)
    """
    if not isinstance(node, str):
        return None
    lowered = node.lower()
    for word in SUPPORTS:
        if lowered == word or (lowered.startswith(word)
                               and _SUFFIX.fullmatch(lowered[len(word):]) is not None):
            return lowered
    return None


def is_support(node: Any) -> bool:
    """Whether a node name denotes a support (see :func:`support_name`).

    Examples
    --------
    >>> is_support("ceiling"), is_support("WALL_RIGHT"), is_support("m1")
    (True, True, False)
    """
    return support_name(node) is not None


def scene_supports(components: Iterable[Component]) -> list[str]:
    """The supports the components attach to, in order of first appearance.

    Examples
    --------
    >>> from laplace_springs.model.scene import Scene
    >>> scene = Scene.from_components(masses={"m1": 1, "m2": 1},
    ...     springs={"k1": ("wall_left", "m1", 1), "k2": ("m1", "m2", 1), "k3": ("m2", "wall_right", 1)})
    >>> scene_supports(scene.components)
    ['wall_left', 'wall_right']
    """
    found: dict[str, None] = {}
    for component in components:
        for node in (component.a, component.b):
            if is_support(node):
                found.setdefault(node)
    return list(found)


def support_velocity(u: sp.Expr, entry: str = "support motion") -> sp.Expr:
    """u'(t), exactly: steps in u become impulses.

    A product g(t) δ(t − τ), as the derivative of ``H(t - 1) H(t - 2)`` or of the ramp
    ``(t - 1) H(t - 1)`` has, is written g(τ) δ(t − τ) (a step at its own switching time
    counts 1/2, SymPy's ``Heaviside(0)``).

    Examples
    --------
    >>> from laplace_springs.model.symbols import TIME as t
    >>> support_velocity(sp.sin(3 * t) / 100)
    3*cos(3*t)/100
    >>> support_velocity(sp.Heaviside(t - 1) / 100)
    DiracDelta(t - 1)/100
    >>> support_velocity(sp.Heaviside(t - 1) * sp.Heaviside(t - 2))
    DiracDelta(t - 2)
    """
    derivative = sp.diff(u, TIME)
    terms = []
    for term in sp.Add.make_args(sp.expand(derivative)):
        deltas = [factor for factor in sp.Mul.make_args(term) if isinstance(factor, sp.DiracDelta)]
        if len(deltas) != 1:
            terms.append(term)
            continue
        delta = deltas[0]
        if len(delta.args) > 1:
            raise SceneError(f"{entry}: its derivative {derivative} has a derivative of an impulse")
        moment = sp.solve(delta.args[0], TIME)
        if len(moment) != 1 or not moment[0].is_number:
            raise SceneError(f"{entry}: the impulse {delta} of its derivative has no single time")
        weight = sp.Mul(*(factor for factor in sp.Mul.make_args(term) if factor is not delta))
        terms.append(weight.xreplace({TIME: moment[0]}) * delta)  # g(t) δ(t − τ) = g(τ) δ(t − τ)
    return sp.Add(*terms)


def parse_support_motion(motion: Any, components: Sequence[Component],
                         parameters: Mapping[str, sp.Symbol] | None = None) -> MotionRecord:
    """The checked record of moving supports: (support, u(t)) pairs, in the order given.

    Parameters
    ----------
    motion : mapping of str to (text, number or sympy.Expr), or None
        Support name -> its displacement u(t), a forcing input in ``t``
        (:func:`laplace_springs.model.forcing.parse_forcing`).
    components : sequence of Component
        The scene's springs and dashpots: every support named must have one attached.
    parameters : mapping of str to sympy.Symbol, optional
        The declared parameters the text may name.

    Raises
    ------
    SceneError
        For a name that is no support or no support of this scene, a support given twice,
        an input outside the forcing class, an undeclared name, a displacement with an
        impulse, or a velocity u' outside the forcing class (when a dashpot is attached).

    Examples
    --------
    >>> from laplace_springs.model.scene import Scene
    >>> scene = Scene.from_components(masses={"m": 1}, springs={"k": ("ground", "m", 4)})
    >>> parse_support_motion({"Ground": "sin(3*t)/100"}, scene.components)
    (('ground', sin(3*t)/100),)
    >>> parse_support_motion({"wall": "t"}, scene.components)
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: support_motion: unknown support 'wall': no spring or dashpot is attached to it; the scene's supports are ground
    """
    if motion is None:
        return ()
    if not isinstance(motion, Mapping):
        raise SceneError("support_motion must be a mapping support name -> displacement u(t), "
                         f"got {shown(motion)}")
    attached = scene_supports(components)
    listed = ", ".join(attached) or "none"
    record: dict[str, sp.Expr] = {}
    for key, value in motion.items():
        name = support_name(key)
        if name is None:
            raise SceneError(f"support_motion: {shown(key)} is not a support name (a support is "
                             f"named {', '.join(sorted(SUPPORTS))}, or one of these followed by "
                             f"_, - or a digit: wall_left); the scene's supports are {listed}")
        if name not in attached:
            raise SceneError(f"support_motion: unknown support {key!r}: no spring or dashpot is "
                             f"attached to it; the scene's supports are {listed}")
        if name in record:
            raise SceneError(f"support_motion: support {name!r} is given twice")
        entry = f"support_motion[{name!r}]"
        u = parse_forcing(value, entry, parameters)
        if u.has(sp.DiracDelta):
            raise SceneError(f"{entry}: a displacement {u} cannot contain an impulse (DiracDelta)")
        if any(c.kind == "dashpot" and name in (c.a, c.b) for c in components):
            velocity = support_velocity(u, entry)
            input_transform(velocity, f"{entry}: its velocity u'(t) = {velocity}")
        record[name] = u
    return tuple((name, u) for name, u in record.items() if u != 0)


def support_forcing(components: Iterable[Component], mass_names: Sequence[str],
                    record: MotionRecord) -> sp.ImmutableMatrix | None:
    """The equivalent force of the moving supports: Σ k u(t) + Σ c u'(t) per mass.

    Examples
    --------
    >>> from laplace_springs.model.scene import Scene
    >>> scene = Scene.from_components(masses={"m": 1}, springs={"k": ("ground", "m", 4)},
    ...                               dashpots={"c": ("m", "ground", "1/2")})
    >>> support_forcing(scene.components, scene.mass_names, (("ground", sp.sin(3 * TIME)),))
    Matrix([[4*sin(3*t) + 3*cos(3*t)/2]])
    """
    if not record:
        return None
    moving = dict(record)
    velocity = {name: support_velocity(u, f"support_motion[{name!r}]") for name, u in record}
    index = {name: i for i, name in enumerate(mass_names)}
    parts: list[list[sp.Expr]] = [[] for _ in mass_names]
    for component in components:
        for support, mass in ((component.a, component.b), (component.b, component.a)):
            if support in moving and mass in index:
                drive = moving[support] if component.kind == "spring" else velocity[support]
                parts[index[mass]].append(component.value * drive)
    column = [sp.Add(*terms) for terms in parts]
    if all(entry == 0 for entry in column):
        return None
    return sp.ImmutableMatrix(column)


def with_support_forcing(external: sp.ImmutableMatrix | None, components: Iterable[Component],
                         mass_names: Sequence[str], record: MotionRecord
                         ) -> sp.ImmutableMatrix | None:
    """The scene's forcing: the external forces plus the moving supports' equivalent force.

    Examples
    --------
    >>> from laplace_springs.model.scene import Scene
    >>> scene = Scene.from_components(masses={"m": 1}, springs={"k": ("ground", "m", 4)})
    >>> with_support_forcing(sp.ImmutableMatrix([1]), scene.components, scene.mass_names,
    ...                      (("ground", TIME),))
    Matrix([[4*t + 1]])
    """
    moving = support_forcing(components, mass_names, record)
    if moving is None:
        return external
    if external is None:
        return moving
    total = sp.ImmutableMatrix(external + moving)
    return None if all(entry == 0 for entry in total) else total


def moving_support(scene: Scene, support: str | None = None) -> str:
    """The support of ``scene`` that ``support`` names, lower case; by default the one that
    moves (or the only one).

    Raises
    ------
    SceneError
        For a scene without components, an unknown support, or no default (several
        supports and not exactly one of them moving).

    Examples
    --------
    >>> from laplace_springs.model.scene import Scene
    >>> scene = Scene.from_components(masses={"m": 1},
    ...     springs={"k1": ("wall_left", "m", 1), "k2": ("m", "wall_right", 1)},
    ...     support_motion={"wall_left": "sin(t)"})
    >>> moving_support(scene), moving_support(scene, "WALL_RIGHT")
    ('wall_left', 'wall_right')
    """
    if not scene.components:
        raise SceneError("supports are known only for scenes built from components "
                         "(Scene.from_components or [masses] in a scene file)")
    attached = scene_supports(scene.components)
    listed = ", ".join(attached) or "none"
    if support is None:
        moving = [name for name, _ in scene.support_motion]
        candidates = moving if moving else attached
        if len(candidates) != 1:
            raise SceneError(f"name the support: this scene has supports {listed}")
        return candidates[0]
    name = support_name(support)
    if name is None or name not in attached:
        raise SceneError(f"unknown support {shown(support)}; the scene's supports are {listed}")
    return name


def support_columns(scene: Scene, support: str | None = None
                    ) -> tuple[sp.ImmutableMatrix, sp.ImmutableMatrix]:
    """(K_s, C_s): the stiffness and damping that tie each mass to one support, n x 1.

    A moving support's displacement u drives the masses with K_s u + C_s u'.

    Examples
    --------
    >>> from laplace_springs.model.scene import Scene
    >>> scene = Scene.from_components(masses={"m1": 1, "m2": 1},
    ...     springs={"k1": ("wall_left", "m1", 3), "k2": ("m1", "m2", 1), "k3": ("m2", "wall_right", 2)},
    ...     dashpots={"c": ("wall_left", "m1", "1/2")})
    >>> support_columns(scene, "wall_left")
    (Matrix([
    [3],
    [0]]), Matrix([
    [1/2],
    [  0]]))
    """
    name = moving_support(scene, support)
    index = {mass: i for i, mass in enumerate(scene.mass_names)}
    columns = {"spring": [sp.S.Zero] * scene.n, "dashpot": [sp.S.Zero] * scene.n}
    for component in scene.components:
        for end, mass in ((component.a, component.b), (component.b, component.a)):
            if end == name and mass in index:
                columns[component.kind][index[mass]] += component.value
    return sp.ImmutableMatrix(columns["spring"]), sp.ImmutableMatrix(columns["dashpot"])


def support_motion_words(scene: Scene) -> str:
    """The moving supports for a scene's ``repr``: ``""`` or ``", moving ground"``.

    Examples
    --------
    >>> from laplace_springs.model.scene import Scene
    >>> scene = Scene.from_components(masses={"m": 1}, springs={"k": ("ground", "m", 4)},
    ...                               support_motion={"ground": "sin(3*t)/100"})
    >>> support_motion_words(scene)
    ', moving ground'
    """
    record = getattr(scene, "support_motion", ())
    return f", moving {', '.join(name for name, _ in record)}" if record else ""


def support_motion_latex(scene: Scene) -> str:
    """The moving supports' displacements as LaTeX, ``u_{\\text{ground}}(t) = ...``; ``""``
    when no support moves.

    Examples
    --------
    >>> from laplace_springs.model.scene import Scene
    >>> scene = Scene.from_components(masses={"m": 1}, springs={"k": ("ground", "m", 4)},
    ...                               support_motion={"ground": "sin(3*t)/100"})
    >>> print(support_motion_latex(scene))
    u_{\\text{ground}}(t) = \\frac{\\sin{\\left(3 t \\right)}}{100}
    """
    record = getattr(scene, "support_motion", ())
    names = [name.replace("_", "\\_") for name, _ in record]
    return ",\\ ".join(f"u_{{\\text{{{name}}}}}(t) = {sp.latex(u)}"
                       for name, (_, u) in zip(names, record))
