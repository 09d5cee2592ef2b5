"""Hostile periodic inputs (issue 22): periods, duties and widths that are not numbers in
range are SceneErrors naming them; one period of an input beyond the forcing limits is a
LimitError; what is accepted is right at any time, checked against the steady state
summed from the square wave's Fourier series (which shares no code with the solver), and
a long evaluation is planned long enough to show its progress.
"""

from __future__ import annotations

import numpy as np
import pytest

import laplace_springs as ls
from laplace_springs.limits import limits
from laplace_springs.model.errors import LimitError, SceneError


def driven(force):
    return ls.Scene.from_matrices(M=[[1]], C=[["1/2"]], K=[[4]], x0=[1], v0=[0], forcing=[force])


@pytest.mark.parametrize(("make", "fragment"), [
    (lambda: ls.square_wave(1, 0), "period must be a real number > 0, got 0"),
    (lambda: ls.square_wave(1, -2), "period must be a real number > 0, got -2"),
    (lambda: ls.square_wave(1, float("nan")), "period: expected a finite number, got nan"),
    (lambda: ls.square_wave(1, float("inf")), "period: expected a finite number, got inf"),
    (lambda: ls.square_wave(1, "1e-400"), "has magnitude 1.00e-400"),
    (lambda: ls.square_wave(1, "1e400"), "has magnitude 1.00e+400"),
    (lambda: ls.square_wave(1, 2, 0), "duty must be a number with 0 < duty < 1, got 0"),
    (lambda: ls.square_wave(1, 2, 2), "duty must be a number with 0 < duty < 1, got 2"),
    (lambda: ls.square_wave(1, 2, float("nan")), "duty: expected a finite number, got nan"),
    (lambda: ls.pulse_train(1, 1, 2), "width must be a number with 0 < width < period = 1, got 2"),
    (lambda: ls.square_wave(1j, 2), "amplitude: expected a number, got 1j"),
    (lambda: ls.square_wave("1e400", 2), "amplitude: '1e400' has magnitude 1.00e+400"),
    (lambda: ls.periodic("t", ls.t), "period must be a real number > 0, got t"),
    (lambda: ls.periodic("__import__('os')", 1), "unexpected character '_' at column 1"),
])
def test_bad_periodic_inputs_are_named(make, fragment):
    with pytest.raises(SceneError) as caught:
        driven(make())
    assert fragment in str(caught.value)


@pytest.mark.parametrize(("one_period", "error", "fragment"), [
    ("t**1000", LimitError, "Limits.max_forcing_degree"),
    ("exp(t**2)", SceneError, "is not linear in t"),
    ("(cos(t)+sin(2*t)+cos(3*t)+sin(5*t))**30", LimitError, "Limits.max_forcing_terms"),
])
def test_one_period_beyond_the_forcing_limits_is_refused(one_period, error, fragment):
    with pytest.raises(error, match=fragment):
        driven(ls.periodic(one_period, 1))


def fourier_steady_state(times: np.ndarray, harmonics: int = 400_000) -> np.ndarray:
    """x_ss(t) of x'' + x'/2 + 4x = square wave (1 on [0, 1), 0 on [1, 2)), from
    f = 1/2 + Σ_{k odd} 2/(kπ) sin(kπt) and H(ω) = 1/(4 − ω² + iω/2); the tail of the
    series is below 1e-13."""
    k = np.arange(1, 2 * harmonics, 2)[:, None]
    w = k * np.pi
    H = 1 / (4 - w**2 + 0.5j * w)
    terms = (2 / (k * np.pi)) * np.imag(H * np.exp(1j * w * times[None, :]))
    return 1 / 8 + terms.sum(axis=0)


def test_a_square_wave_is_right_at_late_and_huge_times():
    sol = ls.solve(driven(ls.square_wave(1, 2)))
    late = np.array([200.25, 1e6 + 0.25, 1e6 + 1.5, 2.0**60])  # the transient is below e^-50
    values = sol.evaluate(late)[0]
    reference = fourier_steady_state(np.array([0.25, 0.25, 1.5, 0.0]))  # t mod 2, exactly
    assert np.allclose(values, reference, rtol=0, atol=1e-10)
    assert np.all(np.isfinite(sol.evaluate([1e300])))


def test_a_long_periodic_evaluation_shows_its_progress():
    # 10^7 times of a periodic force took minutes with no sign of progress: the planner
    # now counts the pole sums' periodic work (about 10 µs per time, measured)
    sol = ls.solve(driven(ls.square_wave(1, 2)))
    assert sol.plan(np.linspace(0.1, 100, 10**6)).seconds > limits().progress_after_seconds
    assert ls.solve(driven("cos(t)")).plan(np.linspace(0.1, 100, 10**5)).seconds \
        < limits().progress_after_seconds
