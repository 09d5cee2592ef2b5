"""Float64 evaluation of exponential-polynomial sums without cancellation or phase error.

A solution in real form is first rewritten, at high precision, as a pole sum

    x_i(t) = Σ_j Σ_k C_ijk t^k e^{z_j t}        (every pole z_j, conjugates included).

Evaluated term by term in float64 this loses digits in two ways:

* **Cancellation between close poles.** Near-critical damping, near-defective pairs and
  a forcing frequency near a natural one give residues C of size 1/δ (δ the pole
  gap) that cancel to a moderate x(t) while δ·t is small.
* **Phase error.** cos(ωt) with ω rounded to float64 is off by ~1e-16·ωt; at ωt = 1e4
  that alone is 1e-12.

**Algorithm.** Poles are linked by single-link clustering on |z_a − z_b| (a dendrogram,
closed under conjugation). At a merge of height h the two groups are *blocked* together
when their separate Newton forms (below) are much larger than the joint one on
0 ≤ t ≤ θ/h, i.e. when keeping them apart would cancel. A block B with nodes
z_1..z_M (repeated by multiplicity, Leja order) is written in the Newton basis of
confluent divided differences of f(λ) = e^{λt}:

    Σ_{j∈B} Σ_k C_jk ∂_λ^k e^{λt}|_{z_j} = Σ_m d_m f[z_1..z_m],   d_m = L(ω_{m-1}),

with ω_{m-1}(λ) = Π_{l<m}(λ − z_l) and L(p) = Σ C_jk p^{(k)}(z_j), computed at high
precision; the d_m are as large as x itself, not as the residues. The divided
differences are the first row of exp(tZ), Z bidiagonal (nodes on the diagonal, ones
above) (Opitz). With the block centre μ and offsets δ_l = z_l − μ,

    f[z_1..z_m] = e^{μt} t^{m-1} E_m,   E = first row of exp(W),  W = diag(tδ) + N,

and the block is used only while t·|z_a − z_b| ≤ θ on its links, so ‖tδ‖ is small and
E comes from a short Taylor series (scaling and squaring past 1/2). The phase of
e^{μt} is formed from μ as a double-double with an error-free product (Veltkamp
split), so cos and sin see it to ~1e-16 absolute whatever μt is.

**Error estimate.** Each block adds eps·κ·|e^{μt}|·Σ_m |d_m| t^{m-1} e^{‖tδ‖}/(m−1)!
(κ grows with the block size and the squarings) to a running bound: the magnitude of
what was summed, which bounds the rounding of every step above. κ also carries the
phase error (2^-103 + the data's relative precision)·|z|·t: at ωt = 1e20 a double-double
phase is no longer good to 1e-13, and the bound says so.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import mpmath
import numpy as np

from ..kernels.batch import rows_product
from ..kernels.dd import two_diff, two_prod
from ..kernels.precision import workdps
from ..limits import limits

__all__ = ["Block", "PoleSum", "evaluate_blocks", "plan_blocks", "two_diff"]

_EPS = float(np.finfo(float).eps)
#: Relative error of a phase formed in double-double (μ stored to 2^-106, products 2^-105).
_PHASE_UNIT = 2.0**-103


@dataclass(frozen=True, eq=False)
class PoleSum:
    """x_i(t) = Σ_j Σ_k coefficients[j][k][i] · t^k e^{nodes[j] t}, as mpmath numbers.

    ``nodes`` are closed under conjugation (with conjugate coefficients), so the sum is
    real. ``multiplicity[j]`` is the number of powers k stored for node j.
    """

    n: int
    nodes: tuple
    coefficients: tuple  # [j][k] -> tuple of n mpc
    mirror: tuple[int, ...]  # index of each node's conjugate
    dps: int
    #: per node, a bound on the absolute error of every one of its coefficients where the
    #: data are balls whose radii are not small relative to the coefficient itself (a
    #: residue of 1e-600 held as 0 ± 1e-59 beside residues of 1): None where every
    #: coefficient is good to ``dps`` digits of itself
    absolute: tuple[float, ...] | None = None

    @property
    def multiplicity(self) -> tuple[int, ...]:
        return tuple(len(c) for c in self.coefficients)


@dataclass(frozen=True, eq=False)
class Block:
    """A group of poles evaluated together in Newton form, on t_low < |t| ≤ t_high.

    ``factor`` is 2 for a block in the upper half plane (its mirror is skipped), 1 for a
    block closed under conjugation. ``mu`` is (re_hi, re_lo, im_hi, im_lo); ``delta``
    the float offsets (M,), ``d`` the Newton coefficients (M, n) as complex floats.
    """

    nodes: tuple[int, ...]
    t_low: float
    t_high: float
    factor: float
    mu: tuple[float, float, float, float]
    delta: np.ndarray
    d: np.ndarray
    magnitude: np.ndarray = field(repr=False)  # |d| summed over coordinates, (M,)
    precision: float = 0.0  # relative error of the high-precision data behind d
    data_error: np.ndarray | None = field(default=None, repr=False)  # absolute, (M, n)


# ----------------------------------------------------------------------------- Newton form


def _leja(indices: Sequence[int], nodes: Sequence, centre) -> list[int]:
    """Distinct node indices in Leja order about ``centre`` (largest distance first)."""
    rest = list(indices)
    first = max(rest, key=lambda j: abs(nodes[j] - centre))
    order = [first]
    rest.remove(first)
    while rest:
        nxt = max(rest, key=lambda j: _product(abs(nodes[j] - nodes[o]) for o in order))
        order.append(nxt)
        rest.remove(nxt)
    return order


def _product(values) -> mpmath.mpf:
    out = mpmath.mpf(1)
    for v in values:
        out *= v
    return out


def _newton(form: PoleSum, block: Sequence[int]) -> tuple[list, list, object]:
    """Expanded node order, Newton coefficients d_m (lists of n mpc) and centre μ."""
    nodes, coeffs, mult = form.nodes, form.coefficients, form.multiplicity
    with workdps(form.dps):
        total = sum(mult[j] for j in block)
        centre = sum((nodes[j] * mult[j] for j in block), mpmath.mpc(0)) / total
        order = [j for j in _leja(block, nodes, centre) for _ in range(mult[j])]
        # Taylor coefficients ω^{(r)}(z_j)/r! of ω = Π (λ - z_l), at each node of the block
        taylor = {j: [mpmath.mpc(1)] + [mpmath.mpc(0)] * (mult[j] - 1) for j in block}
        factorials = [math.factorial(k) for k in range(max(mult[j] for j in block))]
        d = []
        for step in range(total):
            dm = [mpmath.mpc(0)] * form.n
            for j in block:
                for k, ck in enumerate(coeffs[j]):
                    w = taylor[j][k] * factorials[k]
                    if w:
                        dm = [a + c * w for a, c in zip(dm, ck)]
            d.append(dm)
            z = nodes[order[step]]
            for j in block:
                tj, gap = taylor[j], nodes[j] - z
                for r in range(len(tj) - 1, 0, -1):
                    tj[r] = tj[r - 1] + gap * tj[r]
                tj[0] = gap * tj[0]
        return order, d, centre


def _dd(value) -> tuple[float, float]:
    """A real mpmath number as a double-double (hi, lo)."""
    hi = float(value)
    return hi, float(value - hi) if math.isfinite(hi) else 0.0


def _make_block(form: PoleSum, block: Sequence[int], t_high: float) -> Block:
    order, d, centre = _newton(form, block)
    with workdps(form.dps):
        upper = all(mpmath.im(form.nodes[j]) > 0 for j in block)
        delta = np.array([complex(form.nodes[j] - centre) for j in order])
        mu = (*_dd(mpmath.re(centre)), *_dd(mpmath.im(centre)))
        dc = np.array([[complex(v) for v in dm] for dm in d], dtype=complex)
    precision = 10.0 ** (3 - form.dps)
    return Block(tuple(block), -1.0, t_high, 2.0 if upper else 1.0, mu, delta, dc,
                 np.abs(dc).sum(axis=1), precision, _data_error(form, block, delta, precision))


def _data_error(form: PoleSum, block: Sequence[int], delta: np.ndarray,
                precision: float) -> np.ndarray:
    """Absolute errors of the Newton coefficients d_m from the data's own precision, (M, n).

    d_m = Σ C_jk ∂^k ω_{m−1}(z_j) combines coefficients C of the block's nodes; where the
    d_m cancel (a value that is exactly zero, say) their error is that of the C, not a
    fraction of d: (precision · Σ|C| + Σ absolute) · (m + 1)^K · max(1, diameter)^m, K the
    largest power of t, ``absolute`` the form's absolute errors of the C (each counted for
    every power).
    """
    size = np.zeros(form.n)
    for j in block:
        for ck in form.coefficients[j]:
            size += np.array([abs(complex(c)) for c in ck])
    size *= precision
    if form.absolute is not None:
        size += sum(form.absolute[j] * len(form.coefficients[j]) for j in block)
    diameter = max(1.0, 2 * float(np.max(np.abs(delta), initial=0.0)))
    powers = max(len(form.coefficients[j]) for j in block) - 1
    m = np.arange(delta.size)
    growth = (m + 1.0) ** powers * diameter ** m
    return growth[:, None] * size[None, :]


def _size(block: Block, t: float) -> float:
    """Σ_m |d_m| t^{m-1}/(m-1)!: the magnitude a block's Newton form sums at time t."""
    m = np.arange(block.delta.size)
    return float(np.sum(block.magnitude * np.exp(m * math.log(t) - _log_factorials(m)))
                 if t > 0 else block.magnitude[0])


def _log_factorials(m: np.ndarray) -> np.ndarray:
    return np.array([math.lgamma(k + 1) for k in m])


# ----------------------------------------------------------------------------- planning


def _edges(nodes: Sequence) -> list[tuple[float, int, int]]:
    """All pairwise distances (height, a, b), ascending."""
    return sorted((float(abs(nodes[a] - nodes[b])), a, b)
                  for a in range(len(nodes)) for b in range(a + 1, len(nodes)))


def plan_blocks(form: PoleSum) -> list[Block]:
    """The blocks of a pole sum, each with the time window in which it is used.

    Walks the single-link dendrogram upwards (Kruskal). A group is a list of blocks;
    at a link of height h the union becomes one block for t ≤ Limits.block_theta/h when the groups'
    separate Newton forms are more than Limits.block_gain times larger than the joint form
    somewhere on [0, Limits.block_theta/h] (against a floor of a tenth of its largest size), i.e.
    when evaluating them apart would cancel. The mirror link (conjugate nodes) gets
    the same decision, so blocks come in conjugate pairs or are self-conjugate; blocks
    wholly in the lower half plane are dropped and their mirrors count twice.
    """
    count = len(form.nodes)
    parent = list(range(count))
    groups: dict[int, list[Block]] = {}
    built: dict[tuple[int, ...], Block] = {}
    finished: list[tuple[Block, float]] = []

    def find(a: int) -> int:
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    def block_of(nodes: tuple[int, ...], t_high: float) -> Block:
        if nodes not in built:
            built[nodes] = _make_block(form, nodes, t_high)
        return built[nodes]

    def join(a: int, b: int, h: float, decision: bool | None) -> bool:
        ra, rb = find(a), find(b)
        parts = groups.pop(ra) + groups.pop(rb)
        parent[rb] = ra
        t_high = limits().block_theta / h if h > 0 else math.inf
        union = tuple(sorted(j for part in parts for j in part.nodes))
        if decision is None:
            decision = len(union) <= limits().max_block and _needs_merge(
                parts, block_of(union, t_high), t_high)
        if decision:
            finished.extend((part, t_high) for part in parts)
            parts = [block_of(union, t_high)]
        groups[ra] = parts
        return decision

    for j in range(count):
        groups[j] = [block_of((j,), math.inf)]
    for h, a, b in _edges(form.nodes):
        if find(a) == find(b):
            continue
        decision = join(a, b, h, None)
        ma, mb = form.mirror[a], form.mirror[b]
        if find(ma) != find(mb):
            join(ma, mb, h, decision)
    finished += [(part, -1.0) for parts in groups.values() for part in parts]
    out = []
    for blk, t_low in finished:
        if t_low >= blk.t_high or all(mpmath.im(form.nodes[j]) < 0 for j in blk.nodes):
            continue
        out.append(dataclasses.replace(blk, t_low=t_low))
    return out


def _needs_merge(parts: list[Block], joint: Block, t_high: float) -> bool:
    samples = [0.0] + ([t_high * f for f in (1 / 64, 1 / 8, 1 / 2, 1)]
                       if math.isfinite(t_high) else [1.0, 1e3, 1e6])
    apart = np.array([sum(_size(p, t) for p in parts) for t in samples])
    together = np.array([_size(joint, t) for t in samples])
    floor = 0.1 * together.max()
    return bool(np.any(apart > limits().block_gain * (together + floor))) or not math.isfinite(t_high)


# ----------------------------------------------------------------------------- float kernels


def _centre_factor(mu: tuple[float, float, float, float], t: np.ndarray, t_lo: np.ndarray):
    """|e^{μt}|, cos and sin of arg e^{μt}, with μt formed in double-double (t = t + t_lo)."""
    re_hi, re_lo, im_hi, im_lo = mu
    p, e = two_prod(re_hi, t)
    e = e + (re_lo * t + re_hi * t_lo)
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        # past |p| ~ 700 the result is 0 or inf whatever e is (and e may be ~1e3)
        size = np.where(np.abs(p) < 700, np.exp(p) * np.exp(e), np.exp(p + e))
    if im_hi == 0.0 and im_lo == 0.0:
        return size, np.ones_like(t), np.zeros_like(t)
    p, e = two_prod(im_hi, t)
    e = e + (im_lo * t + im_hi * t_lo)
    ce, se = np.cos(e), np.sin(e)
    cp, sp_ = np.cos(p), np.sin(p)
    return size, cp * ce - sp_ * se, sp_ * ce + cp * se


def _row_taylor(x: np.ndarray) -> np.ndarray:
    """First row of exp(diag(x) + N) for ‖x‖ ≤ 1/2, rows of x over times."""
    size = x.shape[1]
    term = np.zeros_like(x)
    term[:, 0] = 1.0
    total = term.copy()
    for k in range(1, size + 17):
        nxt = term * x
        nxt[:, 1:] += term[:, :-1]
        term = nxt / k
        total += term
    return total


def _squared(x: np.ndarray, s: int) -> np.ndarray:
    """First row of exp(diag(x) + N) by Taylor on 2^-s of it and s squarings."""
    count, size = x.shape
    xs, sup = x / 2.0**s, 2.0**-s
    term = np.broadcast_to(np.eye(size, dtype=complex), (count, size, size)).copy()
    total = term.copy()
    for k in range(1, size + 19):
        nxt = term * xs[:, None, :]
        nxt[:, :, 1:] += sup * term[:, :, :-1]
        term = nxt / k
        total += term
    for _ in range(s):
        total = total @ total
    return total[:, 0, :]


def first_row_exp(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """First row of exp(diag(x) + N) per time (rows of x), and the squarings used."""
    rho = np.abs(x).max(axis=1) if x.size else np.zeros(len(x))
    s = np.where(rho > 0.5, np.ceil(np.log2(np.maximum(rho, 0.5) / 0.5)), 0).astype(int)
    out = np.empty_like(x)
    for sv in np.unique(s):
        sel = s == sv
        out[sel] = _row_taylor(x[sel]) if sv == 0 else _squared(x[sel], int(sv))
    return out, s


def _block_values(block: Block, t: np.ndarray,
                  t_lo: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The block's contribution (n, T) and its error bound (n, T) at times t + t_lo."""
    size = block.delta.size
    x = t[:, None] * block.delta[None, :]
    powers = np.arange(size)
    with np.errstate(over="ignore", invalid="ignore"):
        tpow = t[:, None] ** powers[None, :]
        rows, squarings = first_row_exp(x) if size > 1 else (np.ones((t.size, 1), complex),
                                                             np.zeros(t.size, int))
        series = rows_product(tpow * rows, block.d)  # (T, n), each time alone
        scale, cos, sin = _centre_factor(block.mu, t, t_lo)
        values = block.factor * scale[:, None] * (cos[:, None] * series.real
                                                  - sin[:, None] * series.imag)
        rho = np.abs(x).max(axis=1) if size > 1 else np.zeros(t.size)
        bound_rows = tpow * np.exp(rho[:, None] - _log_factorials(powers)[None, :])
        # the phase z·t: z held to 2^-104 (double-double) and to the data's precision
        reach = (math.hypot(block.mu[0], block.mu[2]) + float(np.max(np.abs(block.delta), initial=0.0)))
        phase = (_PHASE_UNIT + block.precision) * reach * np.abs(t + t_lo)
        kappa = _EPS * 2.0 * (size + squarings + 3) + block.precision + phase
        bound = (kappa * block.factor * scale)[:, None] * rows_product(bound_rows, np.abs(block.d))
        if block.data_error is not None:
            bound += (block.factor * scale)[:, None] * rows_product(bound_rows, block.data_error)
    return values.T, bound.T


def evaluate_blocks(blocks: Sequence[Block], n: int, times: np.ndarray,
                    times_lo: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Sum every block on its window: values and error bounds, each (n, len(times)).

    ``times_lo`` (optional) are low parts: the times are times + times_lo exactly.
    """
    times_lo = np.zeros_like(times) if times_lo is None else times_lo
    values = np.zeros((n, times.size))
    bound = np.zeros((n, times.size))
    at = np.abs(times)
    for block in blocks:
        sel = (at > block.t_low) & (at <= block.t_high)
        if not sel.any():
            continue
        v, e = _block_values(block, times[sel], times_lo[sel])
        values[:, sel] += v
        bound[:, sel] += e
    return values, bound


def derivative_sum(form: PoleSum, order: int = 1) -> PoleSum:
    """The pole sum of d^order/dt^order of ``form`` (exact in the stored precision).

    d/dt Σ_k c_k t^k e^{zt} = Σ_k (z c_k + (k + 1) c_{k+1}) t^k e^{zt}.

    Examples
    --------
    >>> form = PoleSum(1, (mpmath.mpc(0, 2), mpmath.mpc(0, -2)),
    ...                (((mpmath.mpc(0.5),),), ((mpmath.mpc(0.5),),)), (1, 0), 20)   # cos 2t
    >>> derivative_sum(form).coefficients[0][0][0]
    mpc(real='0.0', imag='1.0')
    """
    for _ in range(order):
        with workdps(form.dps):
            coefficients = []
            for z, powers in zip(form.nodes, form.coefficients):
                rows = []
                for k, ck in enumerate(powers):
                    nxt = powers[k + 1] if k + 1 < len(powers) else None
                    rows.append(tuple(z * c + ((k + 1) * nxt[i] if nxt is not None else 0)
                                      for i, c in enumerate(ck)))
                coefficients.append(tuple(rows))
        # an absolute error ε of every coefficient becomes at most (|z| + K)·ε, K the powers
        absolute = None if form.absolute is None else tuple(
            float(error * (abs(complex(z)) + len(powers)) * (1 + 1e-12))
            for error, z, powers in zip(form.absolute, form.nodes, form.coefficients))
        form = PoleSum(form.n, form.nodes, tuple(coefficients), form.mirror, form.dps, absolute)
    return form
