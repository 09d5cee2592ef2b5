"""Frequency response and steady-state amplitudes against independent routes.

The exact H(iω) is checked against the textbook 2x2 inverse; the steady-state
amplitude and phase against the forced motion itself, long after the transient has
died out, from the matrix exponential of the scene coupled to an exosystem that
generates F cos ωt (laplace_springs.bench.reference.reference_forced_motion: no
transform, no resolvent).
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.bench.reference import reference_forced_motion


def test_exact_receptance_is_the_textbook_2x2_inverse():
    scene = ls.load_scene("vertical-pair-damped")  # M = diag(1, 1/2), C = diag(1/5, 1/10)
    w = ls.omega
    a = 3 - w**2 + sp.I * w / 5
    d = 1 - w**2 / 2 + sp.I * w / 10
    b = -1
    expected = sp.Matrix([[d, -b], [-b, a]]) / (a * d - b * b)
    H = ls.frequency_response(scene)
    assert (H - expected).applyfunc(sp.cancel) == sp.zeros(2, 2)


def test_numeric_receptance_is_the_textbook_single_mass():
    scene = ls.Scene.from_matrices(M=[[3]], C=[["0.25"]], K=[[12]], x0=[0], v0=[0])
    omegas = np.array([0.1, 1.0, 2.0, 7.5])
    H = ls.frequency_response(scene, omegas)
    assert H.shape == (4, 1, 1)
    np.testing.assert_allclose(H[:, 0, 0], 1 / (12 - 3 * omegas**2 + 0.25j * omegas), rtol=1e-14)


@pytest.mark.parametrize("name, force, frequency", [
    ("vertical-pair-damped", [1, 0], "3/2"),
    ("wall-pair-dashpot", [0, 2], "1/3"),
])
def test_steady_state_is_where_the_forced_motion_settles(name, force, frequency):
    scene = ls.load_scene(name)
    amplitude, phase = ls.steady_state_amplitude(scene, force, frequency)
    w = sp.Rational(frequency)
    decay = min(-complex(sp.N(m.eigenvalue)).real for m in ls.modes(scene))
    start = sp.ceiling(45 / decay)  # the transient is below e^-45 by then
    times = [start + sp.Rational(k, 7) for k in range(4)]
    # F cos ωt = G w(t) with w' = S w, w(0) = (1, 0): w = (cos ωt, sin ωt)
    settled = reference_forced_motion(scene, [[0, -w], [w, 0]], [1, 0],
                                      [[f, 0] for f in force], [str(sp.N(t, 40)) for t in times],
                                      dps=40)
    for i in range(scene.n):
        for t, value in zip(times, settled[i]):
            with mpmath.workdps(40):
                expected = sp.N(amplitude[i] * sp.cos(w * t - phase[i]), 40)
                assert abs(value - mpmath.mpf(str(expected))) < mpmath.mpf(10) ** -15
