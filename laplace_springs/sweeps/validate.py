"""Every parameter set of a sweep held to the checks of :meth:`Scene.subs`.

``ls.solve(scene.subs(set))`` refuses a set that makes a spring or dashpot negative, a
mass negative or the mass matrix indefinite; a sweep refuses the same sets, with the same
words and the set's index and values. The checks run vectorised on the entries (in
double-double where the scene compiles, so the sign of an entry is certain); a set whose
entry is too close to the boundary to decide (a mass that vanishes: a massless node, whose
pencil must then be regular) is checked exactly by ``scene.subs`` itself.
"""

from __future__ import annotations

import numpy as np

from ..model.errors import SceneError
from ..model.scene import Scene
from .entries import SceneEntries
from .parameters import ParameterSets

__all__ = ["validate_sets", "exact_check"]

def exact_check(scene: Scene, sets: ParameterSets, b: int) -> Scene:
    """``scene.subs(set b)``, its SceneError naming the set."""
    try:
        return scene.subs(sets.values(b))
    except SceneError as error:
        raise SceneError(f"sweep: set {b} ({sets.describe(b)}): {error}") from None


def _signs(entries: SceneEntries, name: str, columns: list[int], sets: ParameterSets
           ) -> tuple[np.ndarray, np.ndarray]:
    """Values (P, k) of the chosen entries of ``name`` and whether each one's sign (or its
    being zero) is certain: float64 first, double-double for the sets float64 leaves in
    doubt (an entry within 10⁻¹² of its size from 0)."""
    value = entries.floats(name, sets.rows)[:, columns]
    with np.errstate(invalid="ignore"):
        scale = np.max(np.abs(value), axis=1, keepdims=True)
        certain = np.abs(value) > 1e-12 * scale
    doubt = np.flatnonzero(~np.all(certain, axis=1))
    if doubt.size and entries.compiles(name) and sets.names:
        subset = sets.take(doubt)
        hi, lo, err = entries.evaluate(name, subset.parts(), len(subset))
        exact = hi[:, columns] + lo[:, columns]
        zero = (hi[:, columns] == 0) & (err[:, columns] == 0)
        value[doubt] = hi[:, columns]
        certain[doubt] = zero | (np.abs(exact) > 2 * err[:, columns])
    return value, certain


def validate_sets(scene: Scene, entries: SceneEntries, sets: ParameterSets) -> None:
    """Raise SceneError for the first set ``scene.subs`` would refuse.

    Examples
    --------
    A mass declared real and given a negative value is refused, as ``Scene.subs`` does:

    >>> from laplace_springs.sweeps.entries import scene_entries_of
    >>> from laplace_springs.sweeps.parameters import parameter_sets
    >>> scene = Scene.from_matrices(M=[["m"]], K=[[1]], x0=[1], v0=[0], parameters={"m": "real"})
    >>> sets = parameter_sets(("m",), scene.parameters, {"m": [1.0, -1.0]})
    >>> validate_sets(scene, scene_entries_of(scene), sets)
    Traceback (most recent call last):
    ...
    laplace_springs.model.errors.SceneError: sweep: set 1 (m = -1.0): mass M[0,0] must be positive, got -1.0; 0 is allowed for a massless node
    """
    uncertain = np.zeros(len(sets), dtype=bool)
    symbolic = [k for k, (_, _, value) in enumerate(entries.components) if value.free_symbols]
    if symbolic:
        values, certain = _signs(entries, "components", symbolic, sets)
        negative = (values < 0) & certain
        uncertain |= ~np.all(certain, axis=1)
        if negative.any():
            b, k = (int(v) for v in np.argwhere(negative)[0])
            kind, label, _ = entries.components[symbolic[k]]
            raise SceneError(f"sweep: set {b} ({sets.describe(b)}): subs: {kind} {label!r} "
                             f"becomes {float(values[b, k])!r}")
    pattern = entries.pattern["M"]
    diagonal = all(i == j for i, j in pattern)
    masses = [k for k, (i, j) in enumerate(pattern)
              if i == j and entries.expressions["M"][k].free_symbols]
    if masses:
        values, certain = _signs(entries, "M", masses, sets)
        negative = (values < 0) & certain
        if negative.any():
            b, k = (int(v) for v in np.argwhere(negative)[0])
            i = pattern[masses[k]][0]
            raise SceneError(f"sweep: set {b} ({sets.describe(b)}): mass M[{i},{i}] must be "
                             f"positive, got {float(values[b, k])!r}; 0 is allowed for a "
                             "massless node")
        uncertain |= ~np.all(certain, axis=1)
    if not diagonal and any(e.free_symbols for e in entries.expressions["M"]):
        uncertain |= ~_clearly_positive_definite(entries, sets)
    for index in np.flatnonzero(uncertain).tolist():
        exact_check(scene, sets, index)


def _clearly_positive_definite(entries: SceneEntries, sets: ParameterSets) -> np.ndarray:
    """(P,) whether float64 eigenvalues prove each set's M positive definite (a margin of
    1e-10·‖M‖_F over the eigensolver's and the entries' rounding, as Scene does)."""
    n = entries.n
    values = entries.floats("M", sets.rows)
    dense = np.zeros((len(sets), n, n))
    for k, (i, j) in enumerate(entries.pattern["M"]):
        dense[:, i, j] = values[:, k]
    finite = np.all(np.isfinite(values), axis=1)
    dense[~finite] = np.eye(n)
    size = np.linalg.norm(dense, axis=(1, 2))
    smallest = np.linalg.eigvalsh(dense)[:, 0]
    return finite & (smallest > 1e-10 * size)
