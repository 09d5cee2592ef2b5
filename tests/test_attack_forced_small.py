"""Small forced scenes whose exact route refuses are served by the exo engine in auto mode.

Below Limits.exo_min_coordinates a forced scene is left to exact partial fractions (closed
forms). Where the exact route refuses (a factor of Δ whose roots SymPy would number only
after more than Limits.max_exact_isolation units of work: entries spanning hundreds of
decades), ``ls.solve`` raised a LimitError although the exo engine serves the scene.

Reference: the Laplace-domain solution of the pair wall -k- m1 -k- m2, a dashpot c from
m1 to the wall, x0 = (1, 0), v0 = 0, cos t on m1, by residues in mpmath at 1,500 digits
(written here, with the exact decimal entries): X(s) = adj P(s)·(r(s) + F(s))/Δ(s),
P = s²M + sC + K, r = (ms + c, 0), F = (s/(s² + 1), 0), Δ = (ms² + cs + 2k)(ms² + k) − k²;
x_i(t) = Σ_ρ N_i(ρ)/D'(ρ)·e^{ρt} over the roots of D = Δ·(s² + 1), N = adj P·((ms + c)(s² + 1) + s).
"""

from __future__ import annotations

import mpmath
import numpy as np
import pytest

import laplace_springs as ls

TIMES = [0.0, 0.5, 1.0, 10.0, 100.0]
TARGET = 1e-13

#: (m, k, c) of forced pairs whose exact route refuses (from tests/test_attack_scales.py's
#: HANGING list) and that the exo engine serves.
SERVED = [("1", "1", "1e-300"), ("1e-100", "1", "1e-300"), ("1e-200", "1", "1e300"),
          ("1e-100", "1e-300", "1e300"),
          # the exosystem's state scaled by |f|/max K_ii (not by |f|·M/K: 2^-998 there)
          ("1e-300", "1", "1e-300"), ("1e-300", "1", "1"), ("1e-300", "1", "1e300"),
          # the joined scene's equations scaled by one power of two (2e300 in K)
          ("1e100", "1e300", "1"), ("1e-100", "1e300", "1e300"), ("1e-200", "1e300", "1")]


def pair(m: str, k: str, c: str, forcing: str = "cos(t)") -> ls.Scene:
    return ls.Scene.from_components(
        masses={"m1": m, "m2": m}, springs={"k1": ("wall", "m1", k), "k2": ("m1", "m2", k)},
        dashpots={"c1": ("wall", "m1", c)}, x0={"m1": 1}, forcing={"m1": forcing})


def forced_pair_reference(m: str, k: str, c: str, times: list[float]) -> np.ndarray:
    """x(t) of the pair driven by cos t (2 x len(times)), by residues at 1,500 digits."""
    with mpmath.workdps(1500):
        fm, fk, fc = (mpmath.mpf(v) for v in (m, k, c))  # decimal strings: exact enough
        poly = mpmath.polyval

        def mul(a: list, b: list) -> list:  # coefficients, highest degree first
            out = [mpmath.mpf(0)] * (len(a) + len(b) - 1)
            for i, x in enumerate(a):
                for j, y in enumerate(b):
                    out[i + j] += x * y
            return out

        def add(a: list, b: list) -> list:
            size = max(len(a), len(b))
            a, b = [0] * (size - len(a)) + a, [0] * (size - len(b)) + b
            return [x + y for x, y in zip(a, b)]

        p11, p22 = [fm, fc, 2 * fk], [fm, 0, fk]
        delta = add(mul(p11, p22), [-fk * fk])
        circle = [1, 0, 1]
        D = mul(delta, circle)
        rhs = add(mul([fm, fc], circle), [1, 0])   # (ms + c)(s² + 1) + s
        N = [mul(p22, rhs), mul([fk], rhs)]        # adj P's first column times the data
        dD = [coefficient * (len(D) - 1 - i) for i, coefficient in enumerate(D[:-1])]
        roots = list(mpmath.polyroots(delta, maxsteps=2000, extraprec=3000)) + [1j, -1j]
        out = np.zeros((2, len(times)))
        for col, t in enumerate(times):
            for row in range(2):
                value = mpmath.fsum(poly(N[row], rho) / poly(dD, rho) * mpmath.exp(rho * t)
                                    for rho in roots)
                assert abs(mpmath.im(value)) <= mpmath.mpf(10) ** -40 * (1 + abs(value))
                out[row, col] = float(mpmath.re(value))
        return out


def test_the_reference_is_the_textbook_solution_of_one_mass():
    """The residue sum checked on an ordinary pair against its exact route's closed form,
    sampled at high precision through SymPy (x is exact there: it shares nothing with
    the reference's mpmath roots)."""
    sol = ls.solve(pair("1", "1", "1"), method="exact")
    expected = np.array([[float(sol.x[i].subs(ls.t, t).evalf(30)) for t in TIMES]
                         for i in range(2)])
    assert np.allclose(forced_pair_reference("1", "1", "1", TIMES), expected,
                       rtol=1e-14, atol=1e-14)


@pytest.mark.parametrize("entries", SERVED)
def test_a_forced_pair_the_exact_route_refuses_is_served_by_exo(entries):
    scene = pair(*entries)
    with pytest.raises(ls.InversionError, match="Limits.max_exact_isolation"):
        ls.solve(scene, method="exact")   # the exact route refuses, as before
    sol = ls.solve(pair(*entries))
    assert sol.method.endswith("+exo"), sol.method
    assert "exo (" in sol.reason
    values, bounds = sol.evaluate(TIMES, return_error=True)
    reference = forced_pair_reference(*entries, TIMES)
    error = np.abs(values - reference)
    assert np.all(error <= bounds), (entries, values, reference, bounds)
    # the contract's scale max(‖x(t)‖∞, S₀), with S₀ at least ‖x0‖∞ = 1
    scale = np.maximum(np.max(np.abs(reference), axis=0), 1.0)
    assert np.all(np.max(bounds, axis=0) <= TARGET * scale), (entries, bounds, scale)
    # the plan says why: exact declined with its own refusal, exo serves
    made = ls.plan(scene)
    assert made.primary == "exo"
    declined = {refusal.engine: refusal.reason for refusal in made.refusals}
    assert "Limits.max_exact_isolation" in declined["exact"]


def test_masses_of_1e_300_are_refused_by_limits_not_a_digits_error():
    """The exo engine's split built x0 − Π w(0) of 1,200 digits (beyond Limits.max_digits)
    and raised that SceneError out of ``solve``; it now falls back to the joined scene. With
    springs of 1e300 on them that scene has an entry of 2e300, which float64 cannot hold: a
    refusal, and the planner's LimitError names the limits of both engines."""
    with pytest.raises(ls.LimitError) as raised:
        ls.solve(pair("1e-300", "1e300", "1e-300"))
    text = str(raised.value)
    assert "Limits.max_exact_isolation" in text and "exo: cannot hold the scene" in text
    assert "Limits.max_digits" not in text


@pytest.mark.parametrize("scene", [pair("1", "1", "1"), pair("2", "3", "1/5", "sin(2*t)")],
                         ids=["pair", "pair sin 2t"])
def test_an_ordinary_small_forced_scene_keeps_the_exact_route(scene):
    sol = ls.solve(scene)
    assert sol.method == "exact"
    assert sol.reason.startswith("exact (exact partial fractions")
    assert "exo" in str(ls.plan(scene)) and ls.plan(scene).primary == "exact"


def test_bundled_scenes_driven_by_a_force_keep_the_exact_route():
    """The bundled scenes (none is forced) with cos(2t) on their first coordinate."""
    for name in ls.bundled_scenes():
        base = ls.load_scene(name)
        scene = ls.Scene.from_matrices(M=base.M, C=base.C, K=base.K, x0=base.x0, v0=base.v0,
                                       forcing=["cos(2*t)"] + [0] * (base.n - 1))
        sol = ls.solve(scene)
        assert sol.method == "exact", (name, sol.reason)
        assert sol.reason.startswith("exact (exact partial fractions"), (name, sol.reason)
