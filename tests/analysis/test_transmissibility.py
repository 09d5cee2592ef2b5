"""Transmissibility |X/U|(ω) of moving supports against independent routes.

One mass: the textbook T = √((1 + (2ζr)²)/((1 − r²)² + (2ζr)²)), r = ω/ωₙ, in 30-digit
mpmath and symbolically. Two masses: the hand-written 2x2 inverse (Cramer's rule), and
the steady-state amplitude of the motion itself, long after the transient, from the
matrix exponential of the scene coupled to the exosystem that generates u = sin ωt
(no transform, no resolvent).
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.analysis.frequency import omega, transmissibility, transmissibility_function
from laplace_springs.model.errors import SceneError

R = sp.Rational
lam = ls.lam


def single(m, k, c, **extra):
    return ls.Scene.from_components(masses={"m": m}, springs={"k": ("ground", "m", k)},
                                    dashpots={"c": ("ground", "m", c)}, **extra)


def textbook(r, zeta):
    return mpmath.sqrt((1 + (2 * zeta * r) ** 2) / ((1 - r**2) ** 2 + (2 * zeta * r) ** 2))


def test_single_mass_symbolic_transmissibility_is_the_textbook_formula():
    m, k, c = sp.symbols("m k c", positive=True)
    scene = single("m", "k", "c", parameters=["m", "k", "c"])
    G = transmissibility_function(scene)
    assert sp.cancel(G[0] - (k + c * lam) / (m * lam**2 + c * lam + k)) == 0
    T = transmissibility(scene)[0]
    r = omega / sp.sqrt(k / m)
    zeta = c / (2 * sp.sqrt(k * m))
    expected = (1 + (2 * zeta * r) ** 2) / ((1 - r**2) ** 2 + (2 * zeta * r) ** 2)
    assert sp.cancel(sp.expand(T**2 - expected)) == 0


@pytest.mark.parametrize("zeta", ["0.02", "0.1", "0.5", "1.5"])
def test_single_mass_float_transmissibility_matches_the_textbook_to_1e_13(zeta):
    m, k = 2, 18  # ω_n = 3
    c = 2 * R(zeta) * 6  # ζ = c / (2√(km)) = c / 12
    scene = single(m, k, c)
    ratios = ["0.1", "0.5", "0.9", "1", "1.1", "1.41421356", "2", "5", "30"]
    omegas = np.array([3 * float(r) for r in ratios])
    got = transmissibility(scene, omegas)
    assert got.shape == (len(ratios), 1)
    with mpmath.workdps(30):
        for value, w in zip(got[:, 0], omegas):
            expected = textbook(mpmath.mpf(w) / 3, mpmath.mpf(R(zeta).p) / R(zeta).q)
            assert abs(value - expected) <= 1e-13 * expected, (w, value, expected)
    # exact values at exact frequencies: T(r)² is the textbook rational number
    exact = transmissibility(scene, [3, "3/2", 6], exact=True)
    for row, r in zip(exact.tolist(), [1, R(1, 2), 2]):
        z = R(zeta)
        assert sp.simplify(row[0] ** 2 - (1 + (2 * z * r) ** 2) / ((1 - r**2) ** 2 + (2 * z * r) ** 2)) == 0
    # √2 is where every curve crosses T = 1
    assert sp.simplify(transmissibility(scene, [3 * sp.sqrt(2)], exact=True)[0, 0]) == 1


CHAIN = {
    "masses": {"m1": 1, "m2": "1/2"},
    "springs": {"k1": ("wall_left", "m1", 3), "k2": ("m1", "m2", 1), "k3": ("m2", "wall_right", 2)},
    "dashpots": {"c1": ("wall_left", "m1", "1/2"), "c2": ("m1", "m2", "1/4"),
                 "c3": ("m2", "wall_right", "1/3")},
}


def test_two_mass_transmissibility_function_is_cramers_rule():
    scene = ls.Scene.from_components(**CHAIN, support_motion={"wall_left": "sin(2*t)/10"})
    a = lam**2 + R(3, 4) * lam + 4   # m1 row: λ²·1 + λ(1/2 + 1/4) + (3 + 1)
    b = -(R(1, 4) * lam + 1)          # coupling
    d = lam**2 / 2 + (R(1, 4) + R(1, 3)) * lam + 3
    drive = sp.Matrix([3 + lam / 2, 0])  # K_s + λ C_s of wall_left
    inverse = sp.Matrix([[d, -b], [-b, a]]) / (a * d - b * b)
    expected = inverse * drive
    G = transmissibility_function(scene)  # the moving support by default
    assert (G - expected).applyfunc(sp.cancel) == sp.zeros(2, 1)
    right = transmissibility_function(scene, "WALL_RIGHT")
    expected_right = inverse * sp.Matrix([0, 2 + lam / 3])
    assert (right - expected_right).applyfunc(sp.cancel) == sp.zeros(2, 1)


def _steady_amplitudes(scene_matrices, G, w, time, dps):
    """Amplitudes √(x² + (x'/ω)²) at a late time, from the exosystem matrix exponential."""
    n = len(scene_matrices[0])
    with mpmath.workdps(dps):  # exact rationals become mpf at this precision
        M, C, K, G = ([[mpmath.mpf(e.p) / e.q for e in map(sp.Rational, row)] for row in matrix]
                      for matrix in (*scene_matrices, G))
        Minv = mpmath.inverse(mpmath.matrix(M))
        Z = mpmath.zeros(2 * n + 2, 2 * n + 2)
        for i in range(n):
            Z[i, n + i] = 1
        lower = (-Minv * mpmath.matrix(K), -Minv * mpmath.matrix(C), Minv * mpmath.matrix(G))
        for i in range(n):
            for j in range(n):
                Z[n + i, j], Z[n + i, n + j] = lower[0][i, j], lower[1][i, j]
            for j in range(2):
                Z[n + i, 2 * n + j] = lower[2][i, j]
        Z[2 * n, 2 * n + 1], Z[2 * n + 1, 2 * n] = w, -w   # w = (sin ωt, cos ωt)
        y0 = mpmath.matrix([0] * (2 * n) + [0, 1])
        y = mpmath.expm(Z * time) * y0
        return [mpmath.sqrt(y[i] ** 2 + (y[n + i] / w) ** 2) for i in range(n)]


@pytest.mark.parametrize("w", [1, 2, 5])
def test_two_mass_transmissibility_is_the_steady_amplitude_of_the_motion(w):
    scene = ls.Scene.from_components(**CHAIN)
    M = [[1, 0], [0, R(1, 2)]]
    C = [[R(3, 4), -R(1, 4)], [-R(1, 4), R(1, 4) + R(1, 3)]]
    K = [[4, -1], [-1, 3]]
    G = [[3, R(w, 2)], [0, 0]]  # u = sin ωt: k1 u + c1 u' = 3 w1 + (ω/2) w2
    late = _steady_amplitudes((M, C, K), G, w, 300, 40)  # slowest decay e^{-0.27 t}: e^{-82}
    check = _steady_amplitudes((M, C, K), G, w, 300, 60)
    got = transmissibility(scene, [float(w)], support="wall_left")
    exact = transmissibility(scene, [w], support="wall_left", exact=True)
    for i in range(2):
        assert abs(late[i] - check[i]) < 1e-25
        assert abs(got[0, i] - late[i]) <= 1e-13 * late[i]
        assert abs(sp.N(exact[0, i], 35) - sp.Float(mpmath.nstr(late[i], 35), 35)) < sp.Float("1e-30")
    # outputs by index or name pick columns
    by_name = transmissibility(scene, [float(w)], support="wall_left", outputs=["m2"])
    assert by_name.shape == (1, 1) and by_name[0, 0] == got[0, 1]


def test_transmissibility_errors():
    chain = ls.Scene.from_components(**CHAIN)
    with pytest.raises(SceneError, match="name the support: this scene has supports wall_left, wall_right"):
        transmissibility(chain, [1.0])
    with pytest.raises(SceneError, match="unknown support 'ceiling'; the scene's supports are wall_left"):
        transmissibility(chain, [1.0], support="ceiling")
    with pytest.raises(SceneError, match="outputs: unknown mass or coordinate 'm3'"):
        transmissibility(chain, [1.0], support="wall_left", outputs=["m3"])
    with pytest.raises(SceneError, match="outputs: 2 is not a coordinate"):
        transmissibility(chain, [1.0], support="wall_left", outputs=[2])
    matrices = ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[0], v0=[0])
    with pytest.raises(SceneError, match="only for scenes built from components"):
        transmissibility(matrices, [1.0])
    symbolic = single("m", "k", "c", parameters=["m", "k", "c"])
    with pytest.raises(SceneError, match="symbolic"):
        transmissibility(symbolic, [1.0])
    undamped = ls.Scene.from_components(masses={"m": 1}, springs={"k": ("ground", "m", 4)})
    with pytest.raises(SceneError, match="resonance"):
        transmissibility(undamped, [2], exact=True)
    with pytest.raises(SceneError, match="resonance"):
        transmissibility(undamped, [2.0])
    # off resonance the undamped single mass has T = 1/|1 - r²|
    assert transmissibility(undamped, [4.0])[0, 0] == pytest.approx(1 / 3, rel=1e-15)
