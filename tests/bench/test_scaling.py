"""benchmarks/bench_scaling.py: its scenes, its references and its peers (issue 14, item 3).

The references of the scaling benchmark are checked against python-flint's certified arb
matrix exponential (``reference_motion_arb``) and against each other where they are
independent (the analytic chain solution in float64 against double-double Taylor steps,
on a chain with an overdamped mode). Nothing here is timed.
"""

from __future__ import annotations

import importlib.util
import sys
from fractions import Fraction
from pathlib import Path

import mpmath
import numpy as np
import pytest
import sympy

pytest.importorskip("scipy")

from laplace_springs.bench.reference import reference_motion_arb

PATH = Path(__file__).resolve().parents[2] / "benchmarks" / "bench_scaling.py"


@pytest.fixture(scope="module")
def bs():
    spec = importlib.util.spec_from_file_location("bench_scaling", PATH)
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_scaling"] = module
    spec.loader.exec_module(module)
    yield module
    sys.modules.pop("bench_scaling", None)


def _arb(bs, spec, times, digits=30):
    high, low = bs._split(reference_motion_arb(bs.build_scene(spec), list(times), digits=digits))
    return high, low


def _max_difference(a, b) -> float:
    (ah, al), (bh, bl) = a, b
    return float(np.max(np.abs((ah - bh) + (al - bl))))


def test_chain_scene_has_rayleigh_damping_and_the_wall_dashpot(bs):
    for family in ("chain-rayleigh", "chain-wall-dashpot"):
        scene = bs.build_scene(bs.scene_spec(family, 6))
        K, M, C = sympy.Matrix(scene.K), sympy.Matrix(scene.M), sympy.Matrix(scene.C)
        assert sympy.Matrix(6, 6, lambda i, j: 2 if i == j else -1 if abs(i - j) == 1 else 0) == K
        assert sympy.eye(6) == M
        extra = C - (K / 500 + M / 100)
        expected = sympy.zeros(6, 6)
        if family == "chain-wall-dashpot":
            expected[3, 3] = sympy.Rational(1, 2)        # the middle mass, index n // 2
        assert extra == expected
        assert list(scene.x0) == [1, 0, 0, 0, 0, 0] and list(scene.v0) == [0] * 6


def test_mesh_is_connected_seeded_and_rayleigh(bs):
    spec = bs.scene_spec("mesh-rayleigh", 200)
    assert len(spec.springs) == 600                         # 3 springs per mass
    neighbours = {i: set() for i in range(200)}
    for i, j, _ in spec.springs:
        if j >= 0:
            neighbours[i].add(j)
            neighbours[j].add(i)
    seen, stack = {0}, [0]
    while stack:
        for j in neighbours[stack.pop()] - seen:
            seen.add(j)
            stack.append(j)
    assert len(seen) == 200                                  # connected
    assert any(j < 0 for _, j, _ in spec.springs)            # held by the wall
    assert bs.scene_spec("mesh-rayleigh", 200).springs == spec.springs   # seeded
    dashpots = {(i, j): v for i, j, v in spec.dashpots}
    for i, j, k in spec.springs:
        if j >= 0:
            assert dashpots[(i, j)] == k / 500
    m, K, C = bs.float_arrays(spec)
    extra = bs.float_arrays(bs.scene_spec("mesh-wall-dashpot", 200))[2] - C
    assert extra.nnz == 1 and extra[100, 100] == 0.5


def test_analytic_chain_references_agree_with_arb(bs):
    times = np.linspace(0.0, 50.0, 25)
    arb = _arb(bs, bs.scene_spec("chain-rayleigh", 7), times)
    assert _max_difference(bs._split(bs.chain_reference_mp(7, times)), arb) < 1e-28
    assert _max_difference((bs.chain_reference_float(7, times), 0.0), arb) < 4e-16


def test_double_double_taylor_agrees_with_arb(bs):
    times = np.linspace(0.0, 50.0, 6)
    for family in ("chain-wall-dashpot", "mesh-wall-dashpot"):
        spec = bs.scene_spec(family, 6)
        assert _max_difference(bs.DoubleDoubleTaylor(spec).motion(times), _arb(bs, spec, times)) < 1e-28


def test_float_chain_reference_with_an_overdamped_mode(bs):
    # n = 700: ω_1 = 2 sin(π/1402) ≈ 0.00448 < 0.005, so mode 1 is overdamped (ζ > 1)
    constants = bs._chain_mode_constants(700)
    assert not constants["under"][0] and constants["under"][1:].all()
    times = np.array([0.0, 0.3, 7.25, 50.0])
    taylor = bs.DoubleDoubleTaylor(bs.scene_spec("chain-rayleigh", 700)).motion(times)
    analytic = bs.chain_reference_float(700, times)
    assert _max_difference((analytic, 0.0), taylor) < 1e-15


def test_peers_as_implemented_reach_float64_accuracy(bs):
    times = np.linspace(0.0, 50.0, 50)
    for family in ("chain-rayleigh", "mesh-rayleigh"):
        spec = bs.scene_spec(family, 9)
        reference = bs.Reference("arb", *_arb(bs, spec, times, digits=20))
        m, K, C = bs.float_arrays(spec)
        Z, y0 = bs.first_order(m, K, C)
        errors = {"numpy-eig": reference.error(bs.run_numpy_eig(Z, y0, times)),
                  "modal-eigh": reference.error(bs.run_modal_eigh(m, K, C, times,
                                                                  family.startswith("chain"))),
                  "expm_multiply": reference.error(bs.run_expm_multiply(Z, y0, times)),
                  "scipy-expm": reference.error(bs.run_scipy_expm(Z, y0, times))}
        assert max(errors.values()) < 1e-11, (family, errors)
        # a wrong answer is seen: the undamped motion differs from the damped one
        assert reference.error(bs.run_modal_eigh(m, K, 0 * C, times, family.startswith("chain"))) > 1e-3


def test_modal_motion_branches_against_mpmath(bs):
    # q'' + 2a q' + w2 q = 0 with q(0) = 1, q'(0) = 2: under-, critically and overdamped
    a = np.array([0.1, 1.0, 3.0])
    w2 = np.array([4.0, 1.0, 1.0])
    times = np.array([0.0, 0.5, 4.0])
    q = bs.modal_motion(a, w2, np.ones(3), 2 * np.ones(3), times)
    with mpmath.workdps(30):
        for row, (aj, wj) in enumerate(zip(a, w2)):
            roots = mpmath.polyroots([1, 2 * aj, wj]) if aj * aj != wj else [-aj, -aj]
            for col, t in enumerate(times):
                if aj * aj == wj:
                    exact = mpmath.exp(-aj * t) * (1 + (2 + aj) * t)
                else:
                    r1, r2 = roots
                    c1 = (2 - r2) / (r1 - r2)
                    exact = mpmath.re(c1 * mpmath.exp(r1 * t) + (1 - c1) * mpmath.exp(r2 * t))
                assert abs(q[row, col] - float(exact)) < 1e-14


def test_growth_exponent_and_readme_markers(bs, tmp_path):
    assert bs.growth_exponent([(10, 2.0), (100, 2000.0), (1000, 2e6)]) == pytest.approx(3.0)
    assert bs.growth_exponent([(10, 1.0)]) is None
    readme = tmp_path / "README.md"
    readme.write_text(f"intro\n{bs.START}\nold\n{bs.END}\nafter\n", encoding="utf-8")
    bs.write_readme("| new |", readme)
    assert readme.read_text(encoding="utf-8") == f"intro\n{bs.START}\n| new |\n{bs.END}\nafter\n"


def test_exact_values_are_split_into_double_double(bs):
    hi, lo = bs._dd(Fraction(1, 500))
    with mpmath.workdps(50):
        assert abs(mpmath.mpf(hi) + mpmath.mpf(lo) - mpmath.mpf(1) / 500) < mpmath.mpf(10) ** -33
