"""Assemble x(t) from the resolvent: solve(), the Solution object and its g-basis.

Each coordinate X_i(λ) = N_i(λ)/Δ(λ) is inverted by the shared partial-fraction engine
(the denominator is factored once). The seed's basis g_k(t) = L⁻¹[λ^k/Δ(λ)] and the
coefficients c_ik with x_i(t) = Σ_k c_ik g_k(t) are available beside the closed form.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, Sequence

import numpy as np
import sympy as sp

from .algebraic import numeric_value
from .evaluate import NumericTerms, evaluate_float, evaluate_mp, numeric_terms
from .numbers import TIME
from .partial_fractions import decompose
from .real_terms import Term, group_terms, terms_expr
from .resolvent import Resolvent, lam, resolvent

if TYPE_CHECKING:
    from .scene import Scene

__all__ = ["t", "Solution", "Verification", "solve"]

#: Time, the variable of every solution (the results hold for t ≥ 0).
t = TIME

_METHODS = ("auto", "exact")


def _terms_of(decompositions) -> tuple[tuple[Term, ...], ...]:
    return tuple(tuple(term for group in pf.groups for term in group_terms(group))
                 for pf in decompositions)


@dataclass(frozen=True)
class Verification:
    """Outcome of :meth:`Solution.verify`: residuals relative to the solution's size."""

    ode_residual: float
    initial_residual: float
    tolerance: float

    @property
    def ok(self) -> bool:
        """True when both residuals are within the tolerance."""
        return self.ode_residual <= self.tolerance and self.initial_residual <= self.tolerance

    def __bool__(self) -> bool:
        return self.ok


@dataclass(frozen=True, eq=False)
class Solution:
    """Exact motion x(t) of a scene, in real damped sine/cosine form.

    Build it with :func:`solve`. ``terms[i]`` holds the structured real terms of
    coordinate i; :attr:`x` is the same as a SymPy column matrix in :data:`t`.
    """

    scene: Scene
    resolvent: Resolvent
    terms: tuple[tuple[Term, ...], ...]

    @cached_property
    def x(self) -> sp.ImmutableMatrix:
        """x(t) as a SymPy column matrix in the symbol :data:`laplace_springs.t`."""
        return sp.ImmutableMatrix([terms_expr(list(row), t) for row in self.terms])

    @cached_property
    def _numeric(self) -> NumericTerms:
        return numeric_terms(self.terms, dps=40)

    def evaluate(self, times, *, dps: int | None = None) -> np.ndarray:
        """Evaluate x(t) at the given times.

        Parameters
        ----------
        times : array_like
            Times t ≥ 0 (a scalar is treated as one time).
        dps : int, optional
            Decimal digits. Without it the result is float64; with it, an object array
            of mpmath numbers accurate to about that many digits.

        Returns
        -------
        numpy.ndarray
            Shape (n, len(times)).
        """
        times = np.atleast_1d(times) if dps is None else list(np.atleast_1d(times))
        if dps is None:
            return evaluate_float(self._numeric, self.scene.n, times)
        data = numeric_terms(self.terms, dps=dps + 15)
        return evaluate_mp(data, self.scene.n, times, dps)

    @cached_property
    def g_denominator(self) -> sp.Poly:
        """The Δ(λ) of the g-basis: integer, content 1 (as the seed prints it)."""
        return self.resolvent.integer_characteristic_polynomial

    @cached_property
    def g_coefficients(self) -> sp.ImmutableMatrix:
        """c_ik with x_i(t) = Σ_k c_ik g_k(t), k = 0..2n-1 (the seed's K_j and N_j)."""
        R = self.resolvent
        scale = sp.cancel(self.g_denominator.as_expr() / R.determinant.as_expr())
        n2 = 2 * self.scene.n
        rows = []
        for N in R.numerators:
            coeffs = list(reversed(N.all_coeffs())) if not N.is_zero else []
            coeffs += [0] * (n2 - len(coeffs))
            rows.append([sp.factor_terms(sp.expand(scale * c)) for c in coeffs[:n2]])
        return sp.ImmutableMatrix(rows)

    @cached_property
    def g_indices(self) -> tuple[int, ...]:
        """The k whose g_k occurs in some coordinate (nonzero column of c_ik)."""
        C = self.g_coefficients
        return tuple(k for k in range(C.shape[1]) if any(C[i, k] != 0 for i in range(C.shape[0])))

    @cached_property
    def g_basis(self) -> dict[int, sp.Expr]:
        """g_k(t) = L⁻¹[λ^k/Δ(λ)] for the k in :attr:`g_indices`, exactly."""
        D = self.g_denominator
        monomials = [sp.Poly(lam**k, lam, domain=D.domain) for k in self.g_indices]
        return {k: terms_expr(list(row), t)
                for k, row in zip(self.g_indices, _terms_of(decompose(monomials, D)))}

    def g_form(self) -> sp.ImmutableMatrix:
        """x(t) written as Σ c_ik g_k with g_k as undefined functions g_k(t)."""
        C = self.g_coefficients
        g = {k: sp.Function(f"g_{k}")(t) for k in self.g_indices}
        return sp.ImmutableMatrix([sp.Add(*(C[i, k] * g[k] for k in self.g_indices))
                                   for i in range(C.shape[0])])

    def latex(self, *, form: str = "terms", resolvent: bool = False, sylvester: bool = False,
              standalone: bool = False, markdown: bool = False) -> str:
        """x(t) in LaTeX the way the seed writes it, with every named quantity defined.

        Parameters
        ----------
        form : {"terms", "g"}
            Damped sines and cosines, or x_i = Σ c_ik g_k(t) with the g_k written out.
        resolvent : bool
            Also Δ(λ), R(λ) = (λ²I + λB + A)⁻¹ and X(λ).
        sylvester : bool
            Also Sylvester's matrices and cos(√A t), sin(√A t)/√A (undamped numeric scenes).
        standalone : bool
            A complete ``article`` document (compiles with pdflatex).
        markdown : bool
            A Markdown snippet: each block between ``$$`` lines.

        Returns
        -------
        str
            By default one ``aligned`` block per part (x(t) and its "where" list first).
            See :mod:`laplace_springs.latex_export` for the conventions (no imaginary
            unit, algebraic numbers as named constants, θ(t − τ) for switched inputs).
        """
        from .latex_export import solution_latex

        output = "document" if standalone else "markdown" if markdown else "fragment"
        return solution_latex(self, form=form, resolvent=resolvent, sylvester=sylvester,
                              output=output)

    def _repr_latex_(self) -> str:
        return "$$" + self.latex() + "$$"

    def __repr__(self) -> str:
        body = ", ".join(f"{name}(t) = {expr}" for name, expr in zip(self.scene.names, self.x))
        return f"Solution({body})"

    def verify(self, *, samples: Sequence = ("0.37", "1.3", "4.1"), dps: int = 40) -> Verification:
        """Check at high precision that x satisfies the equations and initial data.

        The exact expression :attr:`x` is differentiated symbolically and
        M x'' + C x' + K x is evaluated at the sample times with ``dps`` digits
        (algebraic numbers from certified root enclosures); x(0) - x0 and x'(0) - v0
        likewise. Symbolic parameters are given fixed generic values first (the
        residual is an identity in them). Residuals are relative to the data's size.

        Returns
        -------
        Verification
            Truthy when both residuals are below 10^(10 - dps).
        """
        s = self.scene
        generic = _generic_values(s.free_symbols)
        x = sp.Matrix(self.x)
        v = x.diff(t)
        residual = (s.M * v.diff(t) + s.C * v + s.K * x).xreplace(generic)
        start = [*(x.subs(t, 0) - s.x0), *(v.subs(t, 0) - s.v0)]
        scale = max(1.0, _size([*s.x0, *s.v0], generic, 20))
        ode = _size([e.subs(t, sp.Rational(tv)) for e in residual for tv in samples], {}, dps)
        return Verification(ode / scale, _size(start, generic, dps) / scale, 10.0 ** (10 - dps))

    # -- plots (see laplace_springs.plotting; need matplotlib) ---------------
    def plot(self, ax=None, **kw):
        """The seed's "Mass Position vs. Time" plot; see :func:`laplace_springs.plotting.plot_motion`."""
        from .plotting import plot_motion

        return plot_motion(self, ax, **kw)

    def plot_phase(self, ax=None, **kw):
        """Phase portraits x_i' against x_i; see :func:`laplace_springs.plotting.plot_phase`."""
        from .plotting import plot_phase

        return plot_phase(self, ax, **kw)

    def plot_energy(self, ax=None, **kw):
        """Kinetic, potential, dissipated energy; see :func:`laplace_springs.plotting.plot_energy`."""
        from .plotting import plot_energy

        return plot_energy(self, ax, **kw)

    # -- named quantities of symbolic scenes (see laplace_springs.symbolic_forms) --
    @property
    def definitions(self) -> dict:
        """Named quantity → definition for the names in :attr:`x` (ω_j, γ_j, S_j, P_j).

        Empty for numeric scenes. A definition may use names listed before it.

        Examples
        --------
        >>> from laplace_springs.scene import Scene
        >>> sol = solve(Scene.from_matrices(M=[["m"]], K=[["k"]], x0=[1], v0=[0]))
        >>> sol.x[0], sol.definitions
        (cos(t*omega_1), {omega_1: sqrt(k)/sqrt(m)})
        """
        from .symbolic_forms import definitions

        return definitions(list(self.x))

    def substituted(self) -> sp.ImmutableMatrix:
        """:attr:`x` with every named quantity replaced by its definition in the parameters."""
        from .symbolic_forms import expand_names

        return sp.ImmutableMatrix(expand_names(self.x))



def _generic_values(symbols) -> dict:
    """Fixed, unremarkable positive rationals for symbolic parameters."""
    return {sym: sp.Rational(97 + 13 * i, 89 + 7 * i)
            for i, sym in enumerate(sorted(symbols, key=lambda v: v.name))}


def _size(exprs, values: dict, dps: int) -> float:
    """max |e| over the expressions, at ``dps`` digits (complex values allowed)."""
    return max((float(abs(numeric_value(sp.sympify(e).xreplace(values), dps))) for e in exprs),
               default=0.0)


def _latex_name(name: str) -> str:
    head = name.rstrip("0123456789")
    tail = name[len(head):]
    return f"{head}_{{{tail}}}" if tail and head else name


def solve(scene: Scene, *, method: str = "auto") -> Solution:
    """Solve M x'' + C x' + K x = 0 with the scene's initial data, exactly.

    Parameters
    ----------
    scene : Scene
        The mechanical system.
    method : {"auto", "exact"}
        "exact" inverts the Laplace transform by exact partial fractions; "auto"
        currently means "exact".

    Returns
    -------
    Solution
        Closed form :attr:`Solution.x`, evaluation, LaTeX, g-basis and verification.

    Examples
    --------
    A critically damped mass, x'' + 2x' + x = 0, x(0) = 1:

    >>> from laplace_springs.scene import Scene
    >>> sol = solve(Scene.from_matrices(M=[[1]], C=[[2]], K=[[1]], x0=[1], v0=[0]))
    >>> sol.x[0]
    t*exp(-t) + exp(-t)
    >>> sol.evaluate([0.0, 1.0]).round(12)
    array([[1.        , 0.73575888]])
    """
    if method not in _METHODS:
        raise ValueError(f"method must be one of {_METHODS}, got {method!r}")
    R = resolvent(scene)
    return Solution(scene, R, _terms_of(decompose(list(R.numerators), R.determinant)))
