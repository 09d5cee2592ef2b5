"""Periodic inputs whose period is far below the motion's time scales (issue 21).

A square wave of period 1e-40 on a damped mass was off by 4e-4 with a claimed bound of
7e-16, and periods of 1e-150 and 1e-300 gave 2.7e107 and 1.5e257. The one-period sums of
the periodic response are then of size 1/(|λ|P) and cancel between the switching times:
the coefficients must be converted with the digits that cancel (an mpmath quotient by
1 − e^{−Pλ} that rounds to 0 needs more digits, not SymPy's evalf), and the evaluation
redone with the digits the parts lose against their sum.

Reference: a force of period P and mean F̄ differs from F̄ by a zero-mean ripple, whose
response is O(P) (integration by parts over each period): at P ≤ 1e-30 the response to
the constant F̄, in closed form at 40 digits, is the response to float64 accuracy.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

import laplace_springs as ls


def mean_response(m, c, k, mean, t, order):
    """x^(order)(t) of m x'' + c x' + k x = mean from rest (underdamped), 40 digits."""
    with mpmath.workdps(40):
        m, c, k, mean = (mpmath.mpf(v) for v in (m, c, k, mean))
        h, w = c / (2 * m), mpmath.sqrt(4 * m * k - c * c) / (2 * m)
        t = mpmath.mpf(t)
        x = mean / k * (1 - mpmath.exp(-h * t) * (mpmath.cos(w * t) + h / w * mpmath.sin(w * t)))
        v = mean / k * mpmath.exp(-h * t) * (h * h / w + w) * mpmath.sin(w * t)
        return float((x, v)[order])


@pytest.mark.parametrize("period", ["1e-35", "1e-40", "1e-150", "1e-300"])
@pytest.mark.parametrize("order", [0, 1])
def test_square_wave_far_below_the_time_scales(period, order):
    scene = ls.Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[0], v0=[0],
                                   forcing=[ls.square_wave(1, period)])
    times = [0.5, 1.0, 3.0, 250.5]
    values, bounds = ls.solve(scene).evaluate(times, return_error=True, derivative=order)
    ref = np.array([mean_response(1, 1, 4, 0.5, t, order) for t in times])
    error = np.abs(values[0] - ref)
    assert np.all(error <= bounds[0] + 1e-30), (error, bounds[0])   # the O(P) ripple
    assert np.max(error) <= 1e-13 * max(np.max(np.abs(ref)), 1e-3)


def test_three_level_wave_with_a_tiny_period_on_two_masses():
    # a 3-valued wave (mean 7/4 of the amplitude units) on the first of two masses; the
    # reference is the response to the mean force on the same scene, from the exact route
    wave = ls.periodic("3 - 2*Heaviside(t - 1e-41) + Heaviside(t - 3e-41)", "4e-41")
    M, C, K = [[1, 0], [0, 2]], [["1/10", 0], [0, "1/5"]], [[3, -1], [-1, 2]]
    scene = ls.Scene.from_matrices(M=M, C=C, K=K, x0=[0, 0], v0=[0, 0], forcing=[wave, 0])
    mean = ls.Scene.from_matrices(M=M, C=C, K=K, x0=[0, 0], v0=[0, 0], forcing=["7/4", 0])
    times = [0.3, 2.0, 17.0]
    values, bounds = ls.solve(scene).evaluate(times, return_error=True)
    ref = ls.solve(mean, method="exact").evaluate(times, dps=30)
    ref = np.array([[float(v) for v in row] for row in ref])
    error = np.abs(values - ref)
    assert np.all(error <= bounds + 1e-30), (error, bounds)
    assert np.max(error) <= 1e-13 * np.max(np.abs(ref))
