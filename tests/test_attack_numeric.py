"""Cases found by a numeric attack on the public API (random scenes, every engine, times
from 1e-300 to 1e6, against an independent reference), kept as regression tests.

The reference is written here from the scene's exact M, C, K, x0, v0 alone: the first-order
matrix Z = [[0, I], [−M⁻¹K, −M⁻¹C]] in flint rationals and x(t) = the first n rows of
exp(Z t) y0 from arb's matrix exponential, at a precision raised until every entry's radius
is below 1e-40 of the motion's size.
"""

from __future__ import annotations

from fractions import Fraction

import mpmath
import numpy as np
import pytest
from flint import arb, arb_mat, ctx, fmpq, fmpq_mat

import laplace_springs as ls
from laplace_springs.numeric import terms
from laplace_springs.numeric.chebyshev import chebyshev_motion, verified_interval
from tests.test_attack import first_order


def _q(value) -> fmpq:
    value = Fraction(value)
    return fmpq(value.numerator, value.denominator)


def motion(scene: ls.Scene, times, order: int = 0) -> list[list[arb]]:
    """x^(order)(t) for each time: rows per coordinate, arb balls (radius < 1e-40 of the size)."""
    n = scene.n
    Z, start, _ = first_order(scene)
    for _ in range(order):
        start = Z * start
    columns = []
    for t in times:
        bits = 256
        while True:
            with ctx.workprec(bits):
                y = (arb_mat(Z) * arb(_q(Fraction(t)))).exp() * arb_mat(start)
                column = [y[i, 0] for i in range(n)]
                size = max(abs(float(c.mid())) for c in column)
                if all(c.is_finite() for c in column) \
                        and max(float(c.rad()) for c in column) <= 1e-40 * size:
                    break
            bits *= 2
            assert bits < 20_000, f"no reference at t = {t}"
        columns.append(column)
    return [list(row) for row in zip(*columns)]


def assert_bounded(values, bounds, reference) -> None:
    """Every entry's error at most its bound (the error's lower end: the reference's
    radius is below 1e-40 of the size, not of each entry)."""
    for i, row in enumerate(reference):
        for j, exact in enumerate(row):
            with ctx.workprec(300):
                difference = arb(float(values[i, j])) - exact
                error = max(abs(float(difference.mid())) - float(difference.rad()), 0.0)
            assert error <= bounds[i, j], (i, j, float(values[i, j]), float(exact.mid()),
                                           error, bounds[i, j])


# ----------------------------------------------------------------------------- chebyshev

#: Rayleigh damping C = K/50 + M/10 with unequal masses: the Gershgorin interval of M⁻¹K
#: took each row's smaller radius of the discs of M⁻¹K and of M^{-1/2}KM^{-1/2}, which is
#: no enclosure: [0.587, 3.216] left out the eigenvalue 0.383 (and 2.980 was above its
#: old upper end 2.739); x(1e-9) was off by 4e-11 with a bound of 1e-14.
UNEQUAL_MASSES = {"M": [["229/50", 0], [0, "49/25"]],
                  "C": [["147/250", "-381/5000"], ["-381/5000", "1361/5000"]],
                  "K": [["13/2", "-381/100"], ["-381/100", "381/100"]],
                  "x0": ["1/10", 1], "v0": [0, 0]}


@pytest.mark.parametrize("damped", [True, False])
def test_chebyshev_with_unequal_masses_keeps_its_bound(damped):
    parts = dict(UNEQUAL_MASSES)
    if not damped:
        parts["C"] = None
    scene = ls.Scene.from_matrices(**parts)
    sol = ls.solve(scene, method="chebyshev")
    times = [0.0, 1e-9, 0.1, 1.0, 10.0]
    for order in (0, 1, 2):
        values, bounds = sol.evaluate(times, return_error=True, derivative=order)
        assert_bounded(values, bounds, motion(scene, times, order))


def test_chebyshev_interval_holds_the_spectrum_with_unequal_masses():
    rng = np.random.default_rng(7)
    for _ in range(200):
        n = int(rng.integers(1, 7))
        masses = [str(rng.choice(["1/3", "1", "2", "229/50", "100", "1e4"])) for _ in range(n)]
        K = np.zeros((n, n), dtype=object)
        K[0, 0] += Fraction(str(rng.choice(["1", "5", "1e3"])))
        for i in range(1, n):
            k = Fraction(str(rng.choice(["1", "3.81", "50", "1e3"])))
            K[i - 1, i - 1] += k
            K[i, i] += k
            K[i - 1, i] -= k
            K[i, i - 1] -= k
        if rng.random() < 0.5:
            K[n - 1, n - 1] += Fraction(str(rng.choice(["1", "1e4"])))
        M = [[masses[i] if i == j else 0 for j in range(n)] for i in range(n)]
        scene = ls.Scene.from_matrices(M=M, C=None,
                                       K=[[str(v) for v in row] for row in K],
                                       x0=[1] * n, v0=[0] * n)
        data = chebyshev_motion(scene).data
        lo, hi, _, _ = verified_interval(data, exact=False)
        root = 1 / np.sqrt(data.mass)
        spectrum = np.linalg.eigvalsh(root[:, None] * data.K.toarray() * root[None, :])
        slack = 1e-12 * spectrum[-1]
        assert lo <= spectrum[0] + slack and spectrum[-1] - slack <= hi, \
            (masses, K.tolist(), lo, hi, spectrum)


#: One mass: the interval is 1e-12·k wide around k, and its nodes came from the float64
#: mid − rad (off by u·k, 1e-4 of the width) while the recurrence's B was centred on mid:
#: x'' + 0.00681x' + 487x = 0, x(0) = 1/10 at t = 100 off by 3.6e-15 with a bound of 1.2e-15.
@pytest.mark.parametrize("k", ["487", "3", "1e4", "12345678"])
def test_chebyshev_on_one_mass_keeps_its_bound(k):
    scene = ls.Scene.from_matrices(M=[[1]], C=[["681/100000"]], K=[[k]], x0=["1/10"], v0=[0])
    sol = ls.solve(scene, method="chebyshev")
    times = [0.37, 50.0, 100.0, 200.0, 1000.0]
    for order in (0, 1, 2):
        values, bounds = sol.evaluate(times, return_error=True, derivative=order)
        assert_bounded(values, bounds, motion(scene, times, order))


# ----------------------------------------------------------------------------- certified


def _diagonal(entries):
    return [[entries[i] if i == j else 0 for j in range(len(entries))] for i in range(len(entries))]


def test_certified_keeps_the_exact_zeros_of_uncoupled_critical_masses():
    """Six uncoupled critically damped masses (double poles −1/2 (twice), −4/3, −1/3, −10,
    −5/6): x_4 does not move with the other poles, but its residues there were balls around
    zero whose midpoints the float64 pole sum added: x_4'(12.5) ≈ −3.3e-52 off by 6.5e-60
    with a bound of 3.3e-67."""
    scene = ls.Scene.from_matrices(
        M=_diagonal([4, "9/4", 4, 1, 4, 9]), C=_diagonal([4, 6, "8/3", 20, 4, 15]),
        K=_diagonal([1, 4, "4/9", 100, 1, "25/4"]),
        x0=["3/2", 2, "1/10", 1, "-1/2", "1/2"], v0=[0, -5, -5, -5, 0, -5])
    sol = ls.solve(scene, method="certified")
    times = [0.0, "0.1", 3.3, 12.5, 40.0]
    for order in (0, 1, 2):
        values, bounds = sol.evaluate(times, return_error=True, derivative=order)
        assert_bounded(values, bounds, motion(scene, times, order))


@pytest.mark.parametrize("method", ["auto", "certified", "tiny", "modal"])
def test_certified_poles_a_hair_apart(method):
    """Two critically damped masses coupled by a spring of 1e-60: the poles −1/2 and −10
    split by about 1e-61. At 64 bits the residues were NaN balls, which the precision check
    passed over (max() skips a NaN), and every engine escalating to certified raised
    flint's "man_exp requires an exact, finite value"."""
    scene = ls.Scene.from_matrices(M=[[4, 0], [0, 1]], C=[[4, 0], [0, 20]],
                                   K=[[1, "-1e-60"], ["-1e-60", 100]], x0=[1, 0], v0=[0, 0])
    sol = ls.solve(scene, method=method)
    times = [1.0, 12.5, 40.0, 100.0]
    for order in (0, 1):
        values, bounds = sol.evaluate(times, return_error=True, derivative=order)
        assert_bounded(values, bounds, motion(scene, times, order))


# ----------------------------------------------------------------------------- planning

#: Six masses with Rayleigh damping C = K/50 + M/100.
SIX_RAYLEIGH_K = [["284/25", "-229/50", 0, 0, 0, 0], ["-229/50", "173/20", "-407/100", 0, 0, 0],
                  [0, "-407/100", "1601/100", "-212/25", 0, "-173/50"],
                  [0, 0, "-212/25", "999/100", "-151/100", 0],
                  [0, 0, 0, "-151/100", "297/100", "-73/50"],
                  [0, 0, "-173/50", 0, "-73/50", "123/25"]]
SIX_RAYLEIGH_M = ["191/25", "449/100", "2/5", "3/5", "51/10", "659/100"]


def test_a_small_rayleigh_scene_at_a_late_time_escalates_past_chebyshev():
    """method='classical' at t = 1e6 escalated first to the Chebyshev engine, quoted 3.2 s
    (a step's overhead, about 9 µs, was not counted: N = 4e6 steps took about 50 s), before
    the refined engine's 2.5 ms."""
    M = _diagonal(SIX_RAYLEIGH_M)
    C = [[str(Fraction(K) / 50 + (Fraction(M[i][j]) / 100 if i == j else 0))
          for j, K in enumerate(row)] for i, row in enumerate(SIX_RAYLEIGH_K)]
    scene = ls.Scene.from_matrices(M=M, C=C, K=SIX_RAYLEIGH_K, x0=[3, "1/10", "1/5", "3/10", 0, 1],
                                   v0=[0, 0, 0, -5, -5, -5])
    chain = ls.plan(scene, [1e6], method="classical", derivative=2).chain
    assert chain.index("refined") < chain.index("chebyshev"), chain
    sol = ls.solve(scene, method="classical")
    values, bounds = sol.evaluate([1e6], return_error=True, derivative=2)
    assert_bounded(values, bounds, motion(scene, [1e6], 2))


def _free_free_four() -> ls.Scene:
    return ls.Scene.from_components(
        masses={"a": 1, "b": 2, "c": 1, "d": 3},
        springs={"k1": ("a", "b", 2), "k2": ("b", "c", 1), "k3": ("c", "d", 3)},
        x0=[1, 0, 0, 0], v0=[0, 0, 0, "1/2"])


def test_a_late_time_escalates_by_the_costs_at_its_own_time():
    """method='modal' on a free-free chain at t = 1e6: the escalation order judged for the
    default request (t up to 100) tried the Chebyshev engine (quoted 12 s at t = 1e6, 13 s
    measured) before the certified engine (0.012 s). A time beyond the default horizon now
    follows the order of its own dyadic band: certified first, and the same value whether
    the time is evaluated alone or with early times."""
    scene = _free_free_four()
    plan = ls.solve(scene, method="modal").plan([1e6])
    late = plan.chain_for(1e6)
    assert late.index("certified") < late.index("chebyshev"), late
    assert plan.chain_for(50.0) == plan.chain
    assert sorted(late) == sorted(plan.chain)  # the same engines, reordered
    sol = ls.solve(scene, method="modal")
    values, bounds, report = sol.evaluate([1e6], return_error=True, return_report=True)
    assert report.engines == ("certified",)
    assert_bounded(values, bounds, motion(scene, [1e6]))
    together = ls.solve(scene, method="modal").evaluate([0.5, 1e6, 3.0], return_error=True)
    assert np.array_equal(together[0][:, 1], values[:, 0])
    assert np.array_equal(together[1][:, 1], bounds[:, 0])


def test_times_of_several_bands_each_follow_their_own_chain():
    """Times on both sides of the default horizon and in several bands: each keeps the value
    it has alone (a function of the time only), every one within its bound."""
    scene = _free_free_four()
    times = [2e6, 1.0, 150.0, 7e5, 99.0, 3e4]
    sol = ls.solve(scene, method="modal")
    values, bounds = sol.evaluate(times, return_error=True)
    assert_bounded(values, bounds, motion(scene, times))
    for j, t in enumerate(times):
        alone = ls.solve(scene, method="modal").evaluate([t], return_error=True)
        assert np.array_equal(alone[0][:, 0], values[:, j]), t
        assert np.array_equal(alone[1][:, 0], bounds[:, j]), t


@pytest.mark.parametrize("method", ["modal", "classical", "certified", "auto"])
def test_a_damping_of_1e300_gives_x_prime_on_every_route_that_escalates(method):
    """x'' + 1e300 x' + x = 0, x(0) = 1: the float64 engines' poles overflow, and their
    x'(t) was refused ("ρ = inf": the contract's scale S₀ρ could not be formed) where the
    certified escalation serves it. Reference: the two real roots at 700 digits,
    x' = λ₁λ₂(e^{λ₁t} − e^{λ₂t})/(λ₂ − λ₁)."""
    scene = ls.Scene.from_matrices(M=[[1]], C=[["1e300"]], K=[[1]], x0=[1], v0=[0])
    times = [0.0, 1e-301, 1.0, 1e300]
    values, bounds = ls.solve(scene, method=method).evaluate(times, return_error=True,
                                                            derivative=1)
    with mpmath.workdps(700):
        c = mpmath.mpf(10) ** 300
        root = mpmath.sqrt(c * c - 4)
        slow, fast = (-c + root) / 2, (-c - root) / 2
        for j, t in enumerate(times):
            tt = mpmath.mpf(t)
            ref = slow * fast * (mpmath.exp(slow * tt) - mpmath.exp(fast * tt)) / (fast - slow)
            assert abs(values[0, j] - ref) <= bounds[0, j], (t, values[0, j], ref)
            assert bounds[0, j] <= 1e-13 * 1e300  # the contract's scale S₀ρ = 1e300


# ----------------------------------------------------------------------------- exact (mp)


def shaken_motion(times, order: int) -> list[list[arb]]:
    """x^(order)(t) of x'' + x' + x = u + u', u = sin t, from rest: the state
    (x, x', sin t, cos t) under its exact first-order matrix, by arb's exponential."""
    Z = fmpq_mat([[0, 1, 0, 0], [-1, -1, 1, 1], [0, 0, 0, 1], [0, 0, -1, 0]])
    start = fmpq_mat(4, 1, [0, 0, 0, 1])
    for _ in range(order):
        start = Z * start
    with ctx.workprec(2400):  # x'(1e-200) is about 1e-200: its own digits
        return [[((arb_mat(Z) * arb(_q(Fraction(t)))).exp() * arb_mat(start))[0, 0]
                 for t in times]]


def _outcome(sol, times, order):
    try:
        return sol.evaluate(times, return_error=True, derivative=order)
    except ls.LimitError:
        return None


@pytest.mark.parametrize("order", [0, 1])
def test_a_time_of_a_system_driven_from_rest_does_not_ride_on_the_others(order):
    """A floor moving as sin t under a spring and a dashpot, the mass at rest (S₀ = 0, so
    each value is asked to its own digits). The mp escalation measured the cancellation
    against the call's largest |x|: x'(1e-300) alone was a LimitError, but beside
    x'(1e-200) it came back as 0 with a bound of 2.6e-229, 1e71 times the value."""
    scene = ls.Scene.from_components(masses={"m": 1}, springs={"k": ("floor", "m", 1)},
                                     dashpots={"c": ("floor", "m", 1)}, x0=[0], v0=[0],
                                     support_motion={"floor": "sin(t)"})
    sol = ls.solve(scene)
    times = [1e-300, 1e-200, 1e-9, 2.5]
    alone = {t: _outcome(sol, [t], order) for t in times}
    served = [t for t in times if alone[t] is not None]
    assert served
    together = _outcome(sol, served, order)
    assert together is not None
    for j, t in enumerate(served):
        assert together[0][0, j] == alone[t][0][0, 0] and together[1][0, j] == alone[t][1][0, 0]
    assert_bounded(together[0], together[1], shaken_motion(served, order))
    for t in set(times) - set(served):  # a time refused alone is refused beside the others
        with pytest.raises(ls.LimitError):
            sol.evaluate([*served, t], return_error=True, derivative=order)


@pytest.mark.parametrize("order", [0, 1, 2])
def test_times_of_1e_300_of_a_system_driven_from_rest_are_served(order):
    """x'(1e-300) ≈ 1e-300 from pole sums of order 1 cancels about 300 digits, and x(1e-300)
    ≈ 5e-601 about 600: the mp escalation stopped at 4·digits + 200 ≈ 300 digits and refused
    (a LimitError where the exact route can serve). Its cap now counts the digits a sum of m
    exponential terms may cancel near t = 0, (m − 1)·log10(1/t). Against arb at 2,400 bits."""
    scene = ls.Scene.from_components(masses={"m": 1}, springs={"k": ("floor", "m", 1)},
                                     dashpots={"c": ("floor", "m", 1)}, x0=[0], v0=[0],
                                     support_motion={"floor": "sin(t)"})
    times = [1e-300, 1e-250, 1e-30]
    values, bounds = ls.solve(scene).evaluate(times, return_error=True, derivative=order)
    assert_bounded(values, bounds, shaken_motion(times, order))


def test_a_value_beyond_float64_is_an_overflow_with_the_digits_way_out() -> None:
    """Four masses with non-symmetric damping and a pole at 7.45: x(150) is about 6e484.
    The certified and exact routes gave value 0 with an infinite bound for it (their float64
    pole sums overflow to inf − inf), which the executor kept over the escalation's ±inf,
    so evaluate said no engine could bound it (a LimitError) where it is an OverflowError
    whose message names dps=; the digits are the arb reference's."""
    M = [["86/77", 0, 0, 0], [0, "24/49", 0, 0], [0, 0, "97/96", 0], [0, 0, 0, "32/45"]]
    C = [["13/6200", 0, 0, "-74/3"], [0, 0, "47/81", 0], ["-91/48", 0, 0, "-6/5"],
         [0, 0, "-51/5", 0]]
    K = [["383/30", "-1/10", 0, 0], ["-1/10", "263/30", "-26/3", 0],
         [0, "-26/3", "114/7", "-160/21"], [0, 0, "-160/21", "16475/798"]]
    scene = ls.Scene.from_matrices(M=M, C=C, K=K, x0=["-1/2", 4, "4/3", 4],
                                   v0=["-4/3", "4/3", "-1/2", 5])
    for method in ("auto", "certified", "exact", "modal"):
        with pytest.raises(OverflowError, match=r"t = 150.0 is beyond the float64 range; "
                                                r"evaluate\(\.\.\., dps=30\)"):
            ls.solve(scene, method=method).evaluate([1.0, 150.0])
    digits = ls.solve(scene).evaluate([150.0], dps=20)
    reference = motion(scene, [150])
    with mpmath.workdps(40):
        for i in range(4):
            exact = mpmath.mpf(reference[i][0].mid().str(35, radius=False))
            assert abs(digits[i, 0] - exact) <= mpmath.mpf("1e-18") * abs(exact)


def test_a_growing_motion_far_out_is_an_overflow_without_thousands_of_digits(monkeypatch) -> None:
    """Negative-definite damping (C = [[0, -1/7, 0], [-1/7, 0, 37], [0, 37, 0]]) grows like
    e^{21.8 t}: at t = 2e4, x is about 1e189444. The exact route's escalation measured the
    digits its pole sum "cancelled" against the floor S₀ instead of max(|x(t)|, S₀), took
    e^{436000} of growth for 189,000 lost digits and worked at up to 37,933 digits (t = 4e3:
    13 s; t = 2e4: 278 s) before saying OverflowError. Now the overflow is said at once, and
    dps=30 gives the digits of an mpmath eigen-decomposition at 80 digits (no cancellation:
    one growing mode dominates)."""
    scene = ls.Scene.from_matrices(
        M=[["7/5", 0, 0], [0, "7/3", 0], [0, 0, "6/5"]],
        C=[[0, "-1/7", 0], ["-1/7", 0, 37], [0, 37, 0]],
        K=[["11/4", 0, 0], [0, "41/4", 0], [0, 0, "21/2"]],
        x0=["3/100000000000000000", 1, 1], v0=[0, 1, 0])
    sol = ls.solve(scene)
    worked: list[int] = []
    original = terms._mp_values

    def spy(*args, **kw):
        out = original(*args, **kw)
        worked.append(out[2])
        return out

    monkeypatch.setattr(terms, "_mp_values", spy)
    for t in (1e3, 4e3, 2e4):
        with pytest.raises(OverflowError, match=r"beyond the float64 range; evaluate\(\.\.\., dps=30\)"):
            sol.evaluate([t], target=1e-10)
    assert worked and max(worked) < 100  # digits of working precision (37,933 before)
    digits = sol.evaluate([2e4, 7.5], dps=30)
    with mpmath.workdps(80):
        third = mpmath.mpf(1) / 3
        M = mpmath.diag([mpmath.mpf(7) / 5, 7 * third, mpmath.mpf(6) / 5])
        C = mpmath.matrix([[0, -mpmath.mpf(1) / 7, 0], [-mpmath.mpf(1) / 7, 0, 37], [0, 37, 0]])
        K = mpmath.diag([mpmath.mpf(11) / 4, mpmath.mpf(41) / 4, mpmath.mpf(21) / 2])
        A, B = M ** -1 * K, M ** -1 * C
        Z = mpmath.zeros(6, 6)
        for i in range(3):
            Z[i, 3 + i] = 1
            for j in range(3):
                Z[3 + i, j], Z[3 + i, 3 + j] = -A[i, j], -B[i, j]
        w, V = mpmath.eig(Z)
        c = mpmath.lu_solve(V, mpmath.matrix([mpmath.mpf(3) / 10**17, 1, 1, 0, 1, 0]))
        for k, t in enumerate((20000, mpmath.mpf(15) / 2)):
            for i in range(3):
                exact = mpmath.re(sum(V[i, m] * c[m] * mpmath.exp(w[m] * t) for m in range(6)))
                assert abs(digits[i, k] - exact) <= mpmath.mpf("1e-28") * abs(exact)
