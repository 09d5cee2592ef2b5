"""Modes against an independent route: mpmath eigenvalues of the first-order matrix.

The eigenvalues of the pencil λ²M + λC + K are those of Z = [[0, I], [−M⁻¹K, −M⁻¹C]];
mpmath's ``eig`` (QR iterations at 30 digits) shares no step with the exact
factorisation of Δ(λ) that :func:`laplace_springs.modes` uses.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.bench.reference import first_order_matrix_mp

SCENES = sorted(ls.bundled_scenes())

OVERDAMPED = ls.Scene.from_matrices(M=[[1]], C=[[5]], K=[[4]], x0=[1], v0=[0])  # λ = −1, −4
FREE_FREE = ls.Scene.from_components(masses={"m1": 1, "m2": 3}, springs={"k1": ("m1", "m2", 3)},
                                     x0=[1, 0], v0=[0, 0])  # rigid λ = 0 twice, ω² = k(1/m1 + 1/m2)
CUBIC = ls.Scene.from_components(  # three unequal masses, three dashpots: Δ has no radical roots
    masses={"m1": 1, "m2": 2, "m3": 3},
    springs={"k1": ("wall", "m1", 5), "k2": ("m1", "m2", 3), "k3": ("m2", "m3", 2)},
    dashpots={"c1": ("wall", "m1", 1), "c2": ("m1", "m2", "1/3"), "c3": ("m3", "wall", "1/7")},
    x0=[1, 0, 0], v0=[0, 0, 0])
EXTRA = {"overdamped": OVERDAMPED, "free-free": FREE_FREE, "cubic": CUBIC}


def _scene(name):
    return EXTRA[name] if name in EXTRA else ls.load_scene(name)


def _reference_eigenvalues(scene) -> list[complex]:
    with mpmath.workdps(30):
        values = mpmath.eig(first_order_matrix_mp(scene), left=False, right=False)
        return sorted((complex(v) for v in values), key=lambda z: (round(z.real, 9), round(z.imag, 9)))


def _all_eigenvalues(modes) -> list[complex]:
    """Every eigenvalue with its multiplicity: a complex pair's conjugate added back."""
    out = []
    for mode in modes:
        value = complex(sp.N(mode.eigenvalue, 30))
        out += [value] * mode.multiplicity
        if mode.kind == "oscillatory":
            out += [value.conjugate()] * mode.multiplicity
    return sorted(out, key=lambda z: (round(z.real, 9), round(z.imag, 9)))


@pytest.mark.parametrize("name", SCENES + sorted(EXTRA))
def test_eigenvalues_match_the_first_order_matrix(name):
    scene = _scene(name)
    found = _all_eigenvalues(ls.modes(scene))
    expected = _reference_eigenvalues(scene)
    assert len(found) == len(expected) == 2 * scene.n
    scale = max(abs(z) for z in expected)
    for got, ref in zip(found, expected):
        assert abs(got - ref) <= 1e-12 * scale, (got, ref)


@pytest.mark.parametrize("name", SCENES + sorted(EXTRA))
def test_frequencies_ratios_and_shapes_follow_from_the_eigenvalue(name):
    scene = _scene(name)
    M, C, K = (np.array(m.evalf(30).tolist(), dtype=float) for m in (scene.M, scene.C, scene.K))
    for mode in ls.modes(scene):
        lam = complex(sp.N(mode.eigenvalue, 30))
        assert float(mode.natural_frequency) == pytest.approx(abs(lam), rel=1e-13, abs=1e-15)
        assert float(mode.damped_frequency) == pytest.approx(abs(lam.imag), rel=1e-13, abs=1e-15)
        if mode.kind == "oscillatory":
            assert float(mode.damping_ratio) == pytest.approx(-lam.real / abs(lam), rel=1e-12, abs=1e-15)
        else:
            assert mode.damping_ratio is None
        pencil = lam**2 * M + lam * C + K
        size = np.abs(lam) ** 2 * np.abs(M).max() + np.abs(lam) * np.abs(C).max() + np.abs(K).max()
        for shape in mode.shapes:
            assert np.abs(shape).max() == pytest.approx(1.0)
            assert np.abs(pencil @ shape).max() <= 1e-12 * size


def test_kinds_of_modes():
    assert [(m.kind, m.eigenvalue, m.multiplicity) for m in ls.modes(OVERDAMPED)] == [
        ("real", -1, 1), ("real", -4, 1)]
    rigid, elastic = ls.modes(FREE_FREE)
    assert (rigid.kind, rigid.eigenvalue, rigid.multiplicity) == ("rigid", 0, 2)
    assert np.allclose(rigid.shape, [1, 1])  # both masses move together
    assert elastic.natural_frequency == 2  # ω² = 3 (1/1 + 1/3) = 4
    assert np.allclose(elastic.shape, [1, -1 / 3])  # momentum m1 v1 + m2 v2 = 0
    assert all(m.kind == "oscillatory" for m in ls.modes(CUBIC))


def test_symbolic_single_mass():
    m, c, k = sp.symbols("m c k", positive=True)
    (mode,) = ls.modes(ls.Scene.from_matrices(M=[[m]], C=[[c]], K=[[k]], x0=[1], v0=[0]))
    # textbook: ω_n = √(k/m), ζ = c/(2√(km)) (written without assuming c² < 4km)
    values = {m: 2, c: sp.Rational(1, 3), k: 5}
    assert sp.N(mode.natural_frequency.xreplace(values) - sp.sqrt(sp.Rational(5, 2)), 30) == 0
    assert sp.N(mode.damping_ratio.xreplace(values) - sp.Rational(1, 3) / (2 * sp.sqrt(10)), 30) == 0
