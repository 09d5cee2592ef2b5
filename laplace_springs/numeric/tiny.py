"""The tiny engine: scenes of 1 to Limits.tiny_max_coordinates coordinates in float64,
with an error bound, at the cost of a few dozen NumPy calls.

The engine reads the scene's exact rational entries (python-flint, from the matrices'
domain representation: no SymPy objects), forms what it needs exactly, rounds once, and
evaluates in float64. It implements the planner's engine interface:
:func:`tiny_refusal`, :func:`tiny_cost`, :func:`tiny_motion` and :class:`TinyMotion`
(``evaluate(times, order) -> (values, bounds)``, ``poles()``).

One coordinate
--------------
m x'' + c x' + k x = 0 has x = e^{αt}[p·C(t) + w·S(t)] with α = −c/2m,
D = α² − k/m = (c² − 4mk)/4m², p = x(0), w = x'(0) − αp (all formed exactly, rounded
once), C = cosh(√D t) and S = sinh(√D t)/√D. As functions of D they are entire, so
nothing cancels at critical damping (D = 0: C = 1, S = t) or near it (at |ζ − 1| = 1e-14
the computed D is the exact one rounded once, where the residue form loses 1e-10 to the
cancellation of two huge residues):

* D < 0: C = cos ωt, S = sin(ωt)/ω, with ω = √−D in double-double from the exact D and
  the phase ωt in double-double (no drift at ωt = 10⁶);
* D = 0: C = 1, S = t;
* D > 0 and √D·t < 1/2: cosh and sinh of √D·t;
* D > 0 and √D·t ≥ 1/2: e^{αt}C = (e^{λ₊t} + e^{λ₋t})/2 and e^{αt}S = (e^{λ₊t} −
  e^{λ₋t})/2√D, with the small root from the large one, λ_small = (k/m)/λ_large (the
  stable quadratic formula: at c = 1e6, k = 1 the slow root −1e-6 to 1e-16 where the
  textbook formula loses 7.6e-6), so no e^{αt}·cosh(√D t) overflows.

Derivatives are the same functions with the initial data (x', x'') and (x'', x''')
formed exactly.

Two to four coordinates
-----------------------
A float64 eigen-decomposition of the 2n x 2n first-order matrix, with 2 x 2 blocks in
the same entire functions for defective and nearly defective pairs, and a bound from its
residual formed in extended precision: see :mod:`laplace_springs.numeric.tiny_blocks`.

Precision and conditioning (one coordinate)
-------------------------------------------
Every quantity is the exact one rounded once, so the bound is the first-order
propagation of those roundings through the closed form: relative errors of e^{λt} of
|λ|·(c·u·t + |lo|) (c from the roundings of λ) plus the libm's 2u, of the phase
8u²·ωt, of the cancellation-free differences, applied to the envelopes |p|·|C| and
|w|·|S|. Against 45-digit references the bound exceeds the error by 2 to 30.

No SymPy on this path: reading the scene costs microseconds; the exact data (Δ,
certified roots) are built by other engines only when the planner escalates.

References: Kahan, "On the cost of floating-point computation without extra-precise
arithmetic" (2004), the stable quadratic formula; Higham, *Functions of Matrices* (SIAM
2008), ch. 10.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
from flint import fmpq, fmpq_mat

from ..kernels.dd import U, two_prod
from ..kernels.peaks import peak
from ..limits import limits
from ..model.errors import SceneError
from ..model.scene import Scene
from .first_order import rational_matrices, scene_cache
from .times import Times, as_times  # noqa: F401  (doctests)
from .tiny_blocks import BlockMotion
from .tiny_modes import classical_modes

__all__ = ["TinyMotion", "TinyData", "tiny_refusal", "tiny_cost", "tiny_motion", "tiny_data"]

#: Relative error a bound may neglect (second-order terms): bounds are multiplied by this.
_SAFETY = 1.02
#: Cost model (seconds): the fastest of 1,500 first calls on the development machine (2
#: cores, OpenBLAS with one thread, both cores busy with other work): reading the scene
#: 12-27 µs; one coordinate 9 µs to build and 30 ns per time (100 times 35 µs, 10,000
#: times 0.35 ms); two to four coordinates 40 µs per coordinate to build (eig, inverse,
#: the residual in extended precision; the seed's pair 88 µs, an SVD more per 2 x 2
#: block) and 20·n² ns per time (pair 51 ns, four coordinates 580 ns at 10,000 times).
#: Used only to rank engines.
_COST_READ = 1.5e-5
_COST_SCALAR = (1.0e-5, 3.0e-8)
_COST_BLOCK_BUILD = 4.0e-5
_COST_BLOCK_TIME = 2.0e-8

Entries = dict[tuple[int, int], Any]


# ----------------------------------------------------------------------------- exact data


@dataclass(frozen=True, eq=False)
class TinyData:
    """A tiny scene's exact data (python-flint fmpq) and its float64 initial state.

    Attributes
    ----------
    n : int
        Coordinates.
    M, C, K : dict
        The nonzero entries {(i, j): fmpq}.
    x0_exact, v0_exact : tuple of flint.fmpq
        The exact initial data.
    x0, v0 : numpy.ndarray
        The same rounded to float64 (read by the contract's scale S₀).
    """

    n: int
    M: Entries
    C: Entries
    K: Entries
    x0_exact: tuple[Any, ...]
    v0_exact: tuple[Any, ...]
    x0: np.ndarray
    v0: np.ndarray

    def initial(self, order: int) -> np.ndarray:
        """x^(order)(0) exactly, rounded to float64: x0, v0, or −M⁻¹(C v0 + K x0)."""
        if order == 0:
            return self.x0
        if order == 1:
            return self.v0
        n = self.n
        force = [sum((v * self.v0_exact[j] for (i, j), v in self.C.items() if i == row),
                     fmpq(0))
                 + sum((v * self.x0_exact[j] for (i, j), v in self.K.items() if i == row),
                       fmpq(0)) for row in range(n)]
        solved = _matrix(self.M, n).solve(fmpq_mat(n, 1, force))
        return np.array([-float(solved[i, 0]) for i in range(n)])

    def normalized(self) -> tuple[Entries, Entries]:
        """The nonzero entries of M⁻¹K and M⁻¹C, exactly."""
        return self._normalized

    @cached_property
    def normalized_floats(self) -> tuple[list[float], list[float]]:
        """The values of :meth:`normalized`'s entries rounded to float64 (in their order;
        inf beyond float64's range)."""
        A, B = self._normalized
        return [_as_float(v) for v in A.values()], [_as_float(v) for v in B.values()]

    @cached_property
    def _normalized(self) -> tuple[Entries, Entries]:
        n = self.n
        if all(i == j for i, j in self.M):
            mass = {i: value for (i, _), value in self.M.items()}
            return ({(i, j): v / mass[i] for (i, j), v in self.K.items()},
                    {(i, j): v / mass[i] for (i, j), v in self.C.items()})
        M = _matrix(self.M, n)
        out = []
        for entries in (self.K, self.C):
            solved = M.solve(_matrix(entries, n))
            out.append({(i, j): solved[i, j] for i in range(n) for j in range(n)
                        if solved[i, j] != 0})
        return out[0], out[1]


def _matrix(entries: Entries, n: int) -> Any:
    matrix = fmpq_mat(n, n)
    for (i, j), value in entries.items():
        matrix[i, j] = value
    return matrix


def _read(scene: Scene) -> TinyData | str:
    """The exact data, or why the tiny engine cannot take the scene (a sentence)."""
    n = scene.n
    most = limits().tiny_max_coordinates
    if n > most:
        return f"coordinates {n:,} > Limits.tiny_max_coordinates = {most:,}"
    if scene.sampled is not None or (scene.forcing is not None and scene.is_forced):
        return "the scene is forced"
    read = rational_matrices(scene, ("M", "C", "K", "x0", "v0"))
    found = [entries for entries in read if entries is not None]
    if len(found) < len(read):
        return "needs rational entries (numbers, no symbols)"
    M, C, K, x0, v0 = found
    diagonal = all(i == j for i, j in M)
    if (len(M) < n if diagonal else _matrix(M, n).det() == 0):
        return "M is singular (massless nodes): the first-order form needs a reduction"
    zero = fmpq(0)
    x0_exact = tuple(x0.get((i, 0), zero) for i in range(n))
    v0_exact = tuple(v0.get((i, 0), zero) for i in range(n))
    start = np.array([float(v) for v in x0_exact + v0_exact])
    data = TinyData(n, M, C, K, x0_exact, v0_exact, start[:n], start[n:])
    return _range_refusal(data) or data


def _range_refusal(data: TinyData) -> str | None:
    """Why the scene's numbers are beyond the engine's float64 closed forms, or None: every
    nonzero entry of M⁻¹K, M⁻¹C, x0 and v0 within Limits.tiny_max_magnitude^{±1}."""
    most = float(limits().tiny_max_magnitude)
    # a float strictly inside (1/most, most) by a relative 2^-40 is inside exactly; the
    # exact comparison is made only for the rare entries near the limits
    inner_low, inner_high = (1 + 2.0**-40) / most, most * (1 - 2.0**-40)
    A, B = data.normalized()
    A_sizes, B_sizes = data.normalized_floats
    named = [("M⁻¹K", A.values(), A_sizes), ("M⁻¹C", B.values(), B_sizes),
             ("x0", data.x0_exact, data.x0.tolist()), ("v0", data.v0_exact, data.v0.tolist())]
    for name, values, sizes in named:
        for value, size in zip(values, sizes):
            if not inner_low < abs(size) < inner_high and value != 0 \
                    and not _within(value, most):
                return (f"an entry of {name} is about {_magnitude(value)}, beyond "
                        f"Limits.tiny_max_magnitude = {most:g} (or its reciprocal): the "
                        "float64 closed forms would overflow")
    return None


def _within(value: Any, most: float) -> bool:
    """1/most ≤ |value| ≤ most, exactly."""
    high = fmpq(*most.as_integer_ratio())
    return bool(1 / high <= abs(value) <= high)


def _as_float(value: Any) -> float:
    """value in float64 (±inf beyond its range)."""
    try:
        return float(value)
    except OverflowError:
        return math.inf if value > 0 else -math.inf


def _magnitude(value: Any) -> str:
    """|value| as a power of ten (it need not be a float64 number)."""
    p, q = abs(int(value.p)), int(value.q)
    return f"1e{len(str(p)) - len(str(q)):+d}"


def tiny_data(scene: Scene) -> TinyData | str:
    """The scene's exact data for the tiny engine (read once per scene), or why it cannot
    take the scene.

    Examples
    --------
    >>> data = tiny_data(Scene.from_matrices(M=[[2]], C=[["1/10"]], K=[[8]], x0=[1], v0=[0]))
    >>> data.n, data.C[0, 0], data.x0
    (1, 1/10, array([1.]))
    >>> tiny_data(Scene.from_matrices(M=[[1]], K=[["k"]], x0=[1], v0=[0], parameters=["k"]))
    'needs rational entries (numbers, no symbols)'
    """
    table = scene_cache(scene)
    found: TinyData | str | None = table.get("tiny")
    if found is None:
        found = table["tiny"] = _read(scene)
    return found


# ----------------------------------------------------------------------------- interface


def tiny_refusal(scene: Scene, *, t_max: float = 100.0, count: int = 100,
                 order: int = 0) -> str | None:
    """None when the tiny engine serves this request, else why not (one sentence).

    Reads the scene's exact entries (microseconds, kept with the scene); decomposes
    nothing. The engine serves every time of a scene it takes; a time whose bound misses
    the target goes to the planner's next engine.

    Examples
    --------
    >>> tiny_refusal(Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0])) is None
    True
    >>> eye = [[int(i == j) for j in range(5)] for i in range(5)]
    >>> tiny_refusal(Scene.from_matrices(M=eye, K=eye, x0=[1, 0, 0, 0, 0], v0=[0] * 5))
    'coordinates 5 > Limits.tiny_max_coordinates = 4'
    """
    if order not in (0, 1, 2):
        return f"derivative order {order} (the engine gives 0, 1 and 2)"
    if not math.isfinite(t_max):
        return f"the last time {t_max!r} is not finite"
    data = tiny_data(scene)
    return data if isinstance(data, str) else None


def tiny_cost(scene: Scene, *, t_max: float = 100.0, count: int = 100, order: int = 0) -> float:
    """Estimated seconds of building the tiny engine and evaluating ``count`` times (the
    model of the module's cost constants: reading, one decomposition, a cost per time and
    coordinate). Cheap: nothing is read or decomposed.

    >>> scene = Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[1], v0=[0])
    >>> tiny_cost(scene, count=100) < 1e-4
    True
    """
    n = scene.n
    build, per_time = _COST_SCALAR if n == 1 else (_COST_BLOCK_BUILD * n, _COST_BLOCK_TIME * n * n)
    return _COST_READ + build + count * per_time


def tiny_motion(scene: Scene) -> TinyMotion:
    """The tiny engine's motion of ``scene`` (decomposed on first use).

    Raises
    ------
    SceneError
        When :func:`tiny_refusal` refuses the scene (call it first).

    Examples
    --------
    The seed's Example 2 pair (two masses hanging from a ceiling, air resistance):

    >>> scene = Scene.from_matrices(M=[[1, 0], [0, "1/2"]], C=[["1/5", 0], [0, "1/10"]],
    ...                             K=[[3, -1], [-1, 1]], x0=[1, 0], v0=[0, 0])
    >>> values, bounds = tiny_motion(scene).evaluate(as_times([0.0, 1.0]), 0)
    >>> values.round(6)
    array([[ 1.      , -0.032509],
           [ 0.      ,  0.601481]])
    >>> bool(bounds[:, 0].max() == 2.0**-53)   # t = 0: the initial data, rounded once
    True
    >>> bool(bounds.max() < 1e-14)
    True
    """
    data = tiny_data(scene)
    if isinstance(data, str):
        raise SceneError(f"the tiny engine cannot take this scene: {data}")
    return TinyMotion(data)


class TinyMotion:
    """x(t) of a tiny scene (see the module notes); built by :func:`tiny_motion`.

    Attributes
    ----------
    n : int
        Coordinates.
    data : TinyData
        The exact data (``data.x0``, ``data.v0`` in float64).
    engine : str
        ``"tiny"``, the planner's name for it.
    """

    engine = "tiny"

    def __init__(self, data: TinyData) -> None:
        self.data = data
        self.n = data.n
        self._form: _Scalar | BlockMotion | None = None

    @property
    def form(self) -> _Scalar | BlockMotion:
        """The closed form (one coordinate) or the block decomposition, built on first use."""
        if self._form is None:
            data = self.data
            if self.n == 1:
                self._form = _Scalar(data)
            else:
                A, B = data.normalized()
                floats = data.normalized_floats
                self._form = BlockMotion(
                    self.n, A, B, data.x0, data.v0, floats=floats,
                    modes=lambda: classical_modes(self.n, data.M, data.K, data.C, floats, (A, B)))
        return self._form

    def evaluate(self, times: Times, order: int) -> tuple[np.ndarray, np.ndarray]:
        """x^(order) at ``times``: values and bounds on their errors, shape (n, len(times)).

        A time the engine cannot bound has an infinite bound (never NaN). The value of a
        time does not depend on the other times of the call.
        """
        if order not in (0, 1, 2):
            raise ValueError(f"derivative must be 0, 1 or 2, got {order!r}")
        t = times.hi
        lo = times.lo if times.given else None  # None: float times (no low parts)
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            values, bounds = self.form.evaluate(t, lo, order)
            # one pass: the sum is finite only where every value and bound is (an overflow
            # of the sum of finite numbers only takes the careful path below)
            if not math.isfinite(float(np.add.reduce(values + bounds, axis=None))):
                bounds = np.where(np.isfinite(values) & np.isfinite(bounds), bounds, np.inf)
        if times.span[0] == 0:  # x^(order)(0) is the initial data: exactly, rounded once
            initial = self.data.initial(order)
            zeros = (t == 0).nonzero()[0]
            rounding = [U * abs(v) for v in initial.tolist()]
            if zeros.size == 1:  # one column: a view
                values[:, zeros[0]], bounds[:, zeros[0]] = initial, rounding
            else:
                values[:, zeros], bounds[:, zeros] = initial[:, None], np.array(rounding)[:, None]
        return values, bounds

    def values(self, times: Times, order: int) -> np.ndarray:
        """The values of :meth:`evaluate` alone, the same numbers, for a caller whose
        :meth:`bound_until` of the last time already meets its target (every bound
        :meth:`evaluate` would give is within it).

        >>> scene = Scene.from_matrices(M=[[1, 0], [0, 2]], C=[[1, 0], [0, 0]],
        ...                             K=[[3, -1], [-1, 1]], x0=[1, 0], v0=[0, 0])
        >>> motion, times = tiny_motion(scene), as_times([0.0, 0.5, 2.0])
        >>> bool((motion.values(times, 0) == motion.evaluate(times, 0)[0]).all())
        True
        """
        if order not in (0, 1, 2):
            raise ValueError(f"derivative must be 0, 1 or 2, got {order!r}")
        t = times.hi
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            values = self.form.values(t, times.lo if times.given else None, order)
        if times.span[0] == 0:
            values[:, (t == 0).nonzero()[0]] = self.data.initial(order)[:, None]
        return values

    def largest_bound(self, t: np.ndarray) -> float:
        """The largest bound of x at the float64 times ``t`` over every coordinate (inf
        where the decomposition serves no time): the bounds of :meth:`evaluate` without its
        values, for a caller that compares them with a floor of the scale.

        >>> scene = Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[1], v0=[0])
        >>> bool(tiny_motion(scene).largest_bound(np.array([0.0, 1.0])) < 1e-14)
        True
        """
        form = self.form
        if isinstance(form, _Scalar):
            bounds = form.evaluate(t, None, 0)[1]
        elif form.failure is not None:
            return math.inf
        else:
            with np.errstate(over="ignore", invalid="ignore"):
                bounds = form.bounds(t, 0)
        largest = float(bounds.max(initial=0.0))
        return math.inf if math.isnan(largest) else largest

    def bound_until(self, t_max: float) -> float:
        """An upper bound of :meth:`largest_bound` over the times [0, t_max], from the
        closed form's or the decomposition's constants alone (float arithmetic, no
        per-time work); inf for a failed decomposition or where an exponential would
        overflow (ask :meth:`largest_bound`). Decomposes on first use.

        >>> scene = Scene.from_matrices(M=[[1, 0], [0, 2]], C=[[1, 0], [0, 0]],
        ...                             K=[[3, -1], [-1, 1]], x0=[1, 0], v0=[0, 0])
        >>> motion = tiny_motion(scene)
        >>> t = np.linspace(0.0, 1.0, 101)
        >>> bool(motion.largest_bound(t) <= motion.bound_until(1.0) < 1e-13)
        True
        """
        return self.form.bound_until(t_max)

    @property
    def spectral_radius(self) -> float:
        """max |λ| over the poles (decomposes on first use)."""
        return self.form.radius

    def poles(self) -> np.ndarray:
        """The poles: the roots of Δ(λ) = det(λ²M + λC + K), complex float64."""
        return np.asarray(self.form.poles)

    def refusal(self) -> str | None:
        """Why the decomposition serves no time (then every bound is infinite), or None."""
        return getattr(self.form, "failure", None)


# ----------------------------------------------------------------------------- one coordinate


def _sqrt_dd(value: Any) -> tuple[float, float]:
    """√value for a positive fmpq as hi + lo: hi = fl(√value), lo = (value − hi²)/(2·hi)
    rounded (|hi + lo − √value| ≤ 2u²·√value: one exact Newton step)."""
    hi = math.sqrt(float(value))
    exact = fmpq(*hi.as_integer_ratio())
    return hi, float((value - exact * exact) / (2 * exact))


#: Relative error of e^{λt} per unit |λ|·t: λ rounded (≤ 6.3u for the roots of the
#: overdamped case, ≤ u for α), the product (u), the time's low part (|lo| ≤ u·t), and
#: e^δ − 1 ≤ 1.0001δ (e^x is 0 or overflows beyond |x| = 745, so δ < 1e-12 wherever it
#: matters); the libm adds 2u.
_EXP_SLOPE = 1.0001 * 8.4 * U


class _Scalar:
    """m x'' + c x' + k x = 0 in closed form (see the module notes).

    x^(r)(t) = p·C(t) + w·S(t) with C, S the branch's functions (e^{αt} included) and
    (p, w) exact for the order r, rounded once. Each branch returns C, S and absolute
    bounds on their errors that include the 3u of p's and w's rounding, the products and
    the sum (relative to |C|, |S| or their envelopes); the bound of x^(r) is
    |p|·err_C + |w|·err_S. The time's low part |lo| ≤ u·t enters the arguments of e^{λt}
    (in the slope), the phase ωt exactly (double-double), and t·e^{αt} (u more).
    """

    failure: str | None = None

    def __init__(self, data: TinyData) -> None:
        zero = fmpq(0)
        m, c, k = data.M[0, 0], data.C.get((0, 0), zero), data.K.get((0, 0), zero)
        alpha = -c / (2 * m)
        disc = (c * c - 4 * m * k) / (4 * m * m)
        self.alpha = float(alpha)
        self.sign = int(disc > 0) - int(disc < 0)
        self._exact = (m, c, k, alpha, data.x0_exact[0], data.v0_exact[0])
        self._pw: dict[int, tuple[float, float]] = {}  # (p, w) per order, made when asked
        if self.sign < 0:
            self.omega = _sqrt_dd(-disc)
            w_hi = self.omega[0]
            self.poles = np.array([complex(self.alpha, w_hi), complex(self.alpha, -w_hi)])
        else:
            self.root = root = math.sqrt(float(disc))
            far = self.alpha + math.copysign(root, self.alpha) if self.alpha else -root
            near = float(k / m) / far if far else 0.0
            self.rates = (max(near, far), min(near, far))
            self.poles = np.array(self.rates, dtype=complex)
        self.radius = max(abs(complex(p)) for p in self.poles)

    def _initial(self, order: int) -> tuple[float, float]:
        """(p, w) of derivative ``order``: x^(r)(0) and x^(r+1)(0) − α·x^(r)(0), formed
        exactly (x'' = −(c x' + k x)/m and its derivative), rounded once."""
        found = self._pw.get(order)
        if found is None:
            m, c, k, alpha, p, q = self._exact
            for _ in range(order):
                p, q = q, -(c * q + k * p) / m
            found = self._pw[order] = (float(p), float(q - alpha * p))
        return found

    def evaluate(self, t: np.ndarray, lo: np.ndarray | None,
                 order: int) -> tuple[np.ndarray, np.ndarray]:
        """Values and bounds, shape (1, len(t)), at the times t + lo (lo None: zero;
        |lo| ≤ u·t, which the bounds cover wherever the values are taken at t)."""
        p, w = self._initial(order)
        if self.sign < 0:
            C, S, err_C, err_S = self._under(t, lo)
        elif self.sign == 0:
            C, S, err_C, err_S = self._critical(t)
        else:
            C, S, err_C, err_S = self._over(t)
        values = p * C + w * S
        # below 2⁻¹⁰²² e^{λt} and the products lose relative accuracy: 1e-300 absolute
        bound = (abs(p) * _SAFETY) * err_C + (abs(w) * _SAFETY) * err_S \
            + 1e-300 * (abs(p) + abs(w) * (1 + t))
        return values[None, :], bound[None, :]

    def values(self, t: np.ndarray, lo: np.ndarray | None, order: int) -> np.ndarray:
        """The values of :meth:`evaluate` alone."""
        return self.evaluate(t, lo, order)[0]

    def bound_until(self, t_max: float) -> float:
        """An upper bound of every bound :meth:`evaluate` gives for x (order 0) at times in
        [0, t_max], in float arithmetic: each branch's bound written as a sum of
        t^k·e^{rt} times constants (cosh and sinh(x)/x at their largest argument, min(t, 1/ω)
        by either side), each t^k·e^{rt} at its peak on [0, t_max]
        (:func:`~laplace_springs.kernels.peaks.peak`: for a decaying motion, that of
        its worst time); inf where an exponential would overflow.

        >>> data = tiny_data(Scene.from_matrices(M=[[1]], C=[["1/10"]], K=[[4]], x0=[1], v0=[0]))
        >>> scalar = _Scalar(data)
        >>> t = np.linspace(0.0, 3.0, 301)
        >>> bool(scalar.evaluate(t, None, 0)[1].max() <= scalar.bound_until(3.0) < 1e-14)
        True
        """
        T = t_max
        if not T < 1e300:
            return math.inf
        p, w = (abs(v) for v in self._initial(0))
        if self.sign < 0:
            err_C, err_S = self._under_until(T)
        elif self.sign == 0:
            P = [peak(self.alpha, k, T) for k in range(3)]
            A = _EXP_SLOPE * abs(self.alpha)
            err_C, err_S = 5 * U * P[0] + A * P[1], 6 * U * P[1] + A * P[2]
        else:
            err_C, err_S = self._over_until(T)
        found = p * _SAFETY * err_C + w * _SAFETY * err_S + 1e-300 * (p + w * (1 + T))
        return math.inf if math.isnan(found) else found * (1 + 1e-12)  # the sum's rounding

    def _under_until(self, T: float) -> tuple[float, float]:
        """The largest err_C and err_S of :meth:`_under` on [0, T]: e^{αt}·ε(t) with
        ε = 11u + t(A + Bt), and (err_C + 2u·e^{αt})·min(t, 1/ω), each power of t with
        e^{αt} at its peak."""
        omega = self.omega[0]
        P = [peak(self.alpha, k, T) for k in range(4)]
        A = _EXP_SLOPE * abs(self.alpha) + 8 * U * U * omega
        B = 2 * (U * omega) ** 2
        err_C = 11 * U * P[0] + A * P[1] + B * P[2]
        err_S = min(13 * U * P[1] + A * P[2] + B * P[3],
                    (13 * U * P[0] + A * P[1] + B * P[2]) / omega)
        return err_C, err_S

    def _over_until(self, T: float) -> tuple[float, float]:
        """The largest err_C and err_S of :meth:`_over` on [0, T]: the sum of both
        branches' (cosh and sinh(x)/x of x ≤ min(√D·T, 1/2) where √D·t < 1/2; e^{λ₊t} and
        e^{λ₋t} beyond), each power of t with its exponential at its peak."""
        s = self.root
        h = min(s * T, 0.5)
        A = _EXP_SLOPE * abs(self.alpha)
        P = [peak(self.alpha, k, T) for k in range(3)]
        err_C = math.cosh(h) * (13 * U * P[0] + A * P[1])
        err_S = (math.sinh(h) / h if h > 0 else 1.0) * (14 * U * P[1] + A * P[2])
        if s * T >= 0.5:
            up, down = self.rates
            E = peak(up, 0, T) + peak(down, 0, T)
            absolute = 2 * U * E + _EXP_SLOPE * (abs(up) * peak(up, 1, T)
                                                 + abs(down) * peak(down, 1, T))
            err_C += absolute / 2 + 2 * U * E
            err_S += absolute / (2 * s) + 3.5 * U * E / s
        return err_C, err_S

    def _under(self, t: np.ndarray, lo: np.ndarray | None) -> tuple[np.ndarray, ...]:
        """D < 0: C = e^{αt} cos ωt and S = e^{αt} sin(ωt)/ω with ωt in double-double: the
        phase θ = P + e (P = fl(ω_hi t), e its exact error plus ω_lo·t + ω_hi·lo), so
        cos θ = cos P − e·sin P and sin θ = sin P + e·cos P up to e²/2 ≤ 2u²θ²; the
        libm's cos and sin (≤ 1 ulp at any argument) and the correction add ≤ 6u of the
        envelopes e^{αt} and e^{αt}·min(t, 1/ω); the phase itself is off by ≤ 8u²θ."""
        w_hi, w_lo = self.omega
        E = np.exp(self.alpha * t)
        P, e = two_prod(w_hi, t)
        e += w_lo * t
        if lo is not None:
            e += w_hi * lo
        cos_P, sin_P = np.cos(P), np.sin(P)
        C = E * (cos_P - e * sin_P)
        S = (E / w_hi) * (sin_P + e * cos_P)
        eps = (11 * U) + t * ((_EXP_SLOPE * abs(self.alpha) + 8 * U * U * w_hi)
                              + (2 * (U * w_hi) ** 2) * t)
        err_C = E * eps
        return C, S, err_C, (err_C + (2 * U) * E) * np.minimum(t, 1 / w_hi)

    def _critical(self, t: np.ndarray) -> tuple[np.ndarray, ...]:
        """D = 0: C = e^{αt}, S = t·e^{αt}."""
        E = np.exp(self.alpha * t)
        S = t * E
        eps = (5 * U) + (_EXP_SLOPE * abs(self.alpha)) * t
        return E, S, E * eps, S * (eps + U)

    def _over(self, t: np.ndarray) -> tuple[np.ndarray, ...]:
        """D > 0: cosh and sinh of √D·t where √D·t < 1/2, else from e^{λ₊t} and e^{λ₋t}
        (each time by its own √D·t)."""
        small = t < 0.5 / self.root
        if small.all():
            return self._over_small(t)
        if not small.any():
            return self._over_large(t)
        parts = [self._over_small(t[small]), self._over_large(t[~small])]
        out = []
        for first, second in zip(*parts):
            whole = np.empty_like(t)
            whole[small], whole[~small] = first, second
            out.append(whole)
        return tuple(out)

    def _over_small(self, t: np.ndarray) -> tuple[np.ndarray, ...]:
        """√D·t < 1/2: √D (1.5u), the product, the libm and the division: ≤ 8u relative;
        the time's low part moves cosh(st) by ≤ 0.53·s·|lo| ≤ 0.3u and sinh(st)/s by
        ≤ 1.13·|lo| ≤ 1.2u relative."""
        s = self.root
        E = np.exp(self.alpha * t)
        st = s * t
        C = E * np.cosh(st)
        S = E * (np.sinh(st) / s)
        eps = (13 * U) + (_EXP_SLOPE * abs(self.alpha)) * t
        return C, S, C * eps, S * (eps + U)

    def _over_large(self, t: np.ndarray) -> tuple[np.ndarray, ...]:
        """√D·t ≥ 1/2: the large root from α and √D (one subtraction of equal signs,
        ≤ 3.1u), the small one through one more rounding and a division (≤ 5.2u);
        e^{λ₊t} − e^{λ₋t} ≥ (1 − e⁻¹)e^{λ₊t}, so the difference and √D add ≤ 4u of S."""
        up, down = self.rates
        E1 = np.exp(up * t)
        E2 = np.exp(down * t)
        C = (E1 + E2) / 2
        S = (E1 - E2) / (2 * self.root)
        absolute = E1 * ((2 * U) + (_EXP_SLOPE * abs(up)) * t) \
            + E2 * ((2 * U) + (_EXP_SLOPE * abs(down)) * t)
        return C, S, absolute / 2 + (4 * U) * C, absolute / (2 * self.root) + (7 * U) * S
