"""The planner: decisions from facts and requests (pure), execution with per-time escalation,
typed refusals, limits, provenance, progress and interruption. Values are checked against
independent references (arb matrix exponentials, analytic solutions)."""

from __future__ import annotations

import importlib
import io
import math
import re
import sys

import mpmath
import numpy as np
import pytest

import laplace_springs as ls
from laplace_springs.bench.reference import reference_motion_arb
from laplace_springs.limits import using_limits
from laplace_springs.numeric.times import as_times
from laplace_springs.planning import Refusal, Request, SceneFacts, execute, plan
from laplace_springs.planning.engines import Cost
from laplace_springs.planning.facts import Quote
from laplace_springs.planning.plan import Plan

RAYLEIGH = {"symbolic": False, "forced": False, "rational": True, "first_order": True,
            "classical": True, "rayleigh": True, "krylov": True, "diagonal_mass": True,
            "stiffness_bound": 4.0, "pole_bound": 2.1,
            "quotes": (Quote("refined", None, 0.05, 2e-4),)}


def chain(n: int, *, k=1, c=None, walls=True, extra=None) -> ls.Scene:
    masses = {f"m{i}": 1 for i in range(n)}
    springs = {f"k{i}": (f"m{i-1}", f"m{i}", k) for i in range(1, n)}
    dashpots = {f"c{i}": (f"m{i-1}", f"m{i}", c) for i in range(1, n)} if c else {}
    if walls:
        springs |= {"left": ("wall", "m0", k), "right": (f"m{n-1}", "wall", k)}
    if extra:
        dashpots["extra"] = ("wall", "m0", extra)
    return ls.Scene.from_components(masses=masses, springs=springs, dashpots=dashpots,
                                    x0=[1] + [0] * (n - 1), v0=[0] * n)


# ----------------------------------------------------------------------------- pure decisions


def test_a_large_rayleigh_chain_takes_chebyshev_and_escalates_to_tighter_engines():
    facts = SceneFacts(n=2_000, nnz=6_000, **RAYLEIGH)
    chosen = plan(facts, Request(count=100, t_max=50.0))
    assert chosen.primary == "chebyshev"
    assert "certified" not in chosen.chain  # 2n = 4,000 > Limits.certified_max_order
    declined = {r.engine: r for r in chosen.refusals}
    assert declined["certified"].limit == "certified_max_order"


def test_chebyshev_serves_times_up_to_its_memory_horizon_and_another_engine_the_rest():
    facts = SceneFacts(n=2_000, nnz=6_000, **RAYLEIGH)
    with using_limits(chebyshev_max_vector_floats=2_000_000):
        chosen = plan(facts, Request(count=10, t_max=1e4), method="chebyshev")
        horizon = chosen.horizons["chebyshev"]
    assert chosen.primary == "chebyshev" and horizon < 1e4
    # the degree that fits: 2·n·(N + 1) floats with N = t·√ν/2 + 40
    assert horizon == pytest.approx((2_000_000 / 4_000 - 41 - 40) * 2 / 2.0)
    assert len(chosen.chain) > 1  # escalation for the times beyond


def test_long_horizons_choose_an_engine_whose_cost_does_not_grow_with_t():
    facts = SceneFacts(n=200, nnz=600, **RAYLEIGH)
    short, long = plan(facts, Request(count=10, t_max=10.0)), plan(facts, Request(count=2, t_max=1e6))
    assert short.primary == "chebyshev"
    assert long.primary == "refined"  # Chebyshev's degree and krylov's steps grow like t
    assert long.costs["refined"].seconds < long.costs["chebyshev"].seconds


def test_digits_come_only_from_arbitrary_precision_engines():
    facts = SceneFacts(n=2, nnz=6, **RAYLEIGH)
    chosen = plan(facts, Request(count=3, t_max=1.0, dps=30), method="classical")
    assert chosen.chain and all(name in ("ball", "mp") for name in chosen.chain)
    big = plan(SceneFacts(n=300, nnz=900, **RAYLEIGH), Request(dps=30))
    assert big.chain == () and "no engine serves" in big.reason


def test_refusals_are_values_with_the_limit_they_name():
    facts = SceneFacts(n=5_000, nnz=15_000, **(RAYLEIGH | {"rayleigh": False}))
    chosen = plan(facts, Request(), method="classical")
    assert chosen.chain == ()
    (refusal,) = [r for r in chosen.refusals if r.engine == "classical"]
    assert isinstance(refusal, Refusal) and refusal.limit == "classical_max_coordinates"
    with using_limits(classical_max_coordinates=10_000):
        assert plan(facts, Request(), method="classical").primary == "classical"


def test_symbolic_and_forced_scenes_go_to_the_exact_engine():
    symbolic = SceneFacts(n=2, symbolic=True, forced=False, rational=False, first_order=False)
    forced = SceneFacts(n=2, symbolic=False, forced=True, rational=True, first_order=True)
    assert plan(symbolic, Request()).primary == "exact"
    assert plan(forced, Request()).primary == "exact"


def test_a_named_method_restricts_the_primary_and_keeps_escalation_open():
    facts = SceneFacts(n=4, nnz=12, **RAYLEIGH)
    chosen = plan(facts, Request(count=5, t_max=100.0), method="modal")
    assert chosen.primary in ("classical", "chebyshev", "modal")
    assert "ball" in chosen.chain  # a time whose bound misses still goes to ball arithmetic
    with pytest.raises(ValueError, match="method must be one of"):
        plan(facts, Request(), method="fastest")


def test_escalations_go_to_the_cheapest_engine_that_meets_the_target_in_a_fixed_order():
    """Times the primary misses go first to the cheapest engine that reaches further and is
    expected to meet the target (krylov's 0.1 s before refined's seconds here), and the order
    is the scene's: the same for every request, so a time's engine never depends on the other
    times of a call."""
    facts = SceneFacts(n=1_000, nnz=7_000, **{**RAYLEIGH, "quotes": (Quote("refined", None, 2.5, 2e-3),)})
    plans = [plan(facts, Request(count=100, t_max=t)) for t in (1.0, 50.0, 2e4)]
    assert plans[0].primary == "chebyshev"
    assert plans[0].chain.index("krylov") < plans[0].chain.index("refined")
    assert plans[0].chain == plans[1].chain == plans[2].chain[:len(plans[0].chain)]


def test_the_modal_engine_is_expected_to_miss_while_a_light_mode_is_alive():
    """The modal engine's bound grows with t while the slowest mode is alive (its rate at
    most the poles' mean decay tr(M⁻¹C)/2n): a lightly damped non-classical network goes to
    krylov for long horizons and keeps modal for short ones; a heavily damped one keeps it."""
    light = SceneFacts(n=20, nnz=80, **{**RAYLEIGH, "classical": False, "rayleigh": False,
                                         "pole_bound": 8.0, "mean_decay": 0.02})
    heavy = SceneFacts(n=20, nnz=80, **{**RAYLEIGH, "classical": False, "rayleigh": False,
                                         "pole_bound": 8.0, "mean_decay": 1.0})
    expects = ls.planning.engines.engine("modal").expectation
    assert expects(light, Request(count=100, t_max=1.0)) is None
    assert "expected to miss" in expects(light, Request(count=100, t_max=50.0))
    assert expects(heavy, Request(count=100, t_max=50.0)) is None
    assert plan(light, Request(count=100, t_max=50.0)).primary == "krylov"
    assert plan(heavy, Request(count=100, t_max=50.0)).primary == "modal"


def test_the_mean_decay_of_the_facts_is_that_of_the_poles():
    """facts.mean_decay against −mean(Re λ) of NumPy's eigenvalues of the first-order matrix."""
    scene = ls.Scene.from_components(
        masses={"a": 1, "b": "2", "c": "1/2"},
        springs={"k0": ("wall", "a", 3), "k1": ("a", "b", 1), "k2": ("b", "c", 2),
                 "k3": ("c", "wall", 1), "k4": ("a", "c", "1/2")},
        dashpots={"c0": ("a", "b", "1/10"), "c1": ("c", "wall", "3/10")},
        x0=[1, 0, 0], v0=[0, 0, 0])
    facts = ls.planning.facts.scene_facts(scene, "modal")
    M, C, K = (np.array(m, dtype=float) for m in (scene.M, scene.C, scene.K))
    Z = np.block([[np.zeros((3, 3)), np.eye(3)],
                  [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    assert math.isclose(facts.mean_decay, -np.linalg.eigvals(Z).real.mean(), rel_tol=1e-12)


def test_a_tiny_scene_leaves_its_damping_class_unasked_until_an_engine_needs_it():
    """The seed's Example 2 pair (C = M/5: Rayleigh, classical). Auto plans without the
    exact damping check; a named symmetric engine asks it and serves, with the values the
    tiny engine gives (both within their bounds of each other)."""
    scene = ls.load_scene("vertical-pair-damped")
    auto = ls.solve(scene)
    assert auto.method == "tiny" and not {"classical", "chebyshev"} & set(auto.plan().chain)
    times = [0.0, 0.5, 3.0]
    values, bounds = auto.evaluate(times, return_error=True)
    for method in ("classical", "chebyshev", "modal"):
        named = ls.solve(ls.load_scene("vertical-pair-damped"), method=method)
        assert named.method in ("classical", "chebyshev")
        other, other_bounds = named.evaluate(times, return_error=True)
        assert np.all(np.abs(values - other) <= bounds + other_bounds)
    way_out = ls.plan(scene).refusals
    assert any("method='classical'" in r.reason for r in way_out if r.engine == "classical")


# ----------------------------------------------------------------------------- execution


def _fake_plan(chain, horizons=None) -> Plan:
    return Plan(Request(), "auto", tuple(chain), horizons or {},
                {name: Cost(0.0, 0.0) for name in chain}, reason="test")


def test_execution_mixes_engines_per_time_and_reports_which():
    times = as_times([0.5, 2.0, 50.0])
    truth = np.cos(times.hi)[None, :]

    def coarse(T, order, target):  # serves only up to t = 10 (its horizon)
        assert np.all(T.hi <= 10)
        return np.cos(T.hi)[None, :], np.where(T.hi > 1, 1e-6, 1e-17)[None, :]

    def fine(T, order, target):
        return np.cos(T.hi)[None, :], np.full((1, len(T)), 1e-17)

    values, bounds, report = execute(_fake_plan(["coarse", "fine"], {"coarse": 10.0}),
                                     {"coarse": coarse, "fine": fine}.__getitem__, times, 1, 0,
                                     1e-13, 1.0, progress=False)
    assert report.engines == ("coarse", "fine", "fine")  # t = 2 escalated, t = 50 beyond horizon
    assert np.array_equal(values, truth) and np.all(bounds <= 1e-16)
    assert report.counts() == {"coarse": 1, "fine": 2}


def test_a_refusal_found_while_building_skips_that_engine():
    times = as_times([1.0])

    def good(T, order, target):
        return np.ones((1, len(T))), np.zeros((1, len(T)))

    build = {"broken": Refusal("broken", "singular"), "good": good}.__getitem__
    _, _, report = execute(_fake_plan(["broken", "good"]), build, times, 1, 0, 1e-13, 1.0,
                           progress=False)
    assert report.engines == ("good",) and report.refusals[0].reason == "singular"


def test_progress_is_shown_for_long_plans():
    stream = io.StringIO()
    execute_module = sys.modules["laplace_springs.planning.execute"]
    original = execute_module.Progress
    execute_module.Progress = lambda *a, **k: original(*a, **(k | {"stream": stream}))
    try:
        sol = ls.solve(chain(3, c="1/10"))
        with using_limits(progress_after_seconds=0.0):
            sol.evaluate(np.linspace(0, 5, 11))
    finally:
        execute_module.Progress = original
    assert "evaluations in" in stream.getvalue()


def test_ctrl_c_leaves_the_solution_usable():
    sol = ls.solve(chain(6, c="1/10", extra="1/5"))
    times = np.linspace(0, 20, 60)
    expected = sol.evaluate(times)
    calls = {"n": 0}
    original = sol._evaluator

    def interrupting(name):
        evaluator = original(name)

        def run(T, order, target):
            calls["n"] += 1
            if calls["n"] == 2:
                raise KeyboardInterrupt
            return evaluator(T, order, target)
        return run

    sol._evaluator = interrupting  # type: ignore[method-assign]
    with using_limits(evaluation_chunk_values=6 * 10), pytest.raises(KeyboardInterrupt):
        sol.evaluate(times)
    del sol._evaluator
    assert np.array_equal(sol.evaluate(times), expected)


def test_an_evaluation_beyond_the_size_limit_is_refused_with_the_way_out():
    sol = ls.solve(chain(3))
    with using_limits(max_evaluation_values=100), pytest.raises(ls.LimitError, match="chunks of at most 33"):
        sol.evaluate(np.linspace(0, 1, 40))


def test_values_no_engine_can_bound_are_refused_not_returned():
    sol = ls.solve(chain(3))

    def hopeless(T, order, target):
        return np.full((3, len(T)), 1e3), np.full((3, len(T)), 1e5)

    sol.__dict__["_evaluators"] = dict.fromkeys(sol.plan([1.0]).chain, hopeless)
    sol.motion.bound_until = lambda t_max: np.inf  # its own bound as hopeless: no values alone
    with pytest.raises(ls.LimitError, match="Limits.refusal_bound"):
        sol.evaluate([1.0])
    with pytest.raises(ls.LimitError):
        sol.evaluate([1.0], return_error=True)


# ----------------------------------------------------------------------------- real scenes


def test_two_free_free_rayleigh_chains_far_out_are_served_by_auto():
    """Two identical free-free 9-mass chains (rigid modes, repeated eigenvalues, Rayleigh
    damping) at t up to 1e7: Chebyshev would need 2 x 3e8 vectors; auto serves it."""
    one = {f"a{i}": 1 for i in range(9)} | {f"b{i}": 1 for i in range(9)}
    springs = {f"ka{i}": (f"a{i-1}", f"a{i}", 1) for i in range(1, 9)}
    springs |= {f"kb{i}": (f"b{i-1}", f"b{i}", 1) for i in range(1, 9)}
    dashpots = {f"c{name[1:]}": (a, b, "1/1000") for name, (a, b, _) in springs.items()}
    scene = ls.Scene.from_components(masses=one, springs=springs, dashpots=dashpots,
                                     x0=[1] + [0] * 17, v0=[0] * 9 + ["1/2"] + [0] * 8)
    times = [0.0, 3.5, 1234.5, 9.87e6]
    values, bounds, report = ls.solve(scene).evaluate(times, return_error=True, return_report=True)
    reference = np.array(reference_motion_arb(scene, times, digits=25), dtype=float)
    error = np.abs(values - reference)
    assert np.all(error <= bounds)
    assert error.max() <= 1e-13 * max(1.0, np.abs(reference).max())
    assert set(report.engines) <= set(ls.planning.ENGINE_NAMES)


def test_a_long_horizon_on_a_small_undamped_scene_keeps_its_phase():
    scene = ls.Scene.from_matrices(M=[[1]], K=[[2]], x0=[1], v0=[0])
    times = [1e6, 1e9, 123456789.125]
    values, bounds = ls.solve(scene).evaluate(times, return_error=True)
    with mpmath.workdps(50):
        exact = [float(mpmath.cos(mpmath.sqrt(2) * mpmath.mpf(t))) for t in times]
    assert np.all(np.abs(values[0] - exact) <= bounds[0]) and np.max(bounds) <= 1e-13


def test_the_plan_is_inspectable_without_evaluating():
    scene = chain(200)
    shown = str(ls.plan(scene, [0.0, 1.0]))
    assert "chebyshev" in shown and "declined" in shown and "certified_max_order" in shown
    sol = ls.solve(chain(2, c="1/10"))
    assert sol.plan([1.0]).primary == sol.method and math.isfinite(sol.plan().seconds)


def test_the_tiny_scenes_facts_from_the_exact_reading_are_the_general_ones():
    facts = importlib.import_module("laplace_springs.planning.facts")
    taken = [
        ls.Scene.from_matrices(M=[[1]], C=[["1/10"]], K=[[4]], x0=[1], v0=[0]),
        ls.Scene.from_matrices(M=[[2]], K=[[8]], x0=[0], v0=["1/3"]),
        ls.load_scene("vertical-pair-damped"),
        ls.Scene.from_matrices(M=[[2, 1], [1, 3]], C=[[1, 0], [0, 0]], K=[[2, -1], [-1, 2]],
                               x0=[1, 0], v0=[0, 0]),
        ls.Scene.from_matrices(M=[[1, 0, 0], [0, 2, 0], [0, 0, 3]], K=[[2, -1, 0], [-1, 2, -1],
                               [0, -1, 1]], x0=[1, 0, 0], v0=[0, 0, "0.5"]),
    ]
    for scene in taken:
        quick = facts._tiny_facts(scene)
        assert quick is not None and quick == facts._general_facts(scene)
    eye = [[int(i == j) for j in range(5)] for i in range(5)]
    refused = [
        ls.Scene.from_matrices(M=eye, K=eye, x0=[1, 0, 0, 0, 0], v0=[0] * 5),
        ls.Scene.from_matrices(M=[[1]], K=[["k"]], x0=[1], v0=[0], parameters=["k"]),
        ls.Scene.from_matrices(M=[[1]], K=[[4]], x0=[1], v0=[0], forcing=["cos(t)"]),
        ls.Scene.from_matrices(M=[[1, 0], [0, 0]], C=[[0, 0], [0, 1]], K=[[2, -1], [-1, 1]],
                               x0=[0, 0], v0=[0, 0]),
        ls.Scene.from_matrices(M=[[1]], K=[["1e300"]], x0=[1], v0=[0]),
    ]
    for scene in refused:
        assert facts._tiny_facts(scene) is None


@pytest.mark.parametrize("method", ["classical", "exo"])
def test_the_way_out_a_refusal_names_serves_the_scene(method):
    """Five free masses (K = 0): method='classical' refuses at build time (a zero frequency)
    and the refusal named 'classical' itself, or the plan's next engine, as the way out
    without trying it. The engine it names now takes the scene; its values follow
    x = x0 + v0·t exactly."""
    n = 5
    scene = ls.Scene.from_matrices(M=[[int(i == j) for j in range(n)] for i in range(n)],
                                K=[[0] * n for _ in range(n)], x0=[1, 2, 3, 4, 5],
                                v0=[1, -1, 0, 0, "1/2"])
    with pytest.raises(ls.SceneError) as refused:
        ls.solve(scene, method=method)
    named = re.search(r"use method='(\w+)'", str(refused.value))
    assert named is not None and named.group(1) != method
    times = [0.0, 1.0, 7.5]
    values, bounds = ls.solve(scene, method=named.group(1)).evaluate(times, return_error=True)
    expected = [[x + v * t for t in times] for x, v in zip([1, 2, 3, 4, 5], [1, -1, 0, 0, 0.5])]
    assert np.all(np.abs(values - np.array(expected)) <= bounds)
