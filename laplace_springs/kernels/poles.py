"""The package's one rule for grouping close poles.

Two poles (or frequencies) are *linked* when they differ by at most ``gap``; a *cluster* is
a connected component of the links (single linkage), so a run of poles each within
``gap`` of the next is one cluster however long it is. Every engine that treats close
poles together uses this rule through these functions, each with the gap it can afford
(in :mod:`laplace_springs.limits`):

* ``Limits.close_poles`` · max|pole| for the eigen-decompositions (the general modal
  engine's blocks, the refined engine's Rayleigh–Ritz clusters): closer eigenvectors are
  not determined in float64, their invariant subspace is;
* ``Limits.cluster_gap`` · max|root| for the sweep kernels, whose roots come from
  companion matrices in float64 for every set at once, so a double root is only known to
  about √ε and its neighbours are summed by divided differences.

The pole-sum evaluation (:mod:`laplace_springs.numeric.pole_sum`) asks a different
question, which poles cancel at a time t (links with t·|λ_i − λ_j| ≤ Limits.block_theta,
merged hierarchically by cost), and keeps its own tree for it.

Examples
--------
>>> import numpy as np
>>> [c.tolist() for c in clusters(np.array([3.0, 1.0 + 2e-9, 1.0, 2.0, 1.0 + 1e-9]), 1e-8)]
[[2, 4, 1]]
>>> cluster_labels(np.array([[0.0, 5.0, 0.1j, 5.05]]), np.array([0.2])).tolist()
[[0, 1, 0, 1]]
"""

from __future__ import annotations

import numpy as np

__all__ = ["clusters", "cluster_labels"]


def clusters(values: np.ndarray, gap: float) -> list[np.ndarray]:
    """The clusters of two or more of ``values`` (real or complex, 1-D), as index arrays.

    Real values are sorted and cut where neighbours differ by more than ``gap`` (single
    linkage on a line): each cluster lists its indices by increasing value, clusters in
    increasing order of their values. Complex ones are linked by a sweep over the real
    parts and union-find: indices in increasing order, clusters by their smallest index.
    """
    values = np.asarray(values)
    if values.size < 2:
        return []
    if np.isrealobj(values):
        order = np.argsort(values, kind="stable")
        runs = np.split(order, np.flatnonzero(np.diff(values[order]) > gap) + 1)
        return [run for run in runs if run.size > 1]
    return _complex_clusters(values, gap)


def _complex_clusters(values: np.ndarray, gap: float) -> list[np.ndarray]:
    """Single linkage in the plane: the values hashed into square cells of side ``gap``,
    each compared with those of its own and the eight neighbouring cells, pairs within
    ``gap`` joined by union-find (about N operations for the thousands of eigenvalues of a
    modal scene, whatever their layout: undamped poles all share one real part)."""
    parent = list(range(values.size))

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    if not gap > 0:   # links only between equal values
        gap = 0.0
    cells: dict[tuple[int, int], list[int]] = {}
    keys = (np.floor(values.real / gap), np.floor(values.imag / gap)) if gap else \
        (values.real, values.imag)
    for i, key in enumerate(zip(keys[0].tolist(), keys[1].tolist())):
        cells.setdefault(key, []).append(i)
    steps = (-1, 0, 1) if gap else (0,)
    for (x, y), members in cells.items():
        for dx in steps:
            for dy in steps:
                for j in cells.get((x + dx, y + dy), ()):
                    for i in members:
                        if i < j and abs(values[j] - values[i]) <= gap:
                            parent[root(j)] = root(i)
    groups: dict[int, list[int]] = {}
    for i in range(values.size):
        groups.setdefault(root(i), []).append(i)
    return [np.array(g) for g in groups.values() if len(g) > 1]


def cluster_labels(values: np.ndarray, gap: np.ndarray) -> np.ndarray:
    """Cluster labels of a batch ``values`` (P, N): each entry's label is the smallest index
    of its cluster in its row; ``gap`` (P,) is each row's link length.

    The links' transitive closure is taken by repeated boolean squaring (⌈log₂ N⌉ products
    of N x N matrices per row): meant for the small N of a sweep's scenes.
    """
    values = np.asarray(values)
    P, N = values.shape
    close = np.abs(values[:, :, None] - values[:, None, :]) <= np.asarray(gap)[:, None, None]
    reach = close | np.eye(N, dtype=bool)[None]
    for _ in range(max(1, int(np.ceil(np.log2(max(N, 2)))))):
        step = reach.astype(np.int32)   # int8 sums would wrap past 127 links
        reach = reach | (np.matmul(step, step) > 0)
    return np.argmax(reach, axis=2)
