"""Periodic forcing (issue 12 item 3): inputs, transforms, and the exact response.

References are independent of the package: the response is propagated segment by
segment with mpmath's matrix exponential of the augmented first-order system (the input
is constant or linear on each segment), at 40+ digits, with the period map raised to a
power for many periods; transforms are the textbook formulas.
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest
import sympy as sp

import laplace_springs as ls
from laplace_springs.exact.laplace import laplace
from laplace_springs.model.errors import SceneError
from laplace_springs.model.periodic import Periodic, periodic, pulse_train, sawtooth, square_wave

t = ls.t
s = sp.Symbol("s")


# ----------------------------------------------------------------------------- reference
def _augmented(M, C, K, drive):
    """y = (x, v, 1) (drive constant on the segment): y' = A y, for M x'' + C x' + K x = drive."""
    n = len(M)
    Mi = mpmath.inverse(mpmath.matrix(M))
    A = mpmath.zeros(2 * n + 1, 2 * n + 1)
    MK, MC = -Mi * mpmath.matrix(K), -Mi * mpmath.matrix(C)
    Md = Mi * mpmath.matrix(drive)
    for i in range(n):
        A[i, n + i] = 1
        for j in range(n):
            A[n + i, j] = MK[i, j]
            A[n + i, n + j] = MC[i, j]
        A[n + i, 2 * n] = Md[i]
    return A


def _piecewise_constant_reference(M, C, K, x0, v0, segments, time, dps=45):
    """x(time) for an input that is ``segments`` = [(length, drive vector), ...] repeated."""
    with mpmath.workdps(dps):
        n = len(M)
        maps = [(mpmath.mpf(length), _augmented(M, C, K, drive)) for length, drive in segments]
        period = sum(length for length, _ in maps)
        one = mpmath.eye(2 * n + 1)
        for length, A in maps:
            one = mpmath.expm(A * length) * one
        time = mpmath.mpf(time)
        count = int(mpmath.floor(time / period))
        y = mpmath.matrix([*x0, *v0, 1])
        y = (one ** count) * y if count else y
        left = time - count * period
        for length, A in maps:
            step = min(left, length)
            if step <= 0:
                break
            y = mpmath.expm(A * step) * y
            left -= step
        return [y[i] for i in range(n)]


def _float_time(value: float) -> mpmath.mpf:
    return mpmath.mpf(value)  # the exact binary value of the float


# ----------------------------------------------------------------------------- the input
def test_periodic_object_prints_substitutes_and_checks_its_period():
    f = periodic("1 - Heaviside(t - 1)", 2)
    assert str(f) == "periodic(1 - Heaviside(t - 1), 2)"
    assert f.subs(t, sp.Rational(1, 2)) == 1 and f.subs(t, sp.Rational(3, 2)) == 0
    assert f.subs(t, 10**6 + sp.Rational(1, 3)) == 1 and f.subs(t, 10**6 + sp.Rational(5, 4)) == 0
    assert r"\bmod 2" in sp.latex(f)
    with pytest.raises(SceneError, match="period must be a real number > 0, got -2"):
        periodic("t", -2)
    with pytest.raises(SceneError, match="got 0"):
        square_wave(1, 0)
    with pytest.raises(SceneError, match="duty .* got 3/2"):
        square_wave(1, 2, 1.5)
    with pytest.raises(SceneError, match="width .* got 3"):
        pulse_train(1, 2, 3)
    assert square_wave(2, 4, 0.25) == Periodic(2 - 2 * sp.Heaviside(t - 1), 4)
    assert sawtooth(3, 2) == Periodic(3 * t / 2, 2)


def test_text_forcing_and_scene_subs():
    scene = ls.Scene.from_matrices(M=[[1]], C=[[1]], K=[[4]], x0=[0], v0=[0],
                                   forcing=["A*periodic(1 - Heaviside(t - 1), 2)"], parameters=["A"])
    assert scene.forcing[0] == sp.Symbol("A", positive=True) * square_wave(1, 2)
    numeric = scene.subs({"A": 3})
    assert numeric.forcing[0] == 3 * square_wave(1, 2)
    with pytest.raises(SceneError, match=r"forcing\[0\]"):
        ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[0], v0=[0], forcing=["periodic(1/(t + 1), 2)"])
    with pytest.raises(SceneError, match="period must be a real number > 0"):
        ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[0], v0=[0], forcing=["periodic(t, -1)"])


# ----------------------------------------------------------------------------- transforms
@pytest.mark.parametrize("value", ["1/2", "1", "37/10"])
def test_forward_transforms_match_the_table(value):
    z = sp.Rational(value)
    for a in (sp.Integer(1), sp.Rational(3, 2)):   # ±1 square wave of period 2a: tanh(as/2)/s
        F = laplace(periodic(1 - 2 * sp.Heaviside(t - a), 2 * a))
        assert abs(sp.N(F.subs(s, z) - sp.tanh(a * z / 2) / z, 30)) < 1e-25
    for T in (sp.Integer(1), sp.Rational(5, 2)):   # t/T on [0, T)
        F = laplace(sawtooth(1, T))
        table = 1 / (T * z**2) - sp.exp(-T * z) / (z * (1 - sp.exp(-T * z)))
        assert abs(sp.N(F.subs(s, z) - table, 30)) < 1e-25
    F = laplace(pulse_train(5, 2, sp.Rational(1, 10)))   # A(1 - e^{-ws})/(s(1 - e^{-Ts}))
    table = 5 * (1 - sp.exp(-z / 10)) / (z * (1 - sp.exp(-2 * z)))
    assert abs(sp.N(F.subs(s, z) - table, 30)) < 1e-25
    # a periodic sin and a sum of two periods (quadrature of one common period as reference)
    F = laplace("periodic(sin(pi*t), 1) + 2*sawtooth(1, 3)")
    with mpmath.workdps(30):
        zz = mpmath.mpf(z.p) / z.q
        f = lambda u: mpmath.sin(mpmath.pi * (u % 1)) + 2 * (u % 3) / 3  # noqa: E731
        one = mpmath.quad(lambda u: f(u) * mpmath.exp(-zz * u), [0, 1, 2, 3])
        assert abs(complex(sp.N(F.subs(s, z), 30)) - complex(one / (1 - mpmath.exp(-3 * zz)))) < 1e-20


def test_inverse_of_periodic_transforms_many_periods_out():
    for f, times in ((periodic(1 - 2 * sp.Heaviside(t - 1), 2), ("12345.25", "12346.5", "999999.75")),
                     (sawtooth(1, sp.Rational(5, 2)), ("12345.25", "100000.1")),
                     (pulse_train(5, 2, sp.Rational(1, 10)), ("123456.05", "123456.5"))):
        back = ls.inverse_laplace(laplace(f), s, t)
        for value in times:
            tv = sp.Rational(value)
            assert abs(sp.N(back.subs(t, tv) - f.subs(t, tv), 30)) < 1e-20


# ----------------------------------------------------------------------------- responses
def test_square_wave_drives_a_damped_oscillator_at_t_1000():
    """x'' + x'/2 + 4x = square wave (1 on [0,1), 0 on [1,2)), x(0) = 1."""
    scene = ls.Scene.from_matrices(M=[[1]], C=[["1/2"]], K=[[4]], x0=[1], v0=[0],
                                   forcing=[square_wave(1, 2)])
    sol = ls.solve(scene)
    assert sol.method == "exact"
    times = [1000.3, 1001.7, 999.99, 123456.7, 1e6 + 0.25]
    values, bounds = sol.evaluate(times, return_error=True)
    reference = [_piecewise_constant_reference([[1]], [["0.5"]], [[4]], [1], [0],
                                               [(1, [1]), (1, [0])], _float_time(tv))[0]
                 for tv in times]
    errors = np.abs(values[0] - np.array([float(r) for r in reference]))
    assert np.all(errors < 1e-12), errors
    assert np.all(errors <= bounds[0] + 1e-16)
    digits = sol.evaluate(times[:2], dps=30)
    for got, want in zip(digits[0], reference):
        assert abs(got - want) < 1e-28


def test_steady_state_is_periodic_and_the_transient_decays():
    scene = ls.Scene.from_matrices(M=[[1]], C=[["1/2"]], K=[[4]], x0=[1], v0=[0],
                                   forcing=[sawtooth(2, 3)])
    sol = ls.solve(scene)
    steady, transient = sol.steady_state[0], sol.transient[0]
    for tv in (sp.Rational(1001, 3) + sp.Rational(1, 7), sp.Rational(10**5) + sp.Rational(2, 9)):
        a, b = sp.N(steady.subs(t, tv), 30), sp.N(steady.subs(t, tv + 3), 30)
        assert abs(a - b) < 1e-25
        assert abs(sp.N(transient.subs(t, tv), 30)) < 1e-25        # e^{-t/4}
        assert abs(sp.N(sol.x[0].subs(t, tv) - a, 30)) < 1e-25
    # the steady state is the response from the state it repeats: reference with that start
    with mpmath.workdps(40):
        x_ss0 = sp.N(steady.subs(t, 0), 40)
        v_ss0 = sp.N(sp.diff(steady.subs(sp.floor(t / 3), 0), t).subs(t, 0), 40)
        ref = _linear_reference(mpmath.mpf(str(x_ss0)), mpmath.mpf(str(v_ss0)), mpmath.mpf("2.5"))
        ref_text = mpmath.nstr(ref, 40)
    assert abs(sp.N(steady.subs(t, sp.Rational(5, 2)), 40) - sp.Float(ref_text, 40)) < 1e-30


def _linear_reference(x0, v0, time):
    """x'' + x'/2 + 4x = 2u/3 on [0, 3) with u' = 1: augmented (x, v, u, 1)."""
    A = mpmath.matrix([[0, 1, 0, 0], [-4, -mpmath.mpf(1) / 2, mpmath.mpf(2) / 3, 0],
                       [0, 0, 0, 1], [0, 0, 0, 0]])
    y = mpmath.expm(A * time) * mpmath.matrix([x0, v0, 0, 1])
    return y[0]


def test_pulse_train_on_a_two_mass_chain_far_out():
    M, C, K = [[1, 0], [0, 2]], [["3/10", "-1/10"], ["-1/10", "1/10"]], [[3, -1], [-1, 1]]
    scene = ls.Scene.from_matrices(M=M, C=C, K=K, x0=[0, 1], v0=[0, 0],
                                   forcing=[0, pulse_train(5, "3/2", "1/10")])
    sol = ls.solve(scene)
    times = [10000.05, 10000.7, 250000.3]
    values = sol.evaluate(times)
    for j, tv in enumerate(times):
        ref = _piecewise_constant_reference(M, C, K, [0, 1], [0, 0],
                                            [("0.1", [0, 5]), ("1.4", [0, 0])], _float_time(tv))
        assert max(abs(values[i, j] - float(ref[i])) for i in range(2)) < 1e-12
    velocity = sol.evaluate([10000.7], derivative=1)
    with mpmath.workdps(40):
        h = mpmath.mpf("1e-12")
        ahead = _piecewise_constant_reference(M, C, K, [0, 1], [0, 0], [("0.1", [0, 5]), ("1.4", [0, 0])],
                                              _float_time(10000.7) + h)
        behind = _piecewise_constant_reference(M, C, K, [0, 1], [0, 0], [("0.1", [0, 5]), ("1.4", [0, 0])],
                                               _float_time(10000.7) - h)
        assert abs(velocity[1, 0] - float((ahead[1] - behind[1]) / (2 * h))) < 1e-9


def test_irrational_period_is_reduced_exactly():
    """Square wave of period π: the reduction t mod π needs the digits of t/π."""
    scene = ls.Scene.from_matrices(M=[[1]], C=[[1]], K=[[2]], x0=[0], v0=[0],
                                   forcing=[square_wave(1, sp.pi)])
    sol = ls.solve(scene)
    times = [1000.5, 99999.9]
    values = sol.evaluate(times)
    with mpmath.workdps(60):
        half = mpmath.pi / 2
        for j, tv in enumerate(times):
            ref = _piecewise_constant_reference([[1]], [[1]], [[2]], [0], [0], [(half, [1]), (half, [0])],
                                                _float_time(tv), dps=60)
            assert abs(values[0, j] - float(ref[0])) < 1e-12


def test_undamped_resonance_grows_and_is_still_exact():
    """x'' + x = sawtooth of period 2π: the harmonic at ω = 1 resonates (t·cos t growth)."""
    scene = ls.Scene.from_matrices(M=[[1]], K=[[1]], x0=[0], v0=[0], forcing=["periodic(t, 2*pi)"])
    sol = ls.solve(scene)
    assert sol.verify()
    for tv in (50.5, 1000.25):
        value = sol.evaluate([tv])[0, 0]
        with mpmath.workdps(40):
            A = mpmath.matrix([[0, 1, 0, 0], [-1, 0, 1, 0], [0, 0, 0, 1], [0, 0, 0, 0]])
            P = 2 * mpmath.pi
            one = mpmath.expm(A * P)
            reset = mpmath.diag([1, 1, 0, 1])     # u restarts at 0 each period
            time = _float_time(tv)
            count = int(mpmath.floor(time / P))
            y = (reset * one) ** count * mpmath.matrix([0, 0, 0, 1])
            y = mpmath.expm(A * (time - count * P)) * y
        assert abs(value - float(y[0])) < 1e-12 * max(1, abs(float(y[0])))
    assert abs(sol.evaluate([1000.25])[0, 0]) > 100   # growing: no periodic steady state


def test_verify_and_latex_of_a_periodic_response():
    scene = ls.Scene.from_matrices(M=[[1]], C=[[2]], K=[[5]], x0=[0], v0=[0],
                                   forcing=["square_wave(1, 1)"])
    sol = ls.solve(scene)
    assert sol.verify()
    assert r"\left\lfloor" in sol.latex()


def test_periodic_hammer_blows_against_the_sum_of_impulse_responses():
    """x'' + x'/5 + 4x = Σ_k δ(t - 1/2 - k) from rest: x is the sum of the shifted impulse
    responses e^{-τ/10} sin(ω_d τ)/ω_d, τ = t - 1/2 - k > 0 (summed in mpmath, 40 digits)."""
    scene = ls.Scene.from_matrices(M=[[1]], C=[["1/5"]], K=[[4]], x0=[0], v0=[0],
                                   forcing=[ls.periodic("DiracDelta(t - 1/2)", 1)])
    sol = ls.solve(scene)

    def reference(time: str):
        with mpmath.workdps(40):
            damping = mpmath.mpf(1) / 5
            wd = mpmath.sqrt(4 - damping**2 / 4)
            total, k, T = mpmath.mpf(0), 0, mpmath.mpf(time)
            while k + mpmath.mpf(1) / 2 < T:
                tau = T - k - mpmath.mpf(1) / 2
                total += mpmath.exp(-damping * tau / 2) * mpmath.sin(wd * tau) / wd
                k += 1
            return float(total)

    for time in ("3.3", "100.25", "100.75", "1000.5001"):
        value, bound = sol.evaluate([time], return_error=True)
        assert abs(value[0, 0] - reference(time)) <= bound[0, 0] + 1e-17
        assert bound[0, 0] < 1e-13


def test_an_impulse_times_a_step_takes_the_steps_value_at_the_impulse():
    """δ(t - 1)H(t - 2) = 0 and δ(t - 3)H(t - 2) = δ(t - 3); a step switching at the impulse
    itself has no value there and is refused."""
    s = ls.s
    assert ls.laplace("DiracDelta(t - 1)*Heaviside(t - 2) + DiracDelta(t - 3)*Heaviside(t - 2)") \
        == sp.exp(-3 * s)
    with pytest.raises(SceneError, match="switches at the same time"):
        ls.laplace("DiracDelta(t - 1)*Heaviside(t - 1)")
