"""The knobs of a scene: what the explorer's and the pages' sliders turn.

:func:`knobbed_scene` rewrites a scene with some of its numbers as parameters, so that
:func:`laplace_springs.sweeps.compile.compile_scene` compiles it once and the sliders only
evaluate it at new values:

- the declared parameters of a symbolic scene (their values from ``values=``, else 1);
- the values of springs, dashpots and masses (a component's stamp on K or C, a diagonal
  entry of M: ``K + (p − k)·stamp``), for a scene built from components or a matrix scene
  that is a chain; not those attached to a moving support, whose motion's force depends
  on them;
- the initial data x_i(0), x_i'(0);
- the amplitude F and angular frequency ω of a harmonic force: the scene's own
  (every force a multiple of cos ωt, or of sin ωt) or, for a free scene, a drive
  F cos ωt on the first coordinate, starting at F = 0 and ω = 0.6 ω₁ (off resonance).

Each knob has a range for its slider: ``[v/4, 4v]`` on a log scale for a positive
stiffness, damping or mass; a symmetric range for initial data; ``[0, 3ω₁]`` for the
frequency (ω₁ the lowest natural frequency).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import sympy as sp

from ..model.components import Component
from ..model.errors import SceneError
from ..model.numbers import shown
from ..model.scene import Scene
from ..model.symbols import RESERVED_NAMES, TIME
from ..output.chain import chain_of, latex_symbol, physical_matrices

__all__ = ["Knob", "knobbed_scene", "knob_values", "KNOB_KINDS"]

#: What a knob turns.
KNOB_KINDS = ("parameter", "spring", "dashpot", "mass", "x0", "v0", "amplitude", "frequency")


@dataclass(frozen=True)
class Knob:
    """One slider: the parameter it sets in the knobbed scene and its range.

    Attributes
    ----------
    name : str
        The parameter's name in the knobbed scene (``k1``, ``x0_1``, ``F``, ``w``: the
        drive's frequency ω, not named ``omega``, which is ``ls.omega``).
    label : str
        LaTeX for the slider (``k_{1}``, ``x_{1}(0)``, ``F``, ``\\omega``).
    kind : str
        One of :data:`KNOB_KINDS`.
    value : float
        The scene's own value (where the slider starts).
    low, high : float
        The slider's range.
    log : bool
        Whether the slider moves on a log scale.
    """

    name: str
    label: str
    kind: str
    value: float
    low: float
    high: float
    log: bool = False

    def grid(self, count: int) -> np.ndarray:
        """``count`` values over the range, the knob's own value among them (odd counts)."""
        if self.log:
            values = np.geomspace(self.low, self.high, count)
        else:
            values = np.linspace(self.low, self.high, count)
        if count % 2:
            values[count // 2] = self.value
        return values


def _range(kind: str, value: float, scale: float) -> tuple[float, float, bool]:
    if kind in ("spring", "dashpot", "mass", "parameter") and value > 0:
        return value / 4, value * 4, True
    if kind in ("spring", "dashpot", "mass", "parameter"):
        return 0.0, max(1.0, abs(value) * 4), False
    if kind == "frequency":
        return 0.0, 3 * scale, False
    if kind == "amplitude":
        reach = max(abs(value), scale) * 2
        return -reach, reach, False
    reach = max(abs(value), scale) * 2  # initial data
    return -reach, reach, False


def _stamp(component: Component, index: dict[str, int], n: int) -> sp.Matrix:
    """The matrix a unit spring (or dashpot) between the component's nodes adds to K (or C)."""
    stamp = sp.zeros(n, n)
    ends = [index[node] for node in (component.a, component.b) if node in index]
    for i in ends:
        stamp[i, i] += 1
    if len(ends) == 2:
        i, j = ends
        stamp[i, j] -= 1
        stamp[j, i] -= 1
    return stamp


def _lowest_frequency(M: Any, K: Any) -> float:
    import scipy.linalg

    Mf = np.array(M.tolist(), dtype=float)
    Kf = np.array(K.tolist(), dtype=float)
    eigenvalues = scipy.linalg.eigvalsh(Kf, Mf)
    positive = eigenvalues[eigenvalues > 1e-12 * max(1.0, float(np.max(np.abs(eigenvalues))))]
    return float(np.sqrt(positive.min())) if positive.size else 1.0


def _harmonic(scene: Scene) -> tuple[float, float, sp.Expr] | None:
    """(amplitude of the first force, ω, the forces over the amplitude) when every force is a
    multiple of one cos(ωt) (or one sin(ωt)); None otherwise."""
    if scene.forcing is None or scene.sampled is not None:
        return None
    a, b = sp.Wild("a", exclude=[TIME]), sp.Wild("b", exclude=[TIME])
    found: list[tuple[int, sp.Expr, sp.Expr, Any]] = []
    for i, entry in enumerate(scene.forcing):
        if entry == 0:
            continue
        for function in (sp.cos, sp.sin):
            match = sp.expand(entry).match(a * function(b * TIME))
            if match and match[a].is_number and match[b].is_number and match[b] > 0:
                found.append((i, match[a], match[b], function))
                break
        else:
            return None
    if not found or len({(b_, f) for _, _, b_, f in found}) != 1:
        return None
    amplitude = found[0][1]
    return float(amplitude), float(found[0][2]), found[0][3]


def _numeric(value: Any) -> float | None:
    value = sp.sympify(value)
    return float(value) if value.is_number and value.is_real else None


def knobbed_scene(scene: Scene, *, knobs: Sequence[str] | None = None,
                  values: Mapping[str, Any] | None = None, initial: bool = True,
                  forcing: bool = True, most: int | None = None) -> tuple[Scene, list[Knob]]:
    """The scene with knobs as parameters, and the knobs (see the module notes).

    Parameters
    ----------
    scene : Scene
    knobs : sequence of str, optional
        The components, masses or parameters to turn (by label/name); by default the
        declared parameters of a symbolic scene, else every component and mass.
    values : mapping, optional
        Values of a symbolic scene's parameters (default 1).
    initial : bool
        Knobs for x_i(0) and x_i'(0).
    forcing : bool
        Knobs for the harmonic force's amplitude and frequency.
    most : int, optional
        Keep at most this many component and mass knobs (the first ones: springs, then
        dashpots, then masses).

    Returns
    -------
    (Scene, list of Knob)

    Examples
    --------
    >>> import laplace_springs as ls
    >>> knobbed, knobs = knobbed_scene(ls.load_scene("wall-pair"), initial=False, forcing=False)
    >>> [k.name for k in knobs], [s.name for s in knobbed.parameters]
    (['k1', 'k2', 'k3', 'm1', 'm2'], ['k1', 'k2', 'k3', 'm1', 'm2'])
    >>> float(knobbed.subs({k.name: k.value for k in knobs}).K[0, 0]) == float(ls.load_scene("wall-pair").K[0, 0])
    True
    """
    if scene.sampled is not None:
        raise SceneError("the sliders need forces given as formulas; this scene has sampled forces")
    given = {str(name): value for name, value in (values or {}).items()}
    unknown = set(given) - {s.name for s in scene.parameters}
    if unknown:
        raise SceneError(f"values: {', '.join(sorted(unknown))} is not a parameter of the scene "
                         f"(its parameters: {', '.join(s.name for s in scene.parameters) or 'none'})")
    base = {s: sp.nsimplify(given.get(s.name, 1)) for s in scene.parameters}
    numeric = scene.subs({s.name: v for s, v in base.items()}) if base else scene
    M, C, K = (sp.Matrix(m) for m in physical_matrices(scene))
    x0, v0 = sp.Matrix(scene.x0), sp.Matrix(scene.v0)
    declared: dict[str, str] = {s.name: "real" for s in scene.parameters}
    out: list[Knob] = []
    scale_x = float(max([abs(float(v)) for v in numeric.x0] + [1e-300]))
    if scene.parameters:
        chosen = set(knobs) if knobs is not None else {s.name for s in scene.parameters}
        for symbol in scene.parameters:
            if symbol.name in chosen:
                value = float(base[symbol])
                low, high, log = _range("parameter", value, 1.0)
                out.append(Knob(symbol.name, latex_symbol(symbol.name), "parameter", value, low, high, log))
    else:
        M, C, K = _component_knobs(scene, M, C, K, knobs, most, out, declared)
    Mn, _, Kn = (m.subs(base) if base else m for m in physical_matrices(numeric))
    omega_1 = _lowest_frequency(Mn, Kn)
    if initial:
        for column, kind in ((x0, "x0"), (v0, "v0")):
            for i in range(scene.n):
                name = f"{kind}_{i + 1}"
                start = _numeric(column[i].subs(base)) if base else _numeric(column[i])
                if start is None:
                    continue
                scale = scale_x if kind == "x0" else scale_x * omega_1
                low, high, log = _range(kind, start, scale if scale > 1e-300 else 1.0)
                coordinate = latex_symbol(scene.names[i])
                label = f"{coordinate}(0)" if kind == "x0" else f"\\dot{{{coordinate}}}(0)"
                out.append(Knob(name, label, kind, start, low, high, log))
                column[i] = sp.Symbol(name)
                declared[name] = "real"
    forces = _forcing_knobs(scene, numeric, Kn, omega_1, scale_x, forcing, out, declared)
    knobbed = Scene.from_matrices(
        M=_text(M), C=_text(C), K=_text(K), x0=[str(v) for v in x0], v0=[str(v) for v in v0],
        forcing=forces, names=scene.names, title=scene.title, layout=scene.layout,
        parameters=declared)
    return knobbed, out


def _text(matrix: sp.Matrix) -> list[list[str]]:
    return [[str(matrix[i, j]) for j in range(matrix.cols)] for i in range(matrix.rows)]


def _component_knobs(scene: Scene, M: sp.Matrix, C: sp.Matrix, K: sp.Matrix,
                     knobs: Sequence[str] | None, most: int | None, out: list[Knob],
                     declared: dict[str, str]) -> tuple[sp.Matrix, sp.Matrix, sp.Matrix]:
    """Springs, dashpots and masses as knobs: their stamps on K, C and M."""
    if not all(m.is_symmetric() for m in (scene.M, scene.C, scene.K)):
        return M, C, K  # a normalised scene rescaled to masses: its forces would change too
    try:
        chain = chain_of(scene)
    except SceneError:  # a matrix scene that is no chain has no springs or dashpots to turn
        return M, C, K
    index = {name: i for i, name in enumerate(chain.masses)}
    moving = {name for name, _ in scene.support_motion}
    candidates: list[tuple[str, str, Any, Any]] = []
    for component in sorted(chain.components, key=lambda c: c.kind != "spring"):
        if {component.a, component.b} & moving:
            continue
        candidates.append((component.label, component.kind, component.value, component))
    candidates += [(name, "mass", value, i) for i, (name, value) in
                   enumerate(zip(chain.masses, chain.mass_values))]
    if knobs is not None:
        wanted = list(knobs)
        labels = [c[0] for c in candidates]
        missing = [k for k in wanted if k not in labels]
        if missing:
            raise SceneError(f"knobs: {', '.join(map(shown, missing))} is not a component or mass "
                             f"of the scene (these can be turned: {', '.join(labels)})")
        candidates = [c for c in candidates if c[0] in wanted]
    if most is not None:
        candidates = candidates[:most]
    used = set(declared)
    for label, kind, value, where in candidates:
        name = _safe_name(label, used)
        symbol = sp.Symbol(name)
        number = _numeric(value)
        if number is None:
            continue
        if kind == "mass":
            M[where, where] += symbol - value
        else:
            stamp = _stamp(where, index, scene.n)
            if kind == "spring":
                K += (symbol - value) * stamp
            else:
                C += (symbol - value) * stamp
        low, high, log = _range(kind, number, 1.0)
        out.append(Knob(name, latex_symbol(label), kind, number, low, high, log))
        declared[name] = "positive" if number > 0 else "nonnegative"
    return M, C, K


def _safe_name(label: str, used: set[str]) -> str:
    base = "".join(ch if ch.isalnum() or ch == "_" else "_" for ch in label) or "p"
    if not base[0].isalpha():
        base = "p_" + base
    name, k = base, 2
    while name in used or name in ("F", "w") or name in RESERVED_NAMES or name.startswith(("x0_", "v0_")):
        name, k = f"{base}_{k}", k + 1
    used.add(name)
    return name


def _forcing_knobs(scene: Scene, numeric: Scene, K: Any, omega_1: float, scale_x: float,
                   wanted: bool, out: list[Knob], declared: dict[str, str]) -> list[str] | None:
    """The forces of the knobbed scene (strings), with F and ω as knobs where they fit."""
    own = [str(entry) for entry in scene.forcing] if scene.forcing is not None else None
    if not wanted:
        return own
    harmonic = _harmonic(numeric)
    if scene.forcing is not None and harmonic is None:
        return own  # not one harmonic force: the forces stay as they are
    declared.update(F="real", w="nonnegative")
    stiffness = abs(float(K[0, 0])) or 1.0
    if harmonic is None:  # a free scene: a drive F cos(ωt) on the first coordinate
        low, high, _ = _range("amplitude", 0.0, stiffness * (scale_x if scale_x > 1e-300 else 1.0))
        out.append(Knob("F", "F", "amplitude", 0.0, low, high))
        out.append(Knob("w", "\\omega", "frequency", 0.6 * omega_1, 0.0, 3 * omega_1))
        return ["F*cos(w*t)"] + ["0"] * (scene.n - 1)
    amplitude, omega, function = harmonic
    low, high, _ = _range("amplitude", amplitude, stiffness * scale_x)
    out.append(Knob("F", "F", "amplitude", amplitude, low, high))
    top = 3 * max(omega_1, omega)
    out.append(Knob("w", "\\omega", "frequency", omega, 0.0, top))
    driven = sp.Symbol("w") * TIME
    assert numeric.forcing is not None  # harmonic: every force is a multiple of cos or sin
    forces = []
    for entry in numeric.forcing:
        if entry == 0:
            forces.append("0")
            continue
        ratio = sp.nsimplify(entry / (sp.nsimplify(amplitude) * function(sp.nsimplify(omega) * TIME)))
        forces.append(str(sp.Symbol("F") * ratio * function(driven)))
    return forces


def knob_values(knobs: Sequence[Knob]) -> dict[str, float]:
    """The knobs at their own values, as ``{name: value}``."""
    return {knob.name: knob.value for knob in knobs}
