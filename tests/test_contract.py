"""The result contract on every route, and the failure classes issue 10 reported.

Every value is checked against python-flint's certified arb matrix exponential of the
first-order system (reference_motion_arb) or a textbook formula in mpmath: the error is
within the target of max(‖x(t)‖∞, S₀), or the returned bound says otherwise; the bound is
finite and never below the true error; a value does not depend on the other times of
the call.
"""

from __future__ import annotations

from itertools import pairwise

import mpmath
import numpy as np
import pytest

import laplace_springs as ls
from laplace_springs.bench.reference import reference_motion_arb
from laplace_springs.limits import limits
from laplace_springs.planning import ENGINE_NAMES, FAMILIES

ROUTES = ("exact", "modal", "certified")


def _true_error(values: np.ndarray, reference: np.ndarray) -> np.ndarray:
    with mpmath.workdps(60):
        return np.array([[float(abs(mpmath.mpf(v) - r)) for v, r in zip(row, ref_row)]
                         for row, ref_row in zip(values, reference)])


def check_contract(sol, scene, times, *, tolerance=1e-10):
    """Values within ``tolerance`` of max|x| (or bounded), bounds finite and honest."""
    values, bounds = sol.evaluate(times, return_error=True)
    reference = reference_motion_arb(scene, list(times), digits=40)
    error = _true_error(values, reference)
    scale = max(float(abs(r)) for r in reference.ravel())
    assert np.all(np.isfinite(values)) and np.all(np.isfinite(bounds))
    assert np.all(error <= bounds), f"bound below the true error: {np.max(error / bounds):.2f}x"
    assert error.max() <= tolerance * scale or np.all(bounds >= error)
    return values, bounds, error / scale


def free_free_three_masses() -> ls.Scene:
    """The undamped free-free 3-mass chain of the issue (springs 441/5 and 23925123/2500)."""
    return ls.Scene.from_matrices(
        M=[["401/5000", 0, 0], [0, "9/625", 0], [0, 0, "39/50"]],
        K=[["441/5", "-441/5", 0], ["-441/5", "24145623/2500", "-23925123/2500"],
           [0, "-23925123/2500", "23925123/2500"]],
        x0=["-199/500", "301/500", "737/1000"], v0=["-33/125", 0, 0])


def chain(n, springs=("1",), dashpots=("0",), masses=("1",), walls=True) -> ls.Scene:
    names = [f"m{i + 1}" for i in range(n)]
    nodes = ["wall", *names, "wall"] if walls else names
    links = list(pairwise(nodes))
    return ls.Scene.from_components(
        masses={m: masses[i % len(masses)] for i, m in enumerate(names)},
        springs={f"k{i}": (a, b, springs[i % len(springs)]) for i, (a, b) in enumerate(links)},
        dashpots={f"c{i}": (a, b, dashpots[i % len(dashpots)]) for i, (a, b) in enumerate(links)
                  if dashpots[i % len(dashpots)] != "0"},
        x0={names[0]: 1, names[-1]: "-1/3"}, v0={names[n // 2]: "1/2"})


# ------------------------------------------------------------------ failure classes of issue 10


@pytest.mark.parametrize("method", ["modal", "auto"])
def test_free_free_chain_over_a_long_horizon(method):
    # the modal route used to return x1 = 9566.19 with a NaN estimate at t = 29·344064
    # (true -241549.3469), and a value that depended on the other times of the call
    scene = free_free_three_masses()
    times = np.array([344064.0 * k for k in (0, 1, 4, 13, 29)])
    sol = ls.solve(scene, method=method)
    values, _, relative = check_contract(sol, scene, times)
    assert relative.max() <= 1e-10
    assert values[0, -1] == pytest.approx(-241549.3469, abs=1e-3)
    alone = sol.evaluate(times[2:3])[0, 0]  # alone or with others: the same value
    assert abs(alone - values[0, 2]) <= 4 * np.finfo(float).eps * abs(values[0, 2])


def test_heavily_damped_scene_with_one_very_soft_spring():
    scene = chain(4, springs=("1000", "1e-6", "250", "40", "900"), dashpots=("30", "0.5", "100"),
                  masses=("0.01", "2", "0.3"))
    for method in ("modal", "auto"):
        check_contract(ls.solve(scene, method=method), scene, [0.0, 1e-3, 0.5, 30.0, 2e4, 1e6])


def test_two_identical_free_free_chains_of_nine_masses():
    # 18 coordinates, every frequency double: the default route's estimates used to climb
    # to 5e287 and then NaN with errors of 1e-3
    one = chain(9, springs=("3", "7", "2"), masses=("1", "2"), walls=False)
    n = one.n
    M = [[one.M[i % n, j % n] if i // n == j // n else 0 for j in range(2 * n)] for i in range(2 * n)]
    K = [[one.K[i % n, j % n] if i // n == j // n else 0 for j in range(2 * n)] for i in range(2 * n)]
    x0 = [1] + [0] * (n - 1) + ["-1/2"] + [0] * (n - 1)
    v0 = [0] * (2 * n - 1) + ["1/5"]
    scene = ls.Scene.from_matrices(M=M, K=K, x0=x0, v0=v0)
    sol = ls.solve(scene)
    _, _, relative = check_contract(sol, scene, [0.0, 2.5, 100.0, 1e4, 1e6])
    assert relative.max() <= 1e-10


@pytest.mark.parametrize("seed", range(4))
def test_heavily_damped_stiff_scenes_on_the_modal_route(seed):
    # the modal estimate used to sit 2-3x below the true error here
    rng = np.random.default_rng(seed)
    def draw(low, high, k):
        return [f"{10 ** rng.uniform(low, high):.3g}" for _ in range(k)]
    n = int(rng.integers(3, 6))
    scene = chain(n, springs=draw(-2, 5, n + 1), dashpots=draw(0, 4, n + 1), masses=draw(-2, 1, n))
    slow = min(abs(p) for p in ls.solve(scene, method="modal").poles)
    times = np.concatenate([[0.0], np.geomspace(1e-4, 30 / slow, 12)])
    check_contract(ls.solve(scene, method="modal"), scene, times)


def test_exact_route_at_huge_phases():
    # x'' + 2x = 0, x(0) = 1: the estimate stayed 1.8e-15 while the error reached 4e-3
    sol = ls.solve(ls.Scene.from_matrices(M=[[1]], K=[[2]], x0=[1], v0=[0]), method="exact")
    times = [1e18, 1e20, 1e25, 1e30]
    values, bounds = sol.evaluate(times, return_error=True)
    with mpmath.workdps(80):
        exact = np.array([float(mpmath.cos(mpmath.sqrt(2) * mpmath.mpf(tv))) for tv in times])
    assert np.all(np.abs(values[0] - exact) <= bounds[0]) and bounds.max() <= 1e-13


@pytest.mark.parametrize("exponent", [94, 100, 200])
def test_exact_route_with_a_stiffness_of_ten_to_the(exponent):
    # x'' + 10^94 x = 0 gave the wrong sign at t = 1
    sol = ls.solve(ls.Scene.from_matrices(M=[[1]], K=[[f"1e{exponent}"]], x0=[1], v0=[0]),
                   method="exact")
    values = sol.evaluate([0.0, 1.0])
    with mpmath.workdps(exponent // 2 + 40):
        exact = float(mpmath.cos(mpmath.mpf(10) ** (exponent // 2)))
    assert values[0, 0] == 1.0 and abs(values[0, 1] - exact) <= 1e-13


@pytest.mark.parametrize("exponent", [160, 300])
def test_modal_route_scales_stiffnesses_beyond_float64(exponent):
    # the modal route returned x(0) = 0 for K = 1e160
    scene = ls.Scene.from_matrices(M=[[1]], K=[[f"1e{exponent}"]], x0=[1], v0=[0])
    values, bounds = ls.solve(scene, method="modal").evaluate([0.0, 1.0], return_error=True)
    with mpmath.workdps(exponent // 2 + 40):
        exact = float(mpmath.cos(mpmath.mpf(10) ** (exponent // 2)))
    assert values[0, 0] == 1.0 and abs(values[0, 1] - exact) <= max(bounds[0, 1], 1e-13)


def test_auto_keeps_a_float64_engine_for_an_eight_mass_damped_chain():
    # the exact route took 2.75 s where the float64 engines meet the contract in milliseconds
    scene = chain(8, springs=("1",), dashpots=("1/20",))
    sol = ls.solve(scene)
    assert sol.method in ("classical", "chebyshev", "modal", "certified")
    check_contract(sol, scene, np.linspace(0, 20, 9), tolerance=limits().target)


# ------------------------------------------------------------------ the contract on every route


SCENES = {
    "three-dashpots": lambda: ls.load_scene("three-dashpots"),
    "critical": lambda: ls.Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[-3]),
    "free-free": lambda: chain(3, springs=("2", "5"), walls=False),
    "stiff": lambda: chain(4, springs=("1", "1e7"), dashpots=("1/10",)),
}


@pytest.mark.parametrize("method", ROUTES)
@pytest.mark.parametrize("name", sorted(SCENES))
def test_every_route_honours_the_contract(name, method):
    scene = SCENES[name]()
    sol = ls.solve(scene, method=method)
    assert sol.method in FAMILIES.get(method, (method,)) and isinstance(sol, ls.Solution)
    times = np.array([0.0, 0.37, 2.0, 15.0, 300.0])
    values, _, relative = check_contract(sol, scene, times)
    assert relative.max() <= limits().target
    for k, tv in enumerate(times):  # one time at a time: the same values, up to the rounding
        alone = sol.evaluate([tv])[:, 0]  # of vectorised exp/cos and BLAS kernels of other shapes
        assert np.max(np.abs(alone - values[:, k])) <= 1e-14 * np.max(np.abs(values[:, k]))


@pytest.mark.parametrize("method", ROUTES)
def test_derivatives_on_every_route(method):
    # x'' + 0.2x' + 4x = 0, x(0) = 1: textbook derivatives of e^{-t/10}(cos ωt + sin(ωt)/(10ω))
    scene = ls.Scene.from_matrices(M=[[1]], C=[["0.2"]], K=[[4]], x0=[1], v0=[0])
    sol = ls.solve(scene, method=method)
    times = [0.0, 0.5, 3.0]
    with mpmath.workdps(40):
        w = mpmath.sqrt(mpmath.mpf(4) - mpmath.mpf("0.01"))
        def x(t):
            return mpmath.exp(-t / 10) * (mpmath.cos(w * t) + mpmath.sin(w * t) / (10 * w))
        for order in (1, 2):
            values, bounds = sol.evaluate(times, derivative=order, return_error=True)
            exact = [float(mpmath.diff(x, mpmath.mpf(tv), order)) for tv in times]
            assert np.all(np.abs(values[0] - exact) <= bounds[0] + 1e-30)
            assert np.max(np.abs(values[0] - exact)) <= 1e-12


@pytest.mark.parametrize("method", ROUTES)
def test_digits_come_with_their_bound(method):
    scene = ls.load_scene("wall-pair-dashpot")
    values, bounds = ls.solve(scene, method=method).evaluate(["0.5", "2.25", "10"], dps=40,
                                                                return_error=True)
    reference = reference_motion_arb(scene, ["0.5", "2.25", "10"], digits=50)
    with mpmath.workdps(60):
        for v, b, r in zip(values.ravel(), bounds.ravel(), reference.ravel()):
            assert isinstance(v, mpmath.mpf) and abs(v - r) <= b <= mpmath.mpf(10) ** -39


def test_a_float_time_is_its_binary_value_on_every_route():
    # 0.1 is 0.1000000000000000055...: at ω = 1e8 the decimal and the binary time differ
    # by a phase of 5.5e-10; every route must evaluate the same instant
    scene = ls.Scene.from_matrices(M=[[1]], K=[["1e16"]], x0=[1], v0=[0])
    with mpmath.workdps(60):
        binary = float(mpmath.cos(mpmath.mpf(10) ** 8 * mpmath.mpf(0.1)))
        decimal = float(mpmath.cos(mpmath.mpf(10) ** 8 / 10))
    for method in ROUTES:
        sol = ls.solve(scene, method=method)
        assert abs(sol.evaluate([0.1])[0, 0] - binary) <= 1e-13
        assert abs(sol.evaluate(["0.1"])[0, 0] - decimal) <= 1e-13
        assert abs(float(sol.evaluate([0.1], dps=30)[0, 0]) - binary) <= 1e-15


def test_target_is_a_parameter():
    scene = ls.Scene.from_matrices(M=[[1]], C=[["1e-6"]], K=[[1]], x0=[1], v0=[0])
    sol = ls.solve(scene, target=1e-6)
    assert sol.target == 1e-6
    values, bounds = sol.evaluate([1e9], return_error=True)  # phase 1e9: float64 bound ~1e-7
    assert bounds[0, 0] <= 1e-6 * max(1.0, abs(values[0, 0]))
    values, bounds = sol.evaluate([1e9], return_error=True, target=1e-13)
    assert bounds[0, 0] <= 1e-13
    with pytest.raises(ValueError, match="target"):
        ls.solve(scene, target=2.0)


@pytest.mark.parametrize("bad", [[float("nan")], [float("inf")], [-1.0], ["abc"], [1 + 2j]])
def test_bad_times_are_refused_on_every_route(bad):
    scene = ls.load_scene("vertical-pair")
    for method in ROUTES:
        with pytest.raises(ValueError, match=r"times\[0\]"):
            ls.solve(scene, method=method).evaluate(bad)


@pytest.mark.parametrize("dps", [0, -5, 10**6, 2.5, True])
def test_bad_precisions_are_refused(dps):
    with pytest.raises(ValueError, match="dps"):
        ls.solve(ls.load_scene("vertical-pair")).evaluate([1.0], dps=dps)


def test_verify_has_one_signature():
    scene = ls.load_scene("vertical-pair-damped")
    for method in ROUTES:
        report = ls.solve(scene, method=method).verify(samples=("0.5", "2"), tolerance=1e-9)
        assert report and report.tolerance == 1e-9


def test_auto_picks_the_fastest_route_and_keeps_the_exact_form_at_hand():
    small = ls.solve(ls.load_scene("three-dashpots"))  # rational, 2 coordinates
    assert small.method in ENGINE_NAMES and "cheapest engine" in small.reason
    exact = ls.solve(ls.load_scene("three-dashpots"), method="exact")
    assert small.x == exact.x and small.g_basis == exact.g_basis  # built when asked
    forced = ls.solve(ls.load_scene("vertical-pair").with_forcing(["cos(t)", 0]))
    assert forced.method == "exact"
    symbolic = ls.solve(ls.Scene.from_matrices(M=[[1]], K=[["k"]], x0=[1], v0=[0], parameters=["k"]))
    assert symbolic.method == "exact"


@pytest.mark.parametrize("method", ["exact", "certified"])
def test_a_value_that_cancels_to_zero_keeps_an_honest_bound(method):
    # x4(0) = 0 is the sum of pole-sum coefficients of size 0.27: the float64 kernel gets
    # -2.9e-42 from the 40-digit data, and its bound used to be 1e-56 (relative to the
    # cancelled Newton coefficient instead of the data it came from)
    scene = ls.Scene.from_matrices(
        M=[["299/100", 0, 0, 0], [0, "191/50000", 0, 0], [0, 0, "51/5", 0], [0, 0, 0, "517/1000"]],
        K=[["699", "-699", 0, 0], ["-699", "69900123/100000", "-123/100000", 0],
           [0, "-123/100000", "3473/100000", "-67/2000"], [0, 0, "-67/2000", "67/2000"]],
        x0=["67/500", 0, "-99/250", 0], v0=[0, "-39/50", "-183/1000", "897/1000"])
    check_contract(ls.solve(scene, method=method), scene, [0.0, 0.01, 3.0, 1e4])
