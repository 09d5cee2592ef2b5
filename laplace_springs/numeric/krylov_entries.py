"""A scene's exact entries as arrays for the krylov engine, the checks that its energy
never grows, and the bound ν of its first-order operator in the energy norm.

Each entry is read once into arrays (row, column, float64 value, and numerator and
denominator as float64 integers, exact below 2^50), cached with the scene. The checks are
exact: on integers after one common denominator (when that stays below 2^53), else in
rationals.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction
from itertools import chain
from operator import attrgetter
from typing import Any

import numpy as np
from flint import fmpq

from ..kernels.dd import from_exact, two_prod
from ..model.errors import FloatRangeError
from ..model.scene import Scene
from .first_order import rational_entries, scene_cache

__all__ = ["Entries", "entries_of", "exact_quotients", "scene_refusal", "spectral_bound",
           "perron_bound", "MARGIN", "RANGE"]

#: Relative margin on float64 sums of non-negative terms (≥ n·u for n ≤ 10⁶ terms).
MARGIN = 1 + 1e-9
#: Integers below this are exact in float64, and so are their sums and products below it.
_EXACT = 2.0**53
#: Numerators and denominators below this are recovered exactly from the value.
_SMALL = 2.0**50
#: Largest |entry| of M, C, K (and 1/mass) the engine holds: the energy-coordinate entries
#: K_ij/√(m_i m_j) stay below 1e300 and every product the bound forms stays finite.
RANGE = 1e150
#: The smallest ν used: where the scene's own is smaller, its entries in energy
#: coordinates may have underflowed (each below 1e-307), which this floor covers.
_NU_FLOOR = 1e-100


@dataclass(frozen=True, eq=False)
class Entries:
    """The nonzero entries of one exact matrix: value = num/den.

    ``value`` is float64 (correctly rounded by python-flint; within 2u in any case),
    ``num`` and ``den`` float64 integers, exact where ``exact`` (both below 2^50:
    num = round(value·den), off from value·den by less than 3u·|num| < 1/2).
    ``fractions`` gives an entry exactly (the rare inexact ones).
    """

    rows: np.ndarray
    cols: np.ndarray
    value: np.ndarray
    num: np.ndarray
    den: np.ndarray
    exact: np.ndarray
    items: list[Any]

    def fraction(self, index: int) -> Fraction:
        item = self.items[index]
        return Fraction(int(item.p), int(item.q))

    @property
    def all_exact(self) -> bool:
        return bool(self.exact.all())


def _read(exact: dict[tuple[int, int], Any], integers: bool) -> Entries:
    count = len(exact)
    keys = np.fromiter(chain.from_iterable(exact), dtype=np.intp, count=2 * count)
    items = list(exact.values())
    value = np.fromiter(map(float, items), dtype=float, count=count)
    den = np.ones(count) if integers else \
        np.fromiter(map(float, map(attrgetter("q"), items)), dtype=float, count=count)
    with np.errstate(invalid="ignore", over="ignore"):
        num = np.rint(value * den)
    ok = (den < _SMALL) & (np.abs(num) < _SMALL)
    return Entries(keys[0::2].copy(), keys[1::2].copy(), value, num, den, ok, items)


def entries_of(scene: Scene, name: str) -> Entries | None:
    """The entries of ``scene.M`` (``"M"``, ``"C"``, ``"K"``, ``"x0"``, ``"v0"``) as arrays,
    or None when one is not rational (cached with the scene).

    >>> e = entries_of(Scene.from_matrices(M=[[2]], K=[["8/3"]], x0=[1], v0=[0]), "K")
    >>> e.value.tolist(), e.num.tolist(), e.den.tolist()
    ([2.6666666666666665], [8.0], [3.0])
    """
    table = scene_cache(scene)
    key = "krylov entries " + name
    if key not in table:
        exact = rational_entries(scene, name)
        rep = getattr(getattr(scene, name), "_rep", None)
        integers = str(getattr(rep, "domain", "")) == "ZZ"   # SymPy's integer domain
        table[key] = None if exact is None else _read(exact, integers)
    found: Entries | None = table[key]
    return found


def exact_quotients(num: np.ndarray, den: np.ndarray, exact: np.ndarray,
                    fraction: Callable[[int], Fraction] | None) -> tuple[np.ndarray, np.ndarray]:
    """num/den as double-doubles hi + lo, |hi + lo − num/den| ≤ 2^-104·|hi|.

    Where ``exact`` (num and den float64 integers below 2^53, den > 0): hi = fl(num/den)
    (correctly rounded), and the remainder num − hi·den is formed exactly (two-product,
    then a subtraction exact by Sterbenz's lemma, the last one off by u of the remainder)
    and divided by den. Elsewhere the entry comes from ``fraction(index)`` (exact).

    >>> hi, lo = exact_quotients(np.array([1.0]), np.array([3.0]), np.array([True]), None)
    >>> Fraction(float(hi[0])) + Fraction(float(lo[0])) - Fraction(1, 3) < Fraction(1, 10**31)
    True
    """
    safe = np.where(exact, den, 1.0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        hi = np.where(exact, num / safe, 0.0)
        p, e = two_prod(hi, safe)
        lo = np.where(exact, ((num - p) - e) / safe, 0.0)
    missing = np.flatnonzero(~exact)
    if missing.size:
        assert fraction is not None
        for index in missing:
            hi[index], lo[index] = from_exact(fraction(int(index)))
    if not (np.all(np.isfinite(hi)) and np.all(np.isfinite(lo))):
        raise FloatRangeError("an entry of the first-order system is beyond the float64 range")
    return hi, lo


# ----------------------------------------------------------------------------- the checks


def _integers(entries: Entries) -> np.ndarray | None:
    """The entries times one common denominator, as exact float64 integers (None when the
    denominators' lcm or a scaled entry reaches 2^51)."""
    if not entries.all_exact:
        return None
    scale = 1
    for den in np.unique(entries.den):
        scale = math.lcm(scale, int(den))
        if scale >= _EXACT:
            return None
    scaled = entries.num * (float(scale) / entries.den)   # scale/den is an exact integer
    if np.max(np.abs(scaled), initial=0.0) >= _EXACT / 4:
        return None
    return scaled


def _symmetric(entries: Entries, n: int, scaled: np.ndarray | None,
               exact: dict[tuple[int, int], Any]) -> bool:
    if scaled is None:
        return all(exact.get((j, i)) == value for (i, j), value in exact.items())
    forward = np.argsort(entries.rows * n + entries.cols)
    backward = np.argsort(entries.cols * n + entries.rows)
    return bool(np.array_equal(entries.rows[forward], entries.cols[backward])
                and np.array_equal(entries.cols[forward], entries.rows[backward])
                and np.array_equal(scaled[forward], scaled[backward]))


def _dominant_integers(scaled: np.ndarray, entries: Entries, n: int, symmetric: bool) -> bool | None:
    """Diagonal dominance of the symmetric part (A + Aᵀ)/2 on exact integers (None when a
    row sum could reach 2^53): 2·A_ii ≥ Σ_{j≠i} |A_ij + A_ji|."""
    diagonal = entries.rows == entries.cols
    if np.max(np.abs(scaled), initial=0.0) * 2 * (n + 1) >= _EXACT / 2:
        return None
    twice = np.bincount(entries.rows[diagonal], 2 * scaled[diagonal], minlength=n)
    off = ~diagonal
    rows, cols, values = entries.rows[off], entries.cols[off], scaled[off]
    if symmetric:   # |A_ij + A_ji| = 2|A_ij|, counted once in row i
        return bool(np.all(twice >= np.bincount(rows, 2 * np.abs(values), minlength=n)))
    key = np.minimum(rows, cols) * n + np.maximum(rows, cols)
    order = np.argsort(key, kind="stable")
    key, values = key[order], values[order]
    unique, start = np.unique(key, return_index=True)
    size = np.abs(np.add.reduceat(values, start)) if values.size else values
    return bool(np.all(twice >= np.bincount(unique // n, size, minlength=n)
                       + np.bincount(unique % n, size, minlength=n)))


def _dominant_exact(entries: dict[tuple[int, int], Any], n: int) -> bool:
    """Symmetric part diagonally dominant with a non-negative diagonal, in rationals."""
    sym: dict[tuple[int, int], Any] = {}
    for (i, j), value in entries.items():
        sym[i, j] = sym.get((i, j), 0) + value / 2
        sym[j, i] = sym.get((j, i), 0) + value / 2
    off = [fmpq(0)] * n
    diag = [fmpq(0)] * n
    for (i, j), value in sym.items():
        if i == j:
            diag[i] = value
        else:
            off[i] += abs(value)
    return all(d >= o for d, o in zip(diag, off))


def _psd_by_dominance(exact: dict[tuple[int, int], Any], entries: Entries, n: int,
                      must_be_symmetric: bool) -> tuple[bool, bool]:
    """(symmetric, symmetric part diagonally dominant with a non-negative diagonal)."""
    scaled = _integers(entries)
    symmetric = _symmetric(entries, n, scaled, exact)
    if must_be_symmetric and not symmetric:
        return False, False
    decided = None if scaled is None else _dominant_integers(scaled, entries, n, symmetric)
    return symmetric, _dominant_exact(exact, n) if decided is None else decided


def scene_refusal(scene: Scene) -> str | None:
    """Why the krylov engine cannot bound this scene's motion, or None (cached with the
    scene).

    It needs rational entries, no forcing, a diagonal positive M, a symmetric K, and K
    and C + Cᵀ diagonally dominant with a non-negative diagonal (K ⪰ 0 and C + Cᵀ ⪰ 0,
    proved exactly): the energy then never grows.

    >>> scene_refusal(Scene.from_matrices(M=[[1]], C=[[-1]], K=[[1]], x0=[1], v0=[0]))
    'C + Cᵀ is not diagonally dominant with a non-negative diagonal (C + Cᵀ ⪰ 0 is not proved)'
    """
    table = scene_cache(scene)
    if "krylov refusal" not in table:
        table["krylov refusal"] = _refusal(scene)
    found: str | None = table["krylov refusal"]
    return found


def _refusal(scene: Scene) -> str | None:
    if scene.is_forced or getattr(scene, "sampled", None) is not None:
        return "the scene is forced"
    exact = {name: rational_entries(scene, name) for name in ("M", "C", "K", "x0", "v0")}
    if any(entries is None for entries in exact.values()):
        return "some entry is not a rational number"
    n = scene.n
    M = entries_of(scene, "M")
    assert M is not None
    if M.rows.size < n or np.any(M.rows != M.cols) or not np.all(M.value > 0):
        return "M is not diagonal with positive masses"
    K, C = entries_of(scene, "K"), entries_of(scene, "C")
    assert K is not None and C is not None and exact["K"] is not None and exact["C"] is not None
    symmetric, dominant = _psd_by_dominance(exact["K"], K, n, must_be_symmetric=True)
    if not symmetric:
        return "K is not symmetric"
    if not dominant:
        return "K is not diagonally dominant with a non-negative diagonal (K ⪰ 0 is not proved)"
    if not _psd_by_dominance(exact["C"], C, n, must_be_symmetric=False)[1]:
        return ("C + Cᵀ is not diagonally dominant with a non-negative diagonal "
                "(C + Cᵀ ⪰ 0 is not proved)")
    largest = max(float(np.max(np.abs(K.value), initial=0.0)),
                  float(np.max(np.abs(C.value), initial=0.0)), float(np.max(M.value, initial=1.0)))
    if largest > RANGE or float(np.min(M.value, initial=1.0)) < 1 / RANGE:
        return (f"an entry of M, C or K is beyond what the engine holds in float64 "
                f"(|entries| and masses within 1e-150..1e150; {largest:.3g})"
                if largest > RANGE else "a mass is below 1e-150 (beyond what the engine holds)")
    x0, v0 = entries_of(scene, "x0"), entries_of(scene, "v0")
    assert x0 is not None and v0 is not None
    x, v = np.zeros(n), np.zeros(n)
    x[x0.rows], v[v0.rows] = x0.value, v0.value
    with np.errstate(over="ignore", invalid="ignore"):
        energy = float(np.sum(M.value * v[M.rows] ** 2)) + float(np.sum(np.abs(x[K.rows] * K.value * x[K.cols])))
    if max(float(np.max(np.abs(x), initial=0.0)), float(np.max(np.abs(v), initial=0.0))) > RANGE \
            or not energy < 1e300:
        return "the initial data are beyond what the engine holds in float64 (energy above 1e150)"
    nu = spectral_bound(scene)
    if not math.isfinite(nu) or nu > RANGE:
        return f"the bound ν on the first-order operator is beyond {RANGE:g}"
    return None


# ----------------------------------------------------------------------------- the bound ν


def perron_bound(apply: Callable[[np.ndarray], np.ndarray], n: int, iterations: int = 40) -> float:
    """An upper bound on the spectral radius of a nonnegative n x n matrix G given as
    ``apply(d) = G·d`` (float64 products whose entries are off by at most 1e-10 of
    themselves): the Collatz–Wielandt bound ρ(G) ≤ max_i (G d)_i/d_i, valid for any d > 0,
    with d from a few power steps.

    >>> perron_bound(lambda d: np.array([[2.0, 1.0], [1.0, 2.0]]) @ d, 2) >= 3.0
    True
    """
    if n == 0:
        return 0.0
    d = np.ones(n)
    for _ in range(iterations):
        g = apply(d)
        top = float(g.max(initial=0.0))
        if top <= 0:
            return 0.0
        d = g / top + 1e-12            # stays positive: a bound for any d > 0
    return float(np.max(apply(d) / d)) * (1 + 1e-9) * MARGIN


def spectral_bound(scene: Scene) -> float:
    """ν ≥ N(Az)/N(z) in the energy seminorm N(z)² = vᵀMv + xᵀKx, for a scene
    :func:`scene_refusal` accepts (cached with the scene; a few dozen sparse products).

    In energy coordinates A is [[0, P], [−Pᵀ, −D]] with ‖P‖₂² = λ_max(M^{-1/2}KM^{-1/2}) ≤
    ρ(|M^{-1/2}KM^{-1/2}|) and ‖D‖₂² ≤ ρ(|D|ᵀ|D|), D = M^{-1/2}CM^{-1/2}: each by the
    Collatz–Wielandt bound, or by Gershgorin's row sums where those are smaller. With
    p ≥ ‖P‖₂ and d ≥ ‖D‖₂, ‖A(a, b)‖² = ‖Pb‖² + ‖Pᵀa + Db‖² ≤ p²b² + (pa + db)² for
    a² + b² = 1 (a, b the parts' norms), whose largest value is that of the 2 x 2 form
    [[p², pd], [pd, p² + d²]]: ν = √(p² + d²/4) + d/2 (≤ p + d). It is at
    least 1e-100 (the entries of a scene slower than that may have underflowed) and may be
    inf for scenes :func:`scene_refusal` declines.

    One mass (p = 2, d = 1/2: ν = √(4 + 1/16) + 1/4, its exact norm here):

    >>> spectral_bound(Scene.from_matrices(M=[[2]], C=[[1]], K=[[8]], x0=[1], v0=[0]))
    2.26556...
    """
    table = scene_cache(scene)
    if "krylov nu" not in table:
        table["krylov nu"] = max(_spectral_bound(scene), _NU_FLOOR)
    nu: float = table["krylov nu"]
    return nu


def _spectral_bound(scene: Scene) -> float:
    """ν without its floor (inf where a sum overflows); ‖D‖₂ from D/max|D| so that DᵀD
    stays finite."""
    import scipy.sparse as sps

    n = scene.n
    M, K, C = (entries_of(scene, name) for name in ("M", "K", "C"))
    assert M is not None and K is not None and C is not None
    root = np.ones(n)
    root[M.rows] = np.sqrt(M.value)
    with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
        s_values = np.abs(K.value) / root[K.rows] / root[K.cols]
        d_values = np.abs(C.value) / root[C.rows] / root[C.cols]
        if not (np.all(np.isfinite(s_values)) and np.all(np.isfinite(d_values))):
            return math.inf
        S = sps.csr_matrix((s_values, (K.rows, K.cols)), shape=(n, n))
        gersh = float(np.max(np.asarray(S.sum(axis=1)), initial=0.0)) * MARGIN
        if not math.isfinite(gersh):
            return math.inf
        stiff = min(gersh, perron_bound(lambda d: S @ d, n))
        top = float(np.max(d_values, initial=0.0))
        damp = 0.0
        if top > 0:
            D = sps.csr_matrix((d_values / top, (C.rows, C.cols)), shape=(n, n))
            Dt = D.T.tocsr()
            d_row = float(np.max(np.asarray(D.sum(axis=1)), initial=0.0))
            d_col = float(np.max(np.asarray(D.sum(axis=0)), initial=0.0))
            # d_values/top is off by u of itself: within the margins
            damp = top * math.sqrt(min(d_row * d_col * MARGIN,
                                       perron_bound(lambda d: Dt @ (D @ d), n))) * MARGIN
        # ‖[[0, P], [−Pᵀ, −D]]‖₂ ≤ √(p² + d²/4) + d/2 (p ≥ ‖P‖, d ≥ ‖D‖; module notes)
        return (math.sqrt(stiff + damp * damp / 4) * MARGIN + damp / 2) * MARGIN
